//! A/B comparison of two renders (docs/commands.md#lookdev-render, `--compare`): the two side by side,
//! and how far apart they look, as the CIELAB colour difference ΔE*ab of their display pixels.

use super::sheet::{self, Cell, Labeller};
use image::{Rgba, RgbaImage};

/// A difference of 2.3 is about the smallest a viewer notices (Sharma 2003).
pub const JUST_NOTICEABLE: f32 = 2.3;
/// The heat map's scale: ΔE at or above this is the hottest colour.
pub const HEAT_MAX: f32 = 10.0;

/// D65's white point in XYZ, with Y = 1.
const WHITE: [f64; 3] = [0.950_47, 1.0, 1.088_83];

/// CIELAB (D65) of an sRGB-encoded colour.
pub fn srgb_to_lab(rgb: [u8; 3]) -> [f64; 3] {
    let linear = rgb.map(|c| {
        let c = c as f64 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    });
    // sRGB's primaries and D65 white (IEC 61966-2-1).
    let xyz = [
        0.412_456_4 * linear[0] + 0.357_576_1 * linear[1] + 0.180_437_5 * linear[2],
        0.212_672_9 * linear[0] + 0.715_152_2 * linear[1] + 0.072_175_0 * linear[2],
        0.019_333_9 * linear[0] + 0.119_192_0 * linear[1] + 0.950_304_1 * linear[2],
    ];
    let f = |t: f64| {
        let delta: f64 = 6.0 / 29.0;
        if t > delta.powi(3) {
            t.cbrt()
        } else {
            t / (3.0 * delta * delta) + 4.0 / 29.0
        }
    };
    let [fx, fy, fz] = [0, 1, 2].map(|k| f(xyz[k] / WHITE[k]));
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// ΔE*ab (CIE 1976): the Euclidean distance of two colours in CIELAB.
pub fn delta_e(a: [u8; 3], b: [u8; 3]) -> f32 {
    let (a, b) = (srgb_to_lab(a), srgb_to_lab(b));
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt() as f32
}

/// ΔE at every pixel of two RGBA8 images of the same size.
pub fn delta_e_image(a: &[u8], b: &[u8]) -> Vec<f32> {
    a.chunks_exact(4).zip(b.chunks_exact(4)).map(|(p, q)| delta_e([p[0], p[1], p[2]], [q[0], q[1], q[2]])).collect()
}

/// The summary of a difference image, over the pixels compared.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Summary {
    pub pixels: usize,
    pub mean: f32,
    pub median: f32,
    pub p95: f32,
    pub max: f32,
    /// The fraction of pixels at or above [`JUST_NOTICEABLE`].
    pub noticeable: f32,
}

impl Summary {
    /// Summarises `values` where `include` holds; `None` when nothing is included.
    pub fn of(values: &[f32], include: impl Fn(usize) -> bool) -> Option<Summary> {
        let mut chosen: Vec<f32> = values.iter().enumerate().filter(|(i, _)| include(*i)).map(|(_, &v)| v).collect();
        if chosen.is_empty() {
            return None;
        }
        chosen.sort_by(f32::total_cmp);
        let at = |q: f64| chosen[((chosen.len() - 1) as f64 * q).round() as usize];
        let mean = (chosen.iter().map(|&v| v as f64).sum::<f64>() / chosen.len() as f64) as f32;
        let noticeable = chosen.iter().filter(|&&v| v >= JUST_NOTICEABLE).count() as f32 / chosen.len() as f32;
        Some(Summary {
            pixels: chosen.len(),
            mean,
            median: at(0.5),
            p95: at(0.95),
            max: chosen[chosen.len() - 1],
            noticeable,
        })
    }
}

/// The heat map's colour for a ΔE: black through purple, red and orange to pale yellow at
/// [`HEAT_MAX`] (a ramp in the manner of "inferno", rising in lightness).
pub fn heat(delta: f32) -> [u8; 3] {
    const STOPS: [[f32; 3]; 5] =
        [[0.0, 0.0, 4.0], [87.0, 16.0, 110.0], [188.0, 55.0, 84.0], [249.0, 142.0, 9.0], [252.0, 255.0, 164.0]];
    let t = (delta / HEAT_MAX).clamp(0.0, 1.0) * (STOPS.len() - 1) as f32;
    let i = (t.floor() as usize).min(STOPS.len() - 2);
    let f = t - i as f32;
    [0, 1, 2].map(|k| (STOPS[i][k] + (STOPS[i + 1][k] - STOPS[i][k]) * f).round() as u8)
}

/// The difference image: each pixel's ΔE as a heat colour, with a scale bar along the bottom.
pub fn heat_map(values: &[f32], width: u32, height: u32) -> RgbaImage {
    let bar = 28;
    let mut image = RgbaImage::from_pixel(width, height + bar, Rgba([24, 24, 27, 255]));
    for (i, &v) in values.iter().enumerate() {
        let [r, g, b] = heat(v);
        image.put_pixel(i as u32 % width, i as u32 / width, Rgba([r, g, b, 255]));
    }
    let (left, right) = (8u32, width.saturating_sub(8).max(9));
    for x in left..right {
        let [r, g, b] = heat(HEAT_MAX * (x - left) as f32 / (right - 1 - left).max(1) as f32);
        for y in height + 4..height + 12 {
            image.put_pixel(x, y, Rgba([r, g, b, 255]));
        }
    }
    let labeller = Labeller::default();
    let ink = [225, 225, 230];
    let label_y = (height + 13) as f32;
    labeller.draw(&mut image, "ΔE 0", left as f32, label_y, 12.0, ink, width as f32);
    let high = format!("{HEAT_MAX}+");
    let high_x = right as f32 - labeller.width(&high, 12.0);
    labeller.draw(&mut image, &high, high_x, label_y, 12.0, ink, width as f32);
    image
}

/// A and B side by side, each with its label under it.
pub fn side_by_side(a: RgbaImage, a_label: &str, b: RgbaImage, b_label: &str) -> RgbaImage {
    let cells = [
        Cell { image: a, title: "A".into(), caption: a_label.into() },
        Cell { image: b, title: "B".into(), caption: b_label.into() },
    ];
    sheet::grid(&cells, 2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lab_matches_published_values() {
        // sRGB red, green and blue in CIELAB (D65), as tabulated by Lindbloom.
        for (rgb, lab) in [
            ([255, 0, 0], [53.2408, 80.0925, 67.2032]),
            ([0, 255, 0], [87.7347, -86.1827, 83.1793]),
            ([0, 0, 255], [32.2970, 79.1875, -107.8602]),
            ([255, 255, 255], [100.0, 0.0, 0.0]),
        ] {
            let got = srgb_to_lab(rgb);
            for k in 0..3 {
                assert!((got[k] - lab[k]).abs() < 0.02, "{rgb:?}: {got:?} vs {lab:?}");
            }
        }
        assert!((delta_e([0, 0, 0], [255, 255, 255]) - 100.0).abs() < 1e-3);
        assert_eq!(delta_e([12, 200, 77], [12, 200, 77]), 0.0);
    }

    #[test]
    fn summaries_count_only_the_pixels_compared() {
        let values = [0.0, 1.0, 2.0, 3.0, 100.0];
        let all = Summary::of(&values, |_| true).unwrap();
        assert_eq!((all.pixels, all.median, all.max), (5, 2.0, 100.0));
        assert!((all.mean - 21.2).abs() < 1e-5);
        assert!((all.noticeable - 0.4).abs() < 1e-6);
        let some = Summary::of(&values, |i| i < 4).unwrap();
        assert_eq!((some.pixels, some.max), (4, 3.0));
        assert!(Summary::of(&values, |_| false).is_none());
    }

    #[test]
    fn the_heat_ramp_rises_in_lightness() {
        let lightness = |d: f32| srgb_to_lab(heat(d))[0];
        let mut last = -1.0;
        for step in 0..=20 {
            let l = lightness(step as f32 * HEAT_MAX / 20.0);
            assert!(l > last, "ΔE {}: L* {l} after {last}", step as f32 * HEAT_MAX / 20.0);
            last = l;
        }
        assert_eq!(heat(HEAT_MAX * 3.0), heat(HEAT_MAX));
    }
}
