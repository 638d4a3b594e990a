//! `lookdev render`.

use super::progress::Progress;
use crate::environment::LoadOptions;
use crate::render::output::{self, OutputFormat};
use crate::render::progressive;
use crate::render::scene::Scene;
use crate::render::settings::Overrides;
use crate::render::tonemap::Tonemap;
use crate::render::Renderer;
use crate::{Error, Result};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The g-buffer EXR to relight (default: the built-in shader ball, 1024x1024).
    #[arg(long, value_name = "FILE.exr")]
    pub gbuffer: Option<PathBuf>,
    /// Equirectangular environment (default: the look's, else the embedded studio).
    #[arg(long, value_name = "FILE.exr|.hdr")]
    pub env: Option<PathBuf>,
    /// Environment rotation about +Y, in degrees.
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    pub rotation: Option<f32>,
    /// Environment radiance scale.
    #[arg(long, value_name = "X")]
    pub intensity: Option<f32>,
    /// The look: layer stacks, environment and render settings.
    #[arg(long, value_name = "FILE.toml")]
    pub look: Option<PathBuf>,
    /// Override a parameter on every layer of every object, e.g. --set metallic=1.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Samples per pixel (each one environment and one BRDF sample).
    #[arg(long, value_name = "N")]
    pub spp: Option<u32>,
    #[arg(long, value_name = "N")]
    pub seed: Option<u32>,
    /// Exposure in stops, for PNG output.
    #[arg(long, value_name = "EV", allow_hyphen_values = true)]
    pub exposure: Option<f32>,
    /// PNG tone map: linear, neutral (Khronos PBR Neutral), aces or agx.
    #[arg(long, value_name = "NAME", value_parser = parse_tonemap)]
    pub tonemap: Option<Tonemap>,
    /// Show black (EXR: transparent) instead of the environment behind the objects.
    #[arg(long)]
    pub no_background: bool,
    /// Vulkan device to use: part of its name (lavapipe is "llvmpipe").
    #[arg(long, value_name = "NAME")]
    pub device: Option<String>,
    /// Read an environment that is not 2:1 as equirectangular anyway.
    #[arg(long)]
    pub env_any_aspect: bool,
    /// Replace NaN, infinite and negative environment texels instead of refusing the file.
    #[arg(long)]
    pub env_clamp: bool,
    /// No progress bar or summary.
    #[arg(long, short)]
    pub quiet: bool,
    /// Output image: .png (exposure, tone map, sRGB) or .exr (linear radiance).
    #[arg(long, value_name = "FILE.png|FILE.exr")]
    pub out: PathBuf,
}

fn parse_tonemap(name: &str) -> std::result::Result<Tonemap, String> {
    Tonemap::from_name(name).ok_or_else(|| format!("unknown tone map '{name}' (expected linear, neutral, aces, agx)"))
}

pub fn run(args: RenderArgs) -> Result<()> {
    let format = OutputFormat::from_path(&args.out)?;
    if let Some(parent) = args.out.parent().filter(|p| !p.as_os_str().is_empty()) {
        if !parent.is_dir() {
            return Err(Error::input_file(&args.out, "the output folder does not exist"));
        }
    }
    let overrides = Overrides {
        environment: args.env.clone(),
        rotation: args.rotation,
        intensity: args.intensity,
        no_background: args.no_background,
        spp: args.spp,
        seed: args.seed,
        exposure: args.exposure,
        tonemap: args.tonemap,
    };
    let env_options = LoadOptions { any_aspect: args.env_any_aspect, clamp_invalid: args.env_clamp };
    let mut sets = Vec::new();
    for text in &args.set {
        sets.push(super::parse_set(text)?);
    }
    let scene = Scene::load(args.gbuffer.as_deref(), args.look.as_deref(), &sets, &overrides, &env_options)?;

    let ctx = super::context(args.device.clone())?;
    let counter = ctx.validation_counter();
    let device_name = ctx.info().name.clone();
    let settings = &scene.settings;
    let stats = {
        let mut renderer = Renderer::new(&ctx, &scene.gbuffer, &scene.environment)?;
        renderer.set_stacks(&scene.stacks)?;
        renderer.set_lighting(settings.lighting);
        renderer.set_seed(settings.seed);
        let mut progress = Progress::new(settings.spp as u64, "rendering", args.quiet);
        let stats = progressive::accumulate(&mut renderer, settings.spp, |done| progress.update(done as u64))?;
        progress.finish();
        let (width, height) = (renderer.width, renderer.height);
        match format {
            OutputFormat::Exr => {
                let radiance = renderer.read_radiance()?;
                output::write_exr(&args.out, width, height, &radiance, settings.lighting.background)?
            }
            OutputFormat::Png => {
                let pixels = renderer.read_display(settings.exposure, settings.tonemap)?;
                output::write_png(&args.out, width, height, &pixels, !settings.lighting.background)?
            }
        }
        stats
    };
    drop(ctx);
    super::check_validation(&counter)?;
    if !args.quiet {
        eprintln!(
            "lookdev: wrote {} ({}x{}, {} spp, {:.2} s on {device_name})",
            args.out.display(),
            scene.gbuffer.width,
            scene.gbuffer.height,
            settings.spp,
            stats.wall.as_secs_f64()
        );
    }
    Ok(())
}
