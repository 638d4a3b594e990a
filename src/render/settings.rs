//! Render settings: the look's values, overridden by command-line flags, over the defaults.

use super::Lighting;
use crate::environment::{Backdrop, EnvironmentRef};
use crate::material::Look;
use crate::shading::model::Model;
use crate::shading::tonemap::{Tonemap, MAX_EXPOSURE};
use crate::{Error, Result};

/// Samples per pixel when neither the look nor a flag says.
pub const DEFAULT_SPP: u32 = 256;

/// The least `--min-spp` when none is given: enough samples that the variance estimate that
/// decides a pixel's stop is itself not too noisy.
pub const DEFAULT_MIN_SPP: u32 = 16;

/// Adaptive sampling (docs/shading.md#adaptive-sampling): each pixel stops once the estimated
/// relative error of its mean, tested after `min_samples` and at each power of two after, is below
/// `threshold`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseThreshold {
    /// The relative standard error of the mean luminance at which a pixel stops (0 < t < 1e3).
    pub threshold: f32,
    /// The samples every pixel takes before it may stop (at least 2).
    pub min_samples: u32,
}

impl NoiseThreshold {
    /// Checks the values, naming the options they come from.
    pub fn new(threshold: f32, min_samples: u32) -> Result<NoiseThreshold> {
        if !(threshold.is_finite() && threshold > 0.0 && threshold < 1e3) {
            return Err(Error::input(format!(
                "--noise-threshold {threshold}: must be a number above 0 and below 1000"
            )));
        }
        if min_samples < 2 {
            return Err(Error::input(format!(
                "--min-spp {min_samples}: a pixel needs at least 2 samples to estimate its noise"
            )));
        }
        Ok(NoiseThreshold { threshold, min_samples })
    }

    /// Samples from `samples` to the next stop test (`checkpoint` in relight.comp): at
    /// `min_samples`, then at each power of two above it. A dispatch that ends there lets no
    /// pixel go on sampling past a test it would pass while the others in its SIMD group finish.
    pub fn to_checkpoint(&self, samples: u32) -> u32 {
        if samples < self.min_samples {
            self.min_samples - samples
        } else {
            (samples + 1).next_power_of_two() - samples
        }
    }
}

/// Values given on the command line; `None` leaves the look's value.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    pub environment: Option<EnvironmentRef>,
    pub rotation: Option<f32>,
    pub intensity: Option<f32>,
    pub no_background: bool,
    pub spp: Option<u32>,
    pub seed: Option<u32>,
    pub exposure: Option<f32>,
    pub tonemap: Option<Tonemap>,
    /// `--model KEY=VALUE`, applied in order over the look's `[model]`.
    pub model: Vec<String>,
    /// `--aov NAME`: when given, these AOVs instead of the look's `[render] aovs`.
    pub aovs: Vec<String>,
    /// `--sampling NAME`: the estimator, instead of the default.
    pub sampling: Option<crate::render::sampling::Sampling>,
    /// `--noise-threshold X`: adaptive sampling, with `spp` the most a pixel takes.
    pub noise_threshold: Option<f32>,
    /// `--min-spp N`: the samples a pixel takes before it may stop ([`DEFAULT_MIN_SPP`]).
    pub min_spp: Option<u32>,
}

/// Everything a render needs besides the g-buffer and the stacks.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// None: the default built-in environment.
    pub environment: Option<EnvironmentRef>,
    pub lighting: Lighting,
    /// What the background is where [`Lighting::background`] shows one.
    pub backdrop: Backdrop,
    pub spp: u32,
    pub seed: u32,
    pub exposure: f32,
    pub tonemap: Tonemap,
    /// The BRDF model.
    pub model: Model,
    /// The AOVs to write beside the beauty.
    pub aovs: Vec<crate::render::aov::Aov>,
    /// The estimator (docs/shading.md#sampling).
    pub sampling: crate::render::sampling::Sampling,
    /// Adaptive sampling, when asked for: `spp` is then the most a pixel takes.
    pub noise: Option<NoiseThreshold>,
}

impl Settings {
    pub fn resolve(look: &Look, overrides: &Overrides) -> Result<Settings> {
        let env = &look.environment;
        let render = &look.render;
        let spp = overrides.spp.or(render.spp).unwrap_or(DEFAULT_SPP);
        if spp == 0 {
            return Err(Error::input("--spp 0: the sample count must be at least 1"));
        }
        let finite = |name: &str, v: f32| {
            if v.is_finite() {
                Ok(v)
            } else {
                Err(Error::input(format!("--{name} {v}: must be a finite number")))
            }
        };
        // The look's own value was checked where it was read, with its file and line.
        if let Some(intensity) = overrides.intensity {
            crate::environment::check_intensity(intensity).map_err(|e| Error::input(format!("--{e}")))?;
        }
        let intensity = overrides.intensity.or(env.intensity).unwrap_or(1.0);
        // The look's own value was checked where it was read, with its file and line.
        let exposure = finite("exposure", overrides.exposure.unwrap_or(0.0))?;
        if exposure.abs() > MAX_EXPOSURE {
            return Err(Error::input(format!("--exposure {exposure}: must be within ±{MAX_EXPOSURE} stops")));
        }
        let exposure = overrides.exposure.or(render.exposure).unwrap_or(0.0);
        let mut model = look.model.unwrap_or_default();
        for text in &overrides.model {
            model.set_from_text(text).map_err(Error::input)?;
        }
        let aov_names =
            if overrides.aovs.is_empty() { render.aovs.clone().unwrap_or_default() } else { overrides.aovs.clone() };
        let aovs = crate::render::aov::Aov::parse_all(&aov_names).map_err(|e| Error::input(format!("--aov: {e}")))?;
        let noise = noise_threshold(look, overrides, spp)?;
        Ok(Settings {
            noise,
            aovs,
            model,
            environment: overrides.environment.clone().or_else(|| env.source.clone()),
            lighting: Lighting {
                rotation_degrees: finite("rotation", overrides.rotation.or(env.rotation).unwrap_or(0.0))?,
                intensity,
                background: !overrides.no_background && env.background.unwrap_or(true),
            },
            backdrop: env.backdrop.clone().unwrap_or_default(),
            spp,
            seed: overrides.seed.or(render.seed).unwrap_or(0),
            exposure,
            tonemap: overrides.tonemap.or(render.tonemap).unwrap_or_default(),
            sampling: overrides.sampling.unwrap_or_default(),
        })
    }
}

/// Adaptive sampling as the flags, else the look's `[render]`, ask for it. Each value's
/// problem names where it came from: the flag, or the look's file.
fn noise_threshold(look: &Look, overrides: &Overrides, spp: u32) -> Result<Option<NoiseThreshold>> {
    let render = &look.render;
    let min_spp = match (overrides.min_spp, render.min_spp) {
        (Some(n), _) => Some((n, format!("--min-spp {n}"))),
        (None, Some(n)) => Some((n, format!("{}: [render] min_spp = {n}", look.place("render.min_spp")))),
        (None, None) => None,
    };
    let threshold = overrides.noise_threshold.or(render.noise_threshold);
    match (threshold, min_spp) {
        (None, None) => Ok(None),
        (None, Some((_, source))) => Err(Error::input(format!(
            "{source}: only adaptive sampling takes it (a noise threshold: [render] noise_threshold, or --noise-threshold)"
        ))),
        (Some(_), Some((min_spp, source))) if min_spp > spp => {
            Err(Error::input(format!("{source}: above spp, the most samples a pixel takes ({spp})")))
        }
        (Some(threshold), Some((min_spp, _))) => NoiseThreshold::new(threshold, min_spp).map(Some),
        // With fewer samples than that in all, the pixels take them all.
        (Some(threshold), None) => NoiseThreshold::new(threshold, DEFAULT_MIN_SPP.min(spp).max(2)).map(Some),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checkpoints_are_the_minimum_then_each_power_of_two_above_it() {
        let noise = NoiseThreshold::new(0.05, 6).unwrap();
        let next: Vec<u32> = [0, 5, 6, 7, 8, 9, 31, 32].iter().map(|&s| s + noise.to_checkpoint(s)).collect();
        assert_eq!(next, [6, 6, 8, 8, 16, 16, 32, 64]);
        let four = NoiseThreshold::new(0.05, 4).unwrap();
        assert_eq!([0, 4, 5].map(|s| s + four.to_checkpoint(s)), [4, 8, 8]);
    }
}
