//! The shader ball's layer masks: functions of world position, antialiased by filter width.
//!
//! Each mask takes the world-space width of the pixel's footprint and removes detail finer than
//! it (an exact box filter for the stripes, octave clamping for the noise), so masks stay smooth
//! at any resolution without per-subsample evaluation.

use glam::Vec3;

/// The mask names, in the order [`masks_at`] returns them.
pub(crate) const MASK_NAMES: [&str; 3] = ["stripes", "grunge", "gradient"];

/// Stripes: one light and one dark band per period, in world Y.
const STRIPE_PERIOD: f32 = 0.36;
/// The stripes' edges are soft over about this width (world units) even when finely sampled.
const STRIPE_SOFTNESS: f32 = 0.012;

/// Grunge: the lowest noise frequency (cycles per world unit), the number of octaves, and the
/// soft threshold applied to the fBm (in its \[-1,1\] range) that turns it into patches of grime.
const GRUNGE_FREQUENCY: f32 = 2.5;
const GRUNGE_OCTAVES: usize = 6;
const GRUNGE_THRESHOLD: (f32, f32) = (0.12, 0.4);
/// The root-mean-square gradient of [`value_noise`] per unit of its input (checked by a test).
const NOISE_SLOPE: f32 = 1.3;

/// The part of the world one pixel covers, as an axis-aligned box around the evaluation point.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Footprint {
    /// Size of the box along X, Y and Z (world units).
    pub extent: Vec3,
}

/// All masks at world position `p` on an object spanning `height_span` in Y, filtered over
/// `footprint`. Each mask uses the extent that matters to it: the stripes vary along Y only,
/// the noise in every direction.
pub(crate) fn masks_at(p: Vec3, footprint: Footprint, height_span: (f32, f32)) -> [f32; 3] {
    let extent = footprint.extent;
    [stripes(p.y, extent.y), grunge(p, extent.max_element()), gradient(p.y, height_span)]
}

/// Latitude bands: a square wave in y, box-filtered over the footprint (widened by a little
/// softness), using the closed-form integral of the wave.
fn stripes(y: f32, filter_width: f32) -> f32 {
    let x = y / STRIPE_PERIOD;
    let width = filter_width.hypot(STRIPE_SOFTNESS) / STRIPE_PERIOD;
    let integral = |x: f32| {
        // Each whole period holds half a period of 1; within a period the wave is 1 on the
        // upper half.
        let fraction = x - x.floor();
        x.floor() * 0.5 + (fraction - 0.5).max(0.0)
    };
    ((integral(x + 0.5 * width) - integral(x - 0.5 * width)) / width).clamp(0.0, 1.0)
}

/// Grime: fBm of value noise, with octaves finer than the footprint faded to their mean (0),
/// then a soft threshold, softened further where the fBm changes a lot across the footprint (a
/// thresholded function is not band-limited by fading octaves alone).
fn grunge(p: Vec3, filter_width: f32) -> f32 {
    let mut sum = 0.0;
    let mut total_amplitude = 0.0;
    // The typical gradient (per world unit) of the octaves kept, in the same units as `sum`.
    let mut slope = 0.0;
    let mut frequency = GRUNGE_FREQUENCY;
    let mut amplitude = 1.0;
    for octave in 0..GRUNGE_OCTAVES {
        // Cycles per footprint: fade out between a quarter and a half (Nyquist is a half).
        let cycles_per_footprint = frequency * filter_width;
        let keep = 1.0 - smoothstep(0.25, 0.5, cycles_per_footprint);
        if keep > 0.0 {
            // A per-octave offset keeps lattice points of different octaves from lining up.
            let offset = Vec3::splat(octave as f32 * 17.31);
            sum += amplitude * keep * value_noise(p * frequency + offset);
            slope += amplitude * keep * frequency * NOISE_SLOPE;
        }
        total_amplitude += amplitude;
        frequency *= 2.0;
        amplitude *= 0.5;
    }
    let fbm = sum / total_amplitude;
    let change_across_footprint = slope / total_amplitude * filter_width;
    let (low, high) = GRUNGE_THRESHOLD;
    let half_width = (0.5 * (high - low)).max(change_across_footprint);
    let centre = 0.5 * (low + high);
    smoothstep(centre - half_width, centre + half_width, fbm)
}

/// A vertical ramp in world Y over an object: 0 at its lowest point, 1 at its highest.
fn gradient(y: f32, (bottom, top): (f32, f32)) -> f32 {
    ((y - bottom) / (top - bottom)).clamp(0.0, 1.0)
}

fn smoothstep(edge0: f32, edge1: f32, x: f32) -> f32 {
    let t = ((x - edge0) / (edge1 - edge0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Value noise in \[-1,1\]: random values at integer lattice points, blended with a quintic fade
/// so the result has continuous first and second derivatives (no creases in the grime).
fn value_noise(p: Vec3) -> f32 {
    let [ix, iy, iz] = [floor(p.x), floor(p.y), floor(p.z)];
    let f = p - Vec3::new(ix as f32, iy as f32, iz as f32);
    let fade = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    // Each lattice axis gets its own odd multiplier, so the three coordinates mix before the
    // finaliser (the products for the two neighbours along an axis are computed once).
    let xs = [ix, ix + 1].map(|x| (x as u32).wrapping_mul(0x8da6_b343));
    let ys = [iy, iy + 1].map(|y| (y as u32).wrapping_mul(0xd816_3841));
    let zs = [iz, iz + 1].map(|z| (z as u32).wrapping_mul(0xcb1a_b31f));
    let corner = |dx: usize, dy: usize, dz: usize| to_signed_unit(hash(xs[dx] ^ ys[dy] ^ zs[dz]));
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let x00 = lerp(corner(0, 0, 0), corner(1, 0, 0), fade.x);
    let x10 = lerp(corner(0, 1, 0), corner(1, 1, 0), fade.x);
    let x01 = lerp(corner(0, 0, 1), corner(1, 0, 1), fade.x);
    let x11 = lerp(corner(0, 1, 1), corner(1, 1, 1), fade.x);
    lerp(lerp(x00, x10, fade.y), lerp(x01, x11, fade.y), fade.z)
}

/// `x.floor()` as an integer. The standard library's `floor` is a function call on baseline
/// x86-64, and this runs millions of times. The scene spans a few hundred lattice cells at most,
/// far inside i32.
fn floor(x: f32) -> i32 {
    let truncated = x as i32;
    truncated - i32::from(x < truncated as f32)
}

/// The top 24 bits of a hash as a value in \[-1,1\].
fn to_signed_unit(h: u32) -> f32 {
    (h >> 8) as f32 * (2.0 / (1u32 << 24) as f32) - 1.0
}

/// An integer finaliser: xor-shifts and odd multipliers, so every input bit reaches every
/// output bit and neighbouring lattice points look unrelated.
fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stripes_are_a_filtered_square_wave() {
        // Mid-band values are exact; the average over a period is one half.
        assert!((stripes(0.75 * STRIPE_PERIOD, 0.0) - 1.0).abs() < 1e-5);
        assert!(stripes(0.25 * STRIPE_PERIOD, 0.0).abs() < 1e-5);
        let n = 1000;
        let mean: f32 = (0..n).map(|i| stripes(i as f32 / n as f32 * STRIPE_PERIOD, 0.001)).sum::<f32>() / n as f32;
        assert!((mean - 0.5).abs() < 0.01, "{mean}");
        // A footprint of whole periods sees the average.
        assert!((stripes(0.3, 2.0 * STRIPE_PERIOD) - 0.5).abs() < 1e-3);
    }

    #[test]
    fn fast_floor_matches_floor() {
        for x in [-2.5f32, -2.0, -1e-7, -0.0, 0.0, 0.3, 1.0, 7.999, -7.999] {
            assert_eq!(floor(x), x.floor() as i32, "{x}");
        }
    }

    #[test]
    fn noise_is_deterministic_bounded_and_continuous() {
        let mut previous = value_noise(Vec3::new(-3.0, 0.2, 0.7));
        for i in 1..2000 {
            let p = Vec3::new(-3.0 + i as f32 * 0.003, 0.2, 0.7);
            let v = value_noise(p);
            assert!((-1.0..=1.0).contains(&v));
            assert!((v - previous).abs() < 0.05, "jump at {p}");
            assert_eq!(v, value_noise(p));
            previous = v;
        }
    }

    #[test]
    fn noise_slope_is_the_rms_gradient() {
        let h = 1e-3;
        let mut sum_squares = 0.0;
        let n = 20_000;
        for i in 0..n {
            let p = Vec3::new(i as f32 * 0.0137, i as f32 * 0.0071 + 0.3, i as f32 * 0.0029 + 0.7);
            let gradient = Vec3::new(
                value_noise(p + Vec3::X * h) - value_noise(p - Vec3::X * h),
                value_noise(p + Vec3::Y * h) - value_noise(p - Vec3::Y * h),
                value_noise(p + Vec3::Z * h) - value_noise(p - Vec3::Z * h),
            ) / (2.0 * h);
            sum_squares += gradient.length_squared();
        }
        let rms = (sum_squares / n as f32).sqrt();
        assert!((rms / NOISE_SLOPE - 1.0).abs() < 0.1, "rms gradient {rms}");
    }

    #[test]
    fn grunge_fades_to_a_constant_for_huge_footprints() {
        let a = grunge(Vec3::new(0.1, 0.2, 0.3), 10.0);
        let b = grunge(Vec3::new(-0.7, 0.5, 0.9), 10.0);
        assert_eq!(a, b);
    }
}
