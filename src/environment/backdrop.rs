//! What a shown background is (docs/formats.md#backgrounds): the lighting environment, the
//! same blurred, a solid colour, or another environment than the one that lights. Whether a
//! background is shown at all is [`crate::render::Lighting::background`]; this says which.
//!
//! The blurred and the other environment are lat-long images that the background pass reads
//! bilinearly, rotated and scaled by the intensity as the lighting environment is; a colour is
//! shown as it is.

use super::{Environment, EnvironmentRef, LoadOptions, MAX_TEXEL};
use crate::Result;

/// The blur of `background = "blur"` when `background_blur` does not say: a Gaussian of this
/// standard deviation, in degrees. Enough to soften a studio's softboxes into gradients while
/// the sky and ground stay apart.
pub const DEFAULT_BLUR_DEGREES: f32 = 5.0;

/// The largest `background_blur`: beyond it the background is about one colour anyway.
pub const MAX_BLUR_DEGREES: f32 = 90.0;

/// What a shown background is.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Backdrop {
    /// The environment that lights the scene, sharp.
    #[default]
    Environment,
    /// The lighting environment blurred by a Gaussian of this standard deviation, in degrees.
    Blurred(f32),
    /// A linear colour, shown as it is: the intensity does not scale it.
    Colour([f32; 3]),
    /// Another environment than the one that lights, rotated and scaled as it is.
    Other(EnvironmentRef),
}

/// A [`Backdrop`] made ready for the background pass.
#[derive(Clone, Debug)]
pub enum Prepared {
    /// The lighting environment's own texels.
    Environment,
    Colour([f32; 3]),
    /// A lat-long image read in place of the lighting environment's texels.
    Image(Environment),
}

impl Backdrop {
    /// Makes the image this backdrop shows: the blurred copy of `lighting`, or the other
    /// environment, loaded with `options`.
    pub fn prepare(&self, lighting: &Environment, options: &LoadOptions) -> Result<Prepared> {
        Ok(match self {
            Backdrop::Environment => Prepared::Environment,
            Backdrop::Colour(rgb) => Prepared::Colour(*rgb),
            Backdrop::Blurred(degrees) => Prepared::Image(blurred(lighting, *degrees)),
            Backdrop::Other(source) => Prepared::Image(source.load(options)?),
        })
    }

    /// The name the viewer's menu and the `background` script command use.
    pub fn label(&self) -> &'static str {
        match self {
            Backdrop::Environment => "environment",
            Backdrop::Blurred(_) => "blurred",
            Backdrop::Colour(_) => "colour",
            Backdrop::Other(_) => "other environment",
        }
    }
}

/// Checks a blur (from a look, the viewer or a script); the message starts with the value.
pub fn check_blur(degrees: f32) -> std::result::Result<(), String> {
    if degrees.is_finite() && degrees > 0.0 && degrees <= MAX_BLUR_DEGREES {
        Ok(())
    } else {
        Err(format!(
            "background_blur {} must be a number of degrees above 0 and at most {MAX_BLUR_DEGREES}",
            crate::number_text(degrees)
        ))
    }
}

/// Checks a background colour: linear, non-negative and at most [`MAX_TEXEL`], as a texel is.
pub fn check_colour(rgb: [f32; 3]) -> std::result::Result<(), String> {
    if rgb.iter().all(|c| c.is_finite() && (0.0..=MAX_TEXEL).contains(c)) {
        Ok(())
    } else {
        let text: Vec<String> = rgb.iter().map(|&c| crate::number_text(c)).collect();
        Err(format!("background colour [{}] must be linear values from 0 to {MAX_TEXEL:e}", text.join(", ")))
    }
}

/// `env` blurred by a Gaussian of standard deviation `degrees` on the sphere, as a lat-long
/// image: first averaged down to texels of about a third of the deviation (no finer than the
/// map), which makes the blur cheap and is invisible under it, then blurred along each row and
/// each column. A row's deviation in texels grows as 1/sin θ toward the poles, where a degree
/// of azimuth is shorter, so the blur is about as wide in every direction; it wraps in azimuth
/// and clamps at the poles. The mean radiance of the map is kept.
pub fn blurred(env: &Environment, degrees: f32) -> Environment {
    let width = ((3.0 * 360.0 / degrees).ceil() as u32).min(env.width).max(2);
    let height = (width / 2).max(1).min(env.height);
    let small = downsampled(env, width, height);
    let (w, h) = (width as usize, height as usize);
    let mut rows = vec![[0.0f32; 3]; w * h];
    for y in 0..h {
        let sin_theta = (std::f32::consts::PI * (y as f32 + 0.5) / height as f32).sin();
        let sigma = degrees / (360.0 / width as f32) / sin_theta.max(1e-3);
        let weights = gaussian(sigma, w / 2);
        for x in 0..w {
            rows[y * w + x] = weighted(&weights, |k| small[y * w + (x as isize + k).rem_euclid(w as isize) as usize]);
        }
    }
    let weights = gaussian(degrees / (180.0 / height as f32), h);
    let mut texels = vec![[0.0f32; 3]; w * h];
    for y in 0..h {
        for x in 0..w {
            texels[y * w + x] =
                weighted(&weights, |k| rows[(y as isize + k).clamp(0, h as isize - 1) as usize * w + x]);
        }
    }
    Environment::new(width, height, texels, format!("{}, blurred {degrees}°", env.source))
}

/// The mean of the texels of `env` that fall in each texel of a `width` × `height` image.
fn downsampled(env: &Environment, width: u32, height: u32) -> Vec<[f32; 3]> {
    if (width, height) == (env.width, env.height) {
        return env.texels.clone();
    }
    let mut sums = vec![[0.0f64; 4]; (width * height) as usize];
    for y in 0..env.height {
        let ty = (y as u64 * height as u64 / env.height as u64) as u32;
        for x in 0..env.width {
            let tx = (x as u64 * width as u64 / env.width as u64) as u32;
            let sum = &mut sums[(ty * width + tx) as usize];
            let texel = env.texel(x, y);
            for c in 0..3 {
                sum[c] += texel[c] as f64;
            }
            sum[3] += 1.0;
        }
    }
    sums.iter().map(|s| [0, 1, 2].map(|c| (s[c] / s[3].max(1.0)) as f32)).collect()
}

/// The normalised weights of a Gaussian of deviation `sigma` (texels) at offsets −r..=r, with r
/// three deviations but at most `max_radius`.
fn gaussian(sigma: f32, max_radius: usize) -> Vec<f32> {
    let radius = ((3.0 * sigma).ceil() as usize).min(max_radius) as isize;
    let weights: Vec<f32> = (-radius..=radius).map(|k| (-0.5 * (k as f32 / sigma).powi(2)).exp()).collect();
    let total: f32 = weights.iter().sum();
    weights.iter().map(|w| w / total).collect()
}

/// The sum of `texel(k)` for offsets k = −r..=r weighted by `weights` (2r + 1 of them).
fn weighted(weights: &[f32], texel: impl Fn(isize) -> [f32; 3]) -> [f32; 3] {
    let radius = (weights.len() / 2) as isize;
    let mut sum = [0.0f32; 3];
    for (i, w) in weights.iter().enumerate() {
        let t = texel(i as isize - radius);
        for c in 0..3 {
            sum[c] += w * t[c];
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mean and the variance of channel 0's texels.
    fn mean_and_variance(env: &Environment) -> (f64, f64) {
        let values: Vec<f64> = env.texels.iter().map(|t| t[0] as f64).collect();
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / values.len() as f64;
        (mean, variance)
    }

    #[test]
    fn blurring_smooths_the_map_and_keeps_its_mean() {
        let studio = Environment::studio();
        let blurred = blurred(&studio, DEFAULT_BLUR_DEGREES);
        assert!(blurred.width < studio.width && blurred.width == 2 * blurred.height);
        let (mean, variance) = mean_and_variance(&studio);
        let (blurred_mean, blurred_variance) = mean_and_variance(&blurred);
        // The means are of texels, not of solid angle: the blur across the rows moves a little
        // radiance between latitudes.
        assert!((blurred_mean - mean).abs() < 0.05 * mean, "mean {mean} became {blurred_mean}");
        assert!(blurred_variance < 0.5 * variance, "variance {variance} became {blurred_variance}");
    }

    #[test]
    fn a_uniform_map_stays_uniform_and_a_wider_blur_is_smoother() {
        let uniform = blurred(&Environment::uniform([0.25, 0.5, 1.0], 64, 32), 10.0);
        assert!(uniform.texels.iter().all(|t| t.iter().zip([0.25, 0.5, 1.0]).all(|(a, b)| (a - b).abs() < 1e-5)));
        let studio = Environment::studio();
        let (_, narrow) = mean_and_variance(&blurred(&studio, 2.0));
        let (_, wide) = mean_and_variance(&blurred(&studio, 20.0));
        assert!(wide < narrow, "{wide} !< {narrow}");
    }

    #[test]
    fn blurs_and_colours_out_of_range_are_refused() {
        assert!(check_blur(DEFAULT_BLUR_DEGREES).is_ok() && check_blur(MAX_BLUR_DEGREES).is_ok());
        for bad in [0.0, -1.0, 91.0, f32::NAN] {
            assert!(check_blur(bad).unwrap_err().starts_with("background_blur"), "{bad}");
        }
        assert!(check_colour([0.0, 0.5, 2.0]).is_ok());
        assert!(check_colour([-0.1, 0.0, 0.0]).is_err() && check_colour([f32::INFINITY, 0.0, 0.0]).is_err());
    }
}
