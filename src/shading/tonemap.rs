//! Display transforms: exposure, tone map and the sRGB OETF.
// The fits' constants are written as their sources publish them.
#![allow(clippy::excessive_precision)]

use glam::{Mat3, Vec3};
use std::fmt;

/// Exposures beyond this many stops overflow (or underflow) float radiance to inf (or 0).
pub const MAX_EXPOSURE: f32 = 64.0;

/// The tone map applied to PNG output, after exposure and before sRGB encoding.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Tonemap {
    /// Clamp to [0, 1].
    Linear,
    /// Khronos PBR Neutral: hue-preserving, base colours reproduced under unit white light.
    #[default]
    Neutral,
    /// ACES 1.0 RRT+ODT (sRGB), Stephen Hill's fit.
    Aces,
    /// Troy Sobotka's AgX base look.
    Agx,
}

impl Tonemap {
    pub const ALL: [Tonemap; 4] = [Tonemap::Linear, Tonemap::Neutral, Tonemap::Aces, Tonemap::Agx];

    pub fn name(self) -> &'static str {
        match self {
            Tonemap::Linear => "linear",
            Tonemap::Neutral => "neutral",
            Tonemap::Aces => "aces",
            Tonemap::Agx => "agx",
        }
    }

    pub fn from_name(name: &str) -> Option<Tonemap> {
        Tonemap::ALL.into_iter().find(|t| t.name() == name)
    }

    /// The tone map of this name, or a message that lists the names and suggests the closest.
    pub fn parse(name: &str) -> Result<Tonemap, String> {
        Tonemap::from_name(name)
            .ok_or_else(|| crate::suggest::unknown("tone map", name, "", &Tonemap::ALL.map(Tonemap::name)))
    }

    /// The id the display kernel switches on.
    pub fn gpu_id(self) -> u32 {
        self as u32
    }
}

impl fmt::Display for Tonemap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

// The transforms below mirror glsl/include/tonemap.glsl function by function; `finalize.comp`
// runs them on the GPU and the tests compare the two.

/// Khronos PBR Neutral (github.com/KhronosGroup/ToneMapping, PBR_Neutral).
pub fn neutral(mut color: Vec3) -> Vec3 {
    const START_COMPRESSION: f32 = 0.8 - 0.04;
    const DESATURATION: f32 = 0.15;
    let x = color.min_element();
    let offset = if x < 0.08 { x - 6.25 * x * x } else { 0.04 };
    color -= Vec3::splat(offset);
    let peak = color.max_element();
    if peak < START_COMPRESSION {
        return color;
    }
    const D: f32 = 1.0 - START_COMPRESSION;
    let new_peak = 1.0 - D * D / (peak + D - START_COMPRESSION);
    color *= new_peak / peak;
    let g = 1.0 - 1.0 / (DESATURATION * (peak - new_peak) + 1.0);
    color.lerp(Vec3::splat(new_peak), g)
}

/// ACES 1.0 RRT+ODT for sRGB, Stephen Hill's fit.
pub fn aces(color: Vec3) -> Vec3 {
    let input = Mat3::from_cols(
        Vec3::new(0.59719, 0.07600, 0.02840),
        Vec3::new(0.35458, 0.90834, 0.13383),
        Vec3::new(0.04823, 0.01566, 0.83777),
    );
    let output = Mat3::from_cols(
        Vec3::new(1.60475, -0.10208, -0.00327),
        Vec3::new(-0.53108, 1.10813, -0.07276),
        Vec3::new(-0.07367, -0.00605, 1.07602),
    );
    let v = input * color;
    let a = v * (v + 0.0245786) - 0.000090537;
    let b = v * (0.983729 * v + 0.4329510) + 0.238081;
    (output * (a / b)).clamp(Vec3::ZERO, Vec3::ONE)
}

/// AgX base look: inset, log2 encoding, the sigmoid fit, outset, then display-linear.
pub fn agx(color: Vec3) -> Vec3 {
    let inset = Mat3::from_cols(
        Vec3::new(0.842479062253094, 0.0423282422610123, 0.0423756549057051),
        Vec3::new(0.0784335999999992, 0.878468636469772, 0.0784336),
        Vec3::new(0.0792237451477643, 0.0791661274605434, 0.879142973793104),
    );
    let outset = Mat3::from_cols(
        Vec3::new(1.19687900512017, -0.0528968517574562, -0.0529716355144438),
        Vec3::new(-0.0980208811401368, 1.15190312990417, -0.0980434501171241),
        Vec3::new(-0.0990297440797205, -0.0989611768448433, 1.15107367264116),
    );
    const MIN_EV: f32 = -12.47393;
    const MAX_EV: f32 = 4.026069;
    let v = (inset * color).max(Vec3::splat(1e-10));
    let v = ((Vec3::new(v.x.log2(), v.y.log2(), v.z.log2()) - MIN_EV) / (MAX_EV - MIN_EV)).clamp(Vec3::ZERO, Vec3::ONE);
    let v2 = v * v;
    let v4 = v2 * v2;
    let v = -17.86 * v4 * v2 * v + 78.01 * v4 * v2 - 126.7 * v4 * v + 92.06 * v4 - 28.72 * v2 * v + 4.361 * v2
        - 0.1718 * v
        + 0.002857;
    let v = (outset * v).max(Vec3::ZERO);
    Vec3::new(v.x.powf(2.2), v.y.powf(2.2), v.z.powf(2.2)).clamp(Vec3::ZERO, Vec3::ONE)
}

pub fn apply(color: Vec3, tonemap: Tonemap) -> Vec3 {
    let color = color.max(Vec3::ZERO);
    let mapped = match tonemap {
        Tonemap::Linear => color,
        Tonemap::Neutral => neutral(color),
        Tonemap::Aces => aces(color),
        Tonemap::Agx => agx(color),
    };
    mapped.clamp(Vec3::ZERO, Vec3::ONE)
}

/// The sRGB OETF (IEC 61966-2-1), piecewise.
pub fn srgb_encode(c: f32) -> f32 {
    if c <= 0.0031308 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// A display pixel from linear radiance: exposure 2^EV, tone map, sRGB, 8 bits.
pub fn display_pixel(radiance: Vec3, exposure: f32, tonemap: Tonemap) -> [u8; 3] {
    let c = apply(radiance * exposure.exp2(), tonemap);
    [c.x, c.y, c.z].map(|v| (srgb_encode(v) * 255.0 + 0.5) as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neutral_reproduces_mid_range_colours_minus_the_offset() {
        // The PBR Neutral guarantee: inputs in [0.08, 0.8] come out minus 0.04, unchanged in hue.
        let c = Vec3::new(0.2, 0.5, 0.7);
        assert!((neutral(c) - (c - 0.04)).abs().max_element() < 1e-6);
        // Highlights compress toward white, monotonically, without exceeding 1.
        let (a, b) = (neutral(Vec3::splat(2.0)), neutral(Vec3::splat(20.0)));
        assert!(a.x < b.x && b.x <= 1.0);
    }

    #[test]
    fn aces_and_agx_are_monotonic_and_bounded() {
        for tonemap in [Tonemap::Aces, Tonemap::Agx, Tonemap::Neutral, Tonemap::Linear] {
            let mut previous = -1.0;
            for i in 0..200 {
                let x = (i as f32 / 20.0 - 6.0).exp2();
                let y = apply(Vec3::splat(x), tonemap).y;
                assert!(y >= previous - 1e-6 && (0.0..=1.0).contains(&y), "{tonemap} at {x}: {y}");
                previous = y;
            }
        }
        // Mid grey lands mid-scale rather than black or white.
        let grey = apply(Vec3::splat(0.18), Tonemap::Agx).y;
        assert!((0.1..0.4).contains(&grey), "{grey}");
    }

    #[test]
    fn srgb_encoding_matches_the_standard() {
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_encode(0.0031308) - 0.04045).abs() < 1e-5);
        assert!((srgb_encode(0.5) - 0.735357).abs() < 1e-5);
        assert_eq!(display_pixel(Vec3::splat(0.5), 0.0, Tonemap::Linear), [188; 3]);
    }
}
