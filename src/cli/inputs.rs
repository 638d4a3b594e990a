//! The flags every rendering command shares: lighting, sampling, display, and `--set`.

use crate::environment::{self, Environment, LoadOptions};
use crate::gbuffer::GBuffer;
use crate::material::{Look, Param, Value};
use crate::render::settings::{Overrides, Settings};
use crate::render::tonemap::Tonemap;
use crate::Result;
use clap::Args;
use std::path::PathBuf;

/// The environment and how it lights the scene.
#[derive(Args, Debug, Default)]
pub struct LightingArgs {
    /// Equirectangular environment (default: the look's, else the embedded studio).
    #[arg(long, value_name = "FILE.exr|.hdr")]
    pub env: Option<PathBuf>,
    /// Environment rotation about +Y, in degrees.
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    pub rotation: Option<f32>,
    /// Environment radiance scale.
    #[arg(long, value_name = "X")]
    pub intensity: Option<f32>,
    /// Show black (EXR: transparent) instead of the environment behind the objects.
    #[arg(long)]
    pub no_background: bool,
    /// Read an environment that is not 2:1 as equirectangular anyway.
    #[arg(long)]
    pub env_any_aspect: bool,
    /// Replace NaN, infinite and negative environment texels instead of refusing the file.
    #[arg(long)]
    pub env_clamp: bool,
}

impl LightingArgs {
    pub fn load_options(&self) -> LoadOptions {
        LoadOptions { any_aspect: self.env_any_aspect, clamp_invalid: self.env_clamp }
    }
}

/// Samples per pixel, the sequence's seed, and the BRDF model they estimate.
#[derive(Args, Debug, Default)]
pub struct SamplingArgs {
    /// Samples per pixel (each one environment and one BRDF sample).
    #[arg(long, value_name = "N")]
    pub spp: Option<u32>,
    #[arg(long, value_name = "N")]
    pub seed: Option<u32>,
    /// Choose a BRDF model variant over the look's [model], e.g. --model diffuse=oren-nayar
    /// (keys: diffuse, specular_d, specular_g, fresnel, gtr_gamma, energy_compensation).
    #[arg(long = "model", value_name = "KEY=VALUE")]
    pub model: Vec<String>,
}

/// How linear radiance becomes PNG pixels.
#[derive(Args, Debug, Default)]
pub struct DisplayArgs {
    /// Exposure in stops, for PNG output.
    #[arg(long, value_name = "EV", allow_hyphen_values = true)]
    pub exposure: Option<f32>,
    /// PNG tone map: linear, neutral (Khronos PBR Neutral), aces or agx.
    #[arg(long, value_name = "NAME", value_parser = Tonemap::parse)]
    pub tonemap: Option<Tonemap>,
}

/// The command-line overrides of a look's settings.
pub fn overrides(lighting: &LightingArgs, sampling: &SamplingArgs, display: &DisplayArgs) -> Overrides {
    Overrides {
        environment: lighting.env.clone(),
        rotation: lighting.rotation,
        intensity: lighting.intensity,
        no_background: lighting.no_background,
        spp: sampling.spp,
        seed: sampling.seed,
        exposure: display.exposure,
        tonemap: display.tonemap,
        model: sampling.model.clone(),
    }
}

/// Parses every `--set NAME=VALUE`.
pub fn parse_sets(texts: &[String]) -> Result<Vec<(Param, Value)>> {
    texts.iter().map(|t| super::parse_set(t)).collect()
}

/// What `presets sheet` and `wedge` render with: the settings of `look` under the flags, `spp`
/// and `model`, its environment, and the built-in shader ball `size` pixels square.
pub fn ball_inputs(
    look: &Look,
    lighting: &LightingArgs,
    display: &DisplayArgs,
    spp: u32,
    model: &[String],
    size: u32,
) -> Result<(Settings, Environment, GBuffer)> {
    let sampling = SamplingArgs { spp: Some(spp), model: model.to_vec(), ..SamplingArgs::default() };
    let settings = Settings::resolve(look, &overrides(lighting, &sampling, display))?;
    let environment = match &settings.environment {
        Some(path) => environment::load::load(path, &lighting.load_options())?,
        None => Environment::studio(),
    };
    let gbuffer = GBuffer::shaderball(size, size);
    let name = std::path::Path::new("built-in shader ball");
    crate::render::scene::dark_render_warnings(&gbuffer, name, &environment, settings.lighting.intensity)
        .into_iter()
        .for_each(crate::warn);
    Ok((settings, environment, gbuffer))
}
