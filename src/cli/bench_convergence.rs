//! `lookdev bench --convergence`: the noise of each estimator (docs/shading.md#sampling) against
//! a high-spp reference, at equal samples and at equal time, in one run.
//!
//! The reference is rendered with another seed, so its own noise is independent of the images
//! measured; at its default 2048 spp it adds about 1/32 of a 64-spp image's error. Each
//! estimator then accumulates from scratch through the sample counts asked for, timed as
//! `lookdev render` accumulates (wall time of the passes, read-backs excluded).

use super::inputs::GBufferArgs;
use crate::environment::EnvironmentRef;
use crate::render::sampling::Sampling;
use crate::render::scene::{GBufferSpec, LookSource, Scene, SceneSpec, MAX_BUILTIN_SIDE};
use crate::render::settings::Overrides;
use crate::render::{progressive, Renderer};
use crate::{Error, Result};
use clap::Args;
use std::path::PathBuf;

/// The seed of the reference: any other than the measured images' (0).
const REFERENCE_SEED: u32 = 0x9e37_79b9;

/// What `--convergence` renders and how.
#[derive(Args, Debug)]
pub struct ConvergenceArgs {
    /// With --convergence or --adaptive: the look (default: the built-in default look).
    #[arg(long, value_name = "FILE.toml")]
    pub look: Option<PathBuf>,
    #[command(flatten)]
    pub gbuffer: GBufferArgs,
    /// With --convergence or --adaptive: the environment, as `render --env` takes it.
    #[arg(long, value_name = "FILE.exr|.hdr|NAME", value_parser = EnvironmentRef::parse)]
    pub env: Option<EnvironmentRef>,
    /// With --convergence or --adaptive: environment rotation about +Y, in degrees.
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    pub rotation: Option<f32>,
    /// With --convergence or --adaptive: override a parameter on every layer, e.g. --set metallic=1.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// With --convergence or --adaptive: a BRDF model variant, as `render --model` takes it.
    #[arg(long = "model", value_name = "KEY=VALUE")]
    pub model: Vec<String>,
    /// With --convergence or --adaptive: the built-in shader ball's size (not with --gbuffer).
    #[arg(long, num_args = 2, value_names = ["W", "H"], default_values_t = [256, 256])]
    pub size: Vec<u32>,
    /// With --convergence: samples per pixel of the reference.
    #[arg(long, default_value_t = 2048, value_name = "N")]
    pub reference_spp: u32,
    /// With --convergence: the sample counts at which each estimator is measured.
    #[arg(long, value_delimiter = ',', default_values_t = [4, 16, 64], value_name = "N,N,…")]
    pub convergence_spp: Vec<u32>,
    /// With --convergence: the estimators measured, in order (default: all); the first is the
    /// one the others are compared with.
    #[arg(long, value_delimiter = ',', value_parser = Sampling::parse, value_name = "NAME,…")]
    pub sampling: Vec<Sampling>,
}

/// Relative mean squared error of `image` against `reference` (linear radiance, RGBA): the mean
/// over pixels of coverage 1 and over the RGB channels of (x − r)²/(r² + 0.01).
pub fn relative_mse(image: &[[f32; 4]], reference: &[[f32; 4]], coverage: &[f32]) -> f64 {
    let (mut sum, mut count) = (0.0f64, 0usize);
    for ((x, r), &a) in image.iter().zip(reference).zip(coverage) {
        if a != 1.0 {
            continue;
        }
        for c in 0..3 {
            let (x, r) = (x[c] as f64, r[c] as f64);
            sum += (x - r) * (x - r) / (r * r + 1e-2);
        }
        count += 3;
    }
    if count == 0 {
        0.0
    } else {
        sum / count as f64
    }
}

impl ConvergenceArgs {
    fn spec(&self) -> Result<SceneSpec> {
        let max = self.convergence_spp.iter().copied().max().unwrap_or(0);
        if self.convergence_spp.contains(&0) || max == 0 {
            return Err(Error::input("--convergence-spp: each sample count must be at least 1"));
        }
        if self.reference_spp <= max {
            return Err(Error::input(format!(
                "--reference-spp {}: the reference needs more samples than the largest --convergence-spp ({max})",
                self.reference_spp
            )));
        }
        self.scene_spec()
    }

    /// The scene measured, as `--convergence` and `--adaptive` take it: the built-in shader ball
    /// at `--size`, or the g-buffer, look, environment and overrides given.
    pub fn scene_spec(&self) -> Result<SceneSpec> {
        let [width, height] = self.size[..] else {
            return Err(Error::input("--size takes a width and a height, e.g. --size 256 256"));
        };
        if !(1..=MAX_BUILTIN_SIDE).contains(&width) || !(1..=MAX_BUILTIN_SIDE).contains(&height) {
            return Err(Error::input(format!(
                "--size {width} {height}: each side must be 1 to {MAX_BUILTIN_SIDE} pixels"
            )));
        }
        Ok(SceneSpec {
            look: self.look.clone().map_or(LookSource::Default, LookSource::File),
            gbuffer: GBufferSpec { builtin_size: Some((width, height)), ..self.gbuffer.spec()? },
            sets: self.set.iter().map(|t| super::parse_set(t)).collect::<Result<_>>()?,
            overrides: Overrides {
                environment: self.env.clone(),
                rotation: self.rotation,
                model: self.model.clone(),
                ..Overrides::default()
            },
            quiet: true,
            ..SceneSpec::default()
        })
    }
}

pub fn run(args: &super::bench::BenchArgs) -> Result<()> {
    let conv = &args.convergence_args;
    let spec = conv.spec()?;
    let mut counts = conv.convergence_spp.clone();
    counts.sort_unstable();
    counts.dedup();
    let samplings = if conv.sampling.is_empty() { Sampling::ALL.to_vec() } else { conv.sampling.clone() };
    let scene = Scene::load(&spec)?;
    let ctx = super::context(args.device.clone())?;
    let counter = ctx.validation_counter();
    scene.check_device(ctx.info())?;
    let gbuffer = &scene.gbuffer;
    let covered = gbuffer.coverage.iter().filter(|&&a| a == 1.0).count();
    println!("device: {}", ctx.info().name);
    println!(
        "scene: {} ({}x{}, {covered} fully covered pixels), look {}, environment {}",
        scene.gbuffer_name.display(),
        gbuffer.width,
        gbuffer.height,
        conv.look.as_ref().map_or("built-in default".to_string(), |p| p.display().to_string()),
        scene.environment.source
    );
    if covered == 0 {
        return Err(Error::input("bench --convergence: the g-buffer has no fully covered pixel to measure"));
    }
    let mut renderer = Renderer::with_model(&ctx, gbuffer, &scene.environment, &scene.settings.model)?;
    renderer.set_stacks(&scene.stacks)?;
    renderer.set_lighting(scene.settings.lighting);

    let reference_wall = {
        renderer.set_seed(REFERENCE_SEED);
        progressive::accumulate(&mut renderer, conv.reference_spp, |_| {})?.wall.as_secs_f64()
    };
    let reference = renderer.read_radiance()?;
    println!(
        "reference: {} spp with {} (seed {REFERENCE_SEED:#x}), {reference_wall:.2} s",
        conv.reference_spp,
        renderer.sampling()
    );
    println!(
        "relMSE: mean over covered pixels and RGB of (x − r)²/(r² + 0.01); efficiency 1/(time × relMSE); \
         ratios against {}",
        samplings[0]
    );
    println!(
        "{:>12} {:>6} {:>11} {:>9} {:>11} {:>13} {:>13}",
        "sampling", "spp", "relMSE", "time (s)", "efficiency", "relMSE ratio", "effic. ratio"
    );
    // (relMSE, efficiency) of the first estimator, per sample count.
    let mut baseline: Vec<(f64, f64)> = Vec::new();
    for (index, &sampling) in samplings.iter().enumerate() {
        renderer.set_sampling(sampling, &scene.environment)?;
        renderer.set_seed(0);
        renderer.restart();
        let mut wall = 0.0;
        for (k, &spp) in counts.iter().enumerate() {
            wall += progressive::accumulate(&mut renderer, spp, |_| {})?.wall.as_secs_f64();
            let error = relative_mse(&renderer.read_radiance()?, &reference, &gbuffer.coverage);
            let efficiency = 1.0 / (wall * error);
            if index == 0 {
                baseline.push((error, efficiency));
            }
            let (base_error, base_efficiency) = baseline[k];
            println!(
                "{:>12} {:>6} {:>11.4e} {:>9.3} {:>11.4e} {:>12.2}× {:>12.2}×",
                sampling.name(),
                spp,
                error,
                wall,
                efficiency,
                base_error / error,
                efficiency / base_efficiency
            );
        }
    }
    drop(renderer);
    drop(ctx);
    super::check_validation(&counter)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_mse_counts_fully_covered_pixels_and_weighs_by_the_reference() {
        let reference = [[1.0, 0.0, 2.0, 1.0], [5.0, 5.0, 5.0, 1.0], [0.0; 4]];
        let image = [[1.5, 0.1, 2.0, 1.0], [9.0, 9.0, 9.0, 1.0], [1.0; 4]];
        // Only the first pixel is fully covered.
        let got = relative_mse(&image, &reference, &[1.0, 0.5, 0.0]);
        let want = (0.25 / 1.01 + 0.01 / 0.01 + 0.0) / 3.0;
        assert!((got - want).abs() < 1e-6, "{got} vs {want}");
        assert_eq!(relative_mse(&image, &reference, &[0.0; 3]), 0.0);
    }
}
