//! `lookdev render`.

use super::inputs::{self, DisplayArgs, LightingArgs, SamplingArgs};
use super::progress::Progress;
use crate::render::output::{self, OutputFormat};
use crate::render::progressive;
use crate::render::scene::Scene;
use crate::render::Renderer;
use crate::{Error, Result};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The g-buffer EXR to relight (default: the built-in shader ball, 1024x1024).
    #[arg(long, value_name = "FILE.exr")]
    pub gbuffer: Option<PathBuf>,
    /// The look: layer stacks, environment and render settings.
    #[arg(long, value_name = "FILE.toml")]
    pub look: Option<PathBuf>,
    /// Override a parameter on every layer of every object, e.g. --set metallic=1.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    #[command(flatten)]
    pub lighting: LightingArgs,
    #[command(flatten)]
    pub sampling: SamplingArgs,
    #[command(flatten)]
    pub display: DisplayArgs,
    /// Vulkan device to use: part of its name (lavapipe is "llvmpipe").
    #[arg(long, value_name = "NAME")]
    pub device: Option<String>,
    /// No progress bar or summary.
    #[arg(long, short)]
    pub quiet: bool,
    /// Output image: .png (exposure, tone map, sRGB) or .exr (linear radiance).
    #[arg(long, value_name = "FILE.png|FILE.exr")]
    pub out: PathBuf,
}

pub fn run(args: RenderArgs) -> Result<()> {
    let format = OutputFormat::from_path(&args.out)?;
    if let Some(parent) = args.out.parent().filter(|p| !p.as_os_str().is_empty()) {
        if !parent.is_dir() {
            return Err(Error::input_file(&args.out, "the output folder does not exist"));
        }
    }
    let overrides = inputs::overrides(&args.lighting, &args.sampling, &args.display);
    let sets = inputs::parse_sets(&args.set)?;
    let scene =
        Scene::load(args.gbuffer.as_deref(), args.look.as_deref(), &sets, &overrides, &args.lighting.load_options())?;

    let ctx = super::context(args.device.clone())?;
    let counter = ctx.validation_counter();
    scene.check_device(ctx.info())?;
    let device_name = ctx.info().name.clone();
    let settings = &scene.settings;
    let stats = {
        let mut renderer = Renderer::with_model(&ctx, &scene.gbuffer, &scene.environment, &settings.model)?;
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
