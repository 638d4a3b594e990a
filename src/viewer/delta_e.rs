//! Colour difference between the live image and a snapshot: CIEDE2000 (ΔE00, Sharma, Wu and
//! Dalal, "The CIEDE2000 Color-Difference Formula", 2005) between the display colours, each
//! sRGB-encoded pixel decoded and converted to CIELAB under D65. It measures what the artist
//! sees, exposure and tone map included. A difference of about 1 is just noticeable.

/// The heat map's colour stops: ΔE00 and the colour shown for it, linearly blended between.
/// Black is identical; 1 (just noticeable) a dark blue; 10 and beyond white.
pub const STOPS: [(f32, [u8; 3]); 6] = [
    (0.0, [0, 0, 0]),
    (1.0, [24, 40, 160]),
    (2.0, [30, 140, 220]),
    (3.0, [40, 190, 80]),
    (5.0, [240, 200, 30]),
    (10.0, [255, 255, 255]),
];

/// A per-pixel ΔE00 map and its summary.
#[derive(Clone, Debug, PartialEq)]
pub struct DeltaE {
    pub width: u32,
    pub height: u32,
    /// ΔE00 per pixel, row by row.
    pub values: Vec<f32>,
    pub mean: f32,
    pub max: f32,
    /// Unique to this map, so that a texture made of it is remade only for a new one.
    pub serial: u64,
}

impl DeltaE {
    /// ΔE00 between two RGBA8 sRGB images of `width`×`height` (alpha is ignored).
    pub fn between(width: u32, height: u32, a: &[u8], b: &[u8]) -> DeltaE {
        let table = decode_table();
        let lab = |p: &[u8]| srgb8_to_lab(&table, [p[0], p[1], p[2]]);
        let pixels = a.len().min(b.len()) / 4;
        let mut values = vec![0.0f32; pixels];
        // A band of pixels per core: at 1024² the map is a fraction of a frame's wait rather
        // than several frames. Each pixel is independent, so the bands do not change the result.
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).clamp(1, 16);
        let band = pixels.div_ceil(threads).max(1);
        std::thread::scope(|scope| {
            for (index, out) in values.chunks_mut(band).enumerate() {
                let (a, b) = (&a[index * band * 4..], &b[index * band * 4..]);
                scope.spawn(move || {
                    for ((value, p), q) in out.iter_mut().zip(a.chunks_exact(4)).zip(b.chunks_exact(4)) {
                        if p[..3] != q[..3] {
                            *value = ciede2000(lab(p), lab(q)) as f32;
                        }
                    }
                });
            }
        });
        let max = values.iter().copied().fold(0.0, f32::max);
        let mean = if values.is_empty() {
            0.0
        } else {
            (values.iter().map(|&v| v as f64).sum::<f64>() / values.len() as f64) as f32
        };
        static MADE: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let serial = MADE.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        DeltaE { width, height, values, mean, max, serial }
    }

    /// The heat map as RGBA8 sRGB pixels (see [`STOPS`]).
    pub fn heat_map(&self) -> Vec<u8> {
        self.values
            .iter()
            .flat_map(|&v| {
                let [r, g, b] = heat(v);
                [r, g, b, 255]
            })
            .collect()
    }
}

/// The heat map's colour for a ΔE00 (see [`STOPS`]).
pub fn heat(delta_e: f32) -> [u8; 3] {
    let v = if delta_e.is_finite() { delta_e.max(0.0) } else { f32::MAX };
    for pair in STOPS.windows(2) {
        let ((v0, c0), (v1, c1)) = (pair[0], pair[1]);
        if v <= v1 {
            let t = (v - v0) / (v1 - v0);
            return std::array::from_fn(|k| (c0[k] as f32 + (c1[k] as f32 - c0[k] as f32) * t).round() as u8);
        }
    }
    STOPS[STOPS.len() - 1].1
}

/// sRGB-encoded 8-bit values decoded to linear, once per image rather than per pixel.
fn decode_table() -> [f64; 256] {
    std::array::from_fn(|i| {
        let c = i as f64 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    })
}

/// CIELAB (D65 white) of an sRGB-encoded colour.
fn srgb8_to_lab(table: &[f64; 256], [r, g, b]: [u8; 3]) -> [f64; 3] {
    let (r, g, b) = (table[r as usize], table[g as usize], table[b as usize]);
    // sRGB primaries (IEC 61966-2-1) to XYZ, D65.
    let x = 0.4124564 * r + 0.3575761 * g + 0.1804375 * b;
    let y = 0.2126729 * r + 0.7151522 * g + 0.0721750 * b;
    let z = 0.0193339 * r + 0.1191920 * g + 0.9503041 * b;
    xyz_to_lab([x, y, z], [0.95047, 1.0, 1.08883])
}

fn xyz_to_lab([x, y, z]: [f64; 3], [xn, yn, zn]: [f64; 3]) -> [f64; 3] {
    const EPSILON: f64 = 216.0 / 24389.0;
    const KAPPA: f64 = 24389.0 / 27.0;
    let f = |t: f64| if t > EPSILON { t.cbrt() } else { (KAPPA * t + 16.0) / 116.0 };
    let (fx, fy, fz) = (f(x / xn), f(y / yn), f(z / zn));
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// CIEDE2000 between two CIELAB colours, with kL = kC = kH = 1.
pub fn ciede2000([l1, a1, b1]: [f64; 3], [l2, a2, b2]: [f64; 3]) -> f64 {
    use std::f64::consts::PI;
    let deg = |r: f64| r * 180.0 / PI;
    let rad = |d: f64| d * PI / 180.0;
    let c_mean = (a1.hypot(b1) + a2.hypot(b2)) / 2.0;
    let c7 = c_mean.powi(7);
    let g = 0.5 * (1.0 - (c7 / (c7 + 25f64.powi(7))).sqrt());
    let (a1p, a2p) = ((1.0 + g) * a1, (1.0 + g) * a2);
    let (c1p, c2p) = (a1p.hypot(b1), a2p.hypot(b2));
    let hue = |b: f64, a: f64| if b == 0.0 && a == 0.0 { 0.0 } else { deg(b.atan2(a)).rem_euclid(360.0) };
    let (h1p, h2p) = (hue(b1, a1p), hue(b2, a2p));

    let dl = l2 - l1;
    let dc = c2p - c1p;
    // The hue difference is taken the short way round, and is zero when either colour is grey.
    let dh = if c1p * c2p == 0.0 {
        0.0
    } else if (h2p - h1p).abs() <= 180.0 {
        h2p - h1p
    } else if h2p - h1p > 180.0 {
        h2p - h1p - 360.0
    } else {
        h2p - h1p + 360.0
    };
    let dh_big = 2.0 * (c1p * c2p).sqrt() * (rad(dh) / 2.0).sin();

    let l_mean = (l1 + l2) / 2.0;
    let cp_mean = (c1p + c2p) / 2.0;
    let hp_mean = if c1p * c2p == 0.0 {
        h1p + h2p
    } else if (h1p - h2p).abs() <= 180.0 {
        (h1p + h2p) / 2.0
    } else if h1p + h2p < 360.0 {
        (h1p + h2p + 360.0) / 2.0
    } else {
        (h1p + h2p - 360.0) / 2.0
    };
    let t = 1.0 - 0.17 * rad(hp_mean - 30.0).cos()
        + 0.24 * rad(2.0 * hp_mean).cos()
        + 0.32 * rad(3.0 * hp_mean + 6.0).cos()
        - 0.20 * rad(4.0 * hp_mean - 63.0).cos();
    let d_theta = 30.0 * (-((hp_mean - 275.0) / 25.0).powi(2)).exp();
    let cp7 = cp_mean.powi(7);
    let rc = 2.0 * (cp7 / (cp7 + 25f64.powi(7))).sqrt();
    let l50 = (l_mean - 50.0).powi(2);
    let sl = 1.0 + 0.015 * l50 / (20.0 + l50).sqrt();
    let sc = 1.0 + 0.045 * cp_mean;
    let sh = 1.0 + 0.015 * cp_mean * t;
    let rt = -(2.0 * rad(d_theta)).sin() * rc;
    let (l, c, h) = (dl / sl, dc / sc, dh_big / sh);
    (l * l + c * c + h * h + rt * c * h).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pairs from Table 1 of Sharma, Wu and Dalal (2005), the formula's published test data,
    /// with their ΔE00 to four decimals: they exercise the hue wrap, grey colours and the
    /// rotation term.
    const SHARMA: [([f64; 3], [f64; 3], f64); 16] = [
        ([50.0, 2.6772, -79.7751], [50.0, 0.0, -82.7485], 2.0425),
        ([50.0, 3.1571, -77.2803], [50.0, 0.0, -82.7485], 2.8615),
        ([50.0, 2.8361, -74.0200], [50.0, 0.0, -82.7485], 3.4412),
        ([50.0, -1.3802, -84.2814], [50.0, 0.0, -82.7485], 1.0000),
        ([50.0, 0.0, 0.0], [50.0, -1.0, 2.0], 2.3669),
        ([50.0, -1.0, 2.0], [50.0, 0.0, 0.0], 2.3669),
        ([50.0, 2.4900, -0.0010], [50.0, -2.4900, 0.0009], 7.1792),
        ([50.0, 2.5, 0.0], [73.0, 25.0, -18.0], 27.1492),
        ([50.0, 2.5, 0.0], [61.0, -5.0, 29.0], 22.8977),
        ([50.0, 2.5, 0.0], [56.0, -27.0, -3.0], 31.9030),
        ([50.0, 2.5, 0.0], [58.0, 24.0, 15.0], 19.4535),
        ([50.0, 2.5, 0.0], [50.0, 3.1736, 0.5854], 1.0000),
        ([60.2574, -34.0099, 36.2677], [60.4626, -34.1751, 39.4387], 1.2644),
        ([63.0109, -31.0961, -5.8663], [62.8187, -29.7946, -4.0864], 1.2630),
        ([22.7233, 20.0904, -46.6940], [23.0331, 14.9730, -42.5619], 2.0373),
        ([2.0776, 0.0795, -1.1350], [0.9033, -0.0636, -0.5514], 0.9082),
    ];

    #[test]
    fn ciede2000_gives_the_published_differences() {
        for (a, b, expected) in SHARMA {
            let got = ciede2000(a, b);
            assert!((got - expected).abs() < 5e-5, "{a:?} vs {b:?}: {got:.5}, expected {expected}");
            assert!((ciede2000(b, a) - got).abs() < 1e-9, "symmetric");
        }
        assert_eq!(ciede2000([40.0, 10.0, -5.0], [40.0, 10.0, -5.0]), 0.0);
    }

    #[test]
    fn srgb_converts_to_the_known_lab_values() {
        let table = decode_table();
        let close = |got: [f64; 3], want: [f64; 3]| got.iter().zip(want).all(|(g, w)| (g - w).abs() < 0.02);
        let white = srgb8_to_lab(&table, [255, 255, 255]);
        assert!(close(white, [100.0, 0.0, 0.0]), "{white:?}");
        assert!(close(srgb8_to_lab(&table, [0, 0, 0]), [0.0, 0.0, 0.0]));
        // sRGB red under D65: L 53.24, a 80.09, b 67.20 (the standard sRGB → CIELAB figures).
        let red = srgb8_to_lab(&table, [255, 0, 0]);
        assert!(close(red, [53.24, 80.09, 67.20]), "{red:?}");
        let grey = srgb8_to_lab(&table, [119, 119, 119]);
        assert!((grey[0] - 50.0).abs() < 0.2 && grey[1].abs() < 0.01 && grey[2].abs() < 0.01, "{grey:?}");
    }

    #[test]
    fn identical_images_have_zero_difference_and_a_changed_pixel_shows() {
        let a: Vec<u8> = (0..16u8).flat_map(|i| [i * 16, 255 - i * 16, 90, 255]).collect();
        let same = DeltaE::between(4, 4, &a, &a);
        assert!(same.values.iter().all(|&v| v == 0.0) && same.max == 0.0 && same.mean == 0.0);
        assert!(same.heat_map().chunks_exact(4).all(|p| p == [0, 0, 0, 255]), "zero is black");
        let mut b = a.clone();
        b[5 * 4] = b[5 * 4].wrapping_add(40);
        let changed = DeltaE::between(4, 4, &a, &b);
        assert!(changed.values[5] > 1.0 && changed.max == changed.values[5], "{:?}", changed.values);
        assert!((changed.mean - changed.max / 16.0).abs() < 1e-6);
        assert!(changed.values.iter().enumerate().all(|(i, &v)| i == 5 || v == 0.0));
    }

    #[test]
    fn every_pixel_is_its_own_difference_whatever_the_bands() {
        let (width, height) = (37u32, 23u32);
        let a: Vec<u8> = (0..width * height * 4).map(|i| (i * 7 % 251) as u8).collect();
        let b: Vec<u8> = (0..width * height * 4).map(|i| (i * 13 % 241) as u8).collect();
        let map = DeltaE::between(width, height, &a, &b);
        let table = decode_table();
        let lab = |p: &[u8]| srgb8_to_lab(&table, [p[0], p[1], p[2]]);
        assert_eq!(map.values.len(), (width * height) as usize);
        for (i, (p, q)) in a.chunks_exact(4).zip(b.chunks_exact(4)).enumerate() {
            assert_eq!(map.values[i], ciede2000(lab(p), lab(q)) as f32, "pixel {i}");
        }
    }

    #[test]
    fn the_heat_map_follows_its_stops() {
        for (value, colour) in STOPS {
            assert_eq!(heat(value), colour);
        }
        assert_eq!(heat(50.0), [255, 255, 255]);
        assert_eq!(heat(f32::NAN), [255, 255, 255]);
        assert_eq!(heat(-1.0), [0, 0, 0]);
        assert_eq!(heat(0.5), [12, 20, 80]);
    }
}
