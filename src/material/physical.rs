//! What the normalised parameters mean physically, as the shading code uses them: the F0 and
//! IOR behind `specular`, the F0 of a metal, the microfacet widths behind `roughness`,
//! `anisotropic` and `clearcoat_gloss`. The layer panel's tooltips are written from these.

use super::params::{Param, Params};
use crate::shading::brdf::tint_luminance;
use glam::Vec3;

/// The coat's fixed normal reflectance: an IOR 1.5 film.
pub const CLEARCOAT_F0: f32 = 0.04;
/// The narrowest microfacet width the shading uses (a mirror is this, not 0).
pub const MIN_ALPHA: f32 = 0.001;

/// A dielectric's normal reflectance: F0 = 0.08 · specular (Burley 2012), so 0.5 is 0.04.
pub fn dielectric_f0(specular: f32) -> f32 {
    0.08 * specular
}

/// The real IOR (against air) with normal reflectance `f0`: n = (1 + √F0) / (1 − √F0); `None`
/// where F0 ≥ 1 has none.
pub fn ior_of_f0(f0: f32) -> Option<f32> {
    let root = f0.max(0.0).sqrt();
    (root < 1.0).then(|| (1.0 + root) / (1.0 - root))
}

/// The normal reflectance of a dielectric of IOR `n` against air: ((n − 1) / (n + 1))².
pub fn f0_of_ior(n: f32) -> f32 {
    ((n - 1.0) / (n + 1.0)).powi(2)
}

/// The GGX width of a roughness: α = roughness² (Burley's remapping, which makes roughness
/// look linear), no narrower than [`MIN_ALPHA`].
pub fn alpha(roughness: f32) -> f32 {
    (roughness * roughness).max(MIN_ALPHA)
}

/// The widths (αx along the tangent, αy across it) of an anisotropic highlight:
/// aspect = √(1 − 0.9 · anisotropic), αx = α / aspect, αy = α · aspect.
pub fn anisotropic_alphas(roughness: f32, anisotropic: f32) -> (f32, f32) {
    let aspect = (1.0 - 0.9 * anisotropic).sqrt();
    let r2 = roughness * roughness;
    ((r2 / aspect).max(MIN_ALPHA), (r2 * aspect).max(MIN_ALPHA))
}

/// The coat's GTR1 width: mix(0.1, 0.001, clearcoat_gloss).
pub fn clearcoat_alpha(gloss: f32) -> f32 {
    0.1 + (0.001 - 0.1) * gloss
}

/// The base colour's hue at luminance 1 (white for black), which the tints move toward.
fn tint_color(params: &Params) -> Vec3 {
    let base = Vec3::from(params.base_color);
    let luminance = tint_luminance(base);
    if luminance > 0.0 {
        base / luminance
    } else {
        Vec3::ONE
    }
}

/// The specular F0 the shading uses, per channel:
/// mix(0.08 · specular · mix(1, tint, specular_tint), base_color, metallic).
pub fn specular_f0(params: &Params) -> [f32; 3] {
    let dielectric = dielectric_f0(params.specular) * Vec3::ONE.lerp(tint_color(params), params.specular_tint);
    dielectric.lerp(Vec3::from(params.base_color), params.metallic).to_array()
}

/// The sheen colour: sheen · mix(1, tint, sheen_tint).
pub fn sheen_color(params: &Params) -> [f32; 3] {
    (params.sheen * Vec3::ONE.lerp(tint_color(params), params.sheen_tint)).to_array()
}

fn rgb([r, g, b]: [f32; 3]) -> String {
    format!("({r:.3}, {g:.3}, {b:.3})")
}

/// "F0 = 0.08·specular = 0.040 (IOR ≈ 1.50)".
fn specular_text(specular: f32) -> String {
    let f0 = dielectric_f0(specular);
    match ior_of_f0(f0) {
        Some(n) => format!("F0 = 0.08·specular = {f0:.3} (IOR ≈ {n:.2})"),
        None => format!("F0 = 0.08·specular = {f0:.3}"),
    }
}

/// What `param` means physically for a layer of these values, for a tooltip: the formula and,
/// where it helps, its value now.
pub fn describe(param: Param, params: &Params) -> String {
    let metal = params.metallic;
    match param {
        Param::BaseColor if metal >= 1.0 => {
            format!("A metal's F0, its colour at normal incidence: F0 = base_color = {}", rgb(params.base_color))
        }
        Param::BaseColor if metal > 0.0 => format!(
            "The diffuse albedo, and as metallic rises the F0: F0 = mix(dielectric F0, base_color, metallic) = {}",
            rgb(specular_f0(params))
        ),
        Param::BaseColor => format!(
            "The diffuse albedo (linear). A dielectric's F0 does not take it: {}",
            specular_text(params.specular)
        ),
        Param::Metallic => format!(
            "0: a dielectric, {}, diffuse from base_color. 1: a metal, F0 is base_color, no diffuse. \
             Now F0 = {}",
            specular_text(params.specular),
            rgb(specular_f0(params))
        ),
        Param::Roughness => {
            let mut text = format!("GGX width α = roughness² = {:.4}; 0 is a mirror", alpha(params.roughness));
            if params.anisotropic > 0.0 {
                let (ax, ay) = anisotropic_alphas(params.roughness, params.anisotropic);
                text += &format!(" (anisotropic: αx = {ax:.4}, αy = {ay:.4})");
            }
            text
        }
        Param::Emission => "Emitted radiance (linear), added to the reflected light: 1 is as bright as a white \
                            diffuse surface under a uniform environment of radiance 1"
            .to_string(),
        Param::Specular if metal >= 1.0 => {
            format!(
                "The dielectric reflectance, {}; unused here: a metal's F0 is base_color",
                specular_text(params.specular)
            )
        }
        Param::Specular => format!("The dielectric reflectance: {}", specular_text(params.specular)),
        Param::SpecularTint => format!(
            "Tints the dielectric F0 toward base_color's hue (an artistic control): F0 = {}",
            rgb(specular_f0(params))
        ),
        Param::Anisotropic => {
            let (ax, ay) = anisotropic_alphas(params.roughness, params.anisotropic);
            format!(
                "Stretches the highlight along the tangent: αx = α/√(1−0.9·anisotropic) = {ax:.4}, \
                 αy = α·√(1−0.9·anisotropic) = {ay:.4}"
            )
        }
        Param::Clearcoat => format!(
            "A colourless coat lobe (GTR1) of F0 {CLEARCOAT_F0} (IOR {:.1}), weighted 0.25·clearcoat = {:.3}",
            ior_of_f0(CLEARCOAT_F0).unwrap_or(1.5),
            0.25 * params.clearcoat
        ),
        Param::ClearcoatGloss => {
            format!(
                "The coat's width: α = mix(0.1, 0.001, clearcoat_gloss) = {:.4}",
                clearcoat_alpha(params.clearcoat_gloss)
            )
        }
        Param::Sheen => format!(
            "A grazing rim for cloth, added to the diffuse: sheen·Csheen·(1 − cos θd)⁵, with sheen·Csheen = {}",
            rgb(sheen_color(params))
        ),
        Param::SheenTint => {
            format!("Tints the sheen toward base_color's hue: sheen·Csheen = {}", rgb(sheen_color(params)))
        }
        Param::Subsurface => format!(
            "Blends the diffuse toward Hanrahan–Krueger's subsurface approximation, {:.0}%: flatter and softer at \
             the terminator; not a scattering distance",
            params.subsurface * 100.0
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f32, b: f32, tolerance: f32) -> bool {
        (a - b).abs() <= tolerance
    }

    /// Burley's calibration: specular 0.5 is F0 0.04, which is IOR 1.5 (glass, most plastics).
    #[test]
    fn specular_half_is_f0_four_percent_and_ior_one_and_a_half() {
        assert!(close(dielectric_f0(0.5), 0.04, 1e-7));
        assert!(close(ior_of_f0(0.04).unwrap(), 1.5, 1e-5));
        assert!(close(f0_of_ior(1.5), 0.04, 1e-7));
        // Water (1.33) and diamond (2.42), and the round trip across the range.
        assert!(close(f0_of_ior(1.33), 0.02006, 1e-4));
        assert!(close(f0_of_ior(2.42), 0.1724, 1e-3));
        for n in [1.0, 1.2, 1.5, 2.0, 2.6] {
            assert!(close(ior_of_f0(f0_of_ior(n)).unwrap(), n, 1e-4), "{n}");
        }
        assert_eq!(ior_of_f0(1.0), None);
        assert!(close(ior_of_f0(0.0).unwrap(), 1.0, 0.0));
    }

    #[test]
    fn widths_follow_the_shading_code() {
        assert!(close(alpha(0.5), 0.25, 1e-7));
        assert_eq!(alpha(0.0), MIN_ALPHA);
        assert_eq!(anisotropic_alphas(0.5, 0.0), (0.25, 0.25));
        let (ax, ay) = anisotropic_alphas(0.5, 1.0);
        assert!(close(ax, 0.25 / 0.1f32.sqrt(), 1e-6) && close(ay, 0.25 * 0.1f32.sqrt(), 1e-6));
        assert!(close(ax * ay, 0.0625, 1e-6), "anisotropy keeps the area");
        assert!(close(clearcoat_alpha(1.0), 0.001, 1e-7) && close(clearcoat_alpha(0.0), 0.1, 1e-7));
        assert!(close(ior_of_f0(CLEARCOAT_F0).unwrap(), 1.5, 1e-5));
    }

    /// F0 as the shading code computes it: a dielectric's from specular, a metal's is its
    /// base colour, and metallic blends them.
    #[test]
    fn the_f0_is_the_shading_codes() {
        let dielectric = Params { base_color: [0.9, 0.1, 0.1], specular: 0.5, ..Params::default() };
        assert_eq!(specular_f0(&dielectric), [0.04; 3]);
        let gold = Params { base_color: [0.944, 0.776, 0.373], metallic: 1.0, ..Params::default() };
        assert_eq!(specular_f0(&gold), gold.base_color);
        let half = Params { metallic: 0.5, ..gold };
        assert!(close(specular_f0(&half)[0], 0.5 * 0.04 + 0.5 * 0.944, 1e-6));
        // Full specular tint: the dielectric F0 takes base_color's hue at its luminance.
        let tinted = Params { specular_tint: 1.0, ..dielectric };
        let f0 = specular_f0(&tinted);
        assert!(f0[0] > 0.04 && f0[1] < 0.04, "{f0:?}");
    }

    #[test]
    fn tooltips_state_the_values_now() {
        let params = Params::default();
        assert!(describe(Param::Specular, &params).contains("F0 = 0.08·specular = 0.040 (IOR ≈ 1.50)"));
        assert!(describe(Param::Roughness, &params).contains("α = roughness² = 0.2500"));
        let gold = Params { base_color: [0.944, 0.776, 0.373], metallic: 1.0, ..params };
        assert!(describe(Param::BaseColor, &gold).contains("F0 = base_color = (0.944, 0.776, 0.373)"));
        assert!(describe(Param::Metallic, &params).contains("1: a metal, F0 is base_color"));
        assert!(describe(Param::ClearcoatGloss, &params).contains("= 0.0010"));
        for param in Param::ALL {
            assert!(!describe(param, &params).is_empty());
        }
    }
}
