//! `lookdev render`.

use super::inputs::SceneArgs;
use super::progress::Progress;
use crate::gpu::{Context, ContextOptions};
use crate::render::aov::{self, Aov};
use crate::render::compare::{self, Summary};
use crate::render::downsample;
use crate::render::output::{self, Metadata, OutputFormat};
use crate::render::progressive::{self, RenderStats};
use crate::render::renderer::{KernelSource, Specialization};
use crate::render::scene::{LookSource, Scene, SceneSpec};
use crate::render::settings::{Overrides, Settings};
use crate::render::startup::{self, Started};
use crate::render::Renderer;
use crate::shading::model::Model;
use crate::{Error, Result};
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The look: layer stacks, environment and render settings.
    #[arg(long, value_name = "FILE.toml")]
    pub look: Option<PathBuf>,
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Vulkan device to use: part of its name (lavapipe is "llvmpipe").
    #[arg(long, value_name = "NAME")]
    pub device: Option<String>,
    /// No progress bar or summary.
    #[arg(long, short)]
    pub quiet: bool,
    /// Output image: .png (exposure, tone map, sRGB) or .exr (linear radiance).
    #[arg(long, value_name = "FILE.png|FILE.exr")]
    pub out: PathBuf,
    /// Render twice and compare: A is this render, B the same with the look B.toml; or, without
    /// a file, A is the look's own BRDF model and B the model with the --model changes. Writes A
    /// and B side by side to --out, their ΔE*ab to <out>.diff.png, and prints the statistics.
    #[arg(long, value_name = "B.toml", num_args = 0..=1)]
    pub compare: Option<Option<PathBuf>>,
    /// Write an AOV beside the beauty in EXR output (repeatable; instead of the look's
    /// [render] aovs): diffuse, specular, clearcoat, sheen, emission, albedo, a parameter's name,
    /// layers, N, V, objectId, variance, masks, maps, or the groups light, material, geometry, error,
    /// inputs, all.
    #[arg(long = "aov", value_name = "NAME")]
    pub aovs: Vec<String>,
    /// PNG output: show this AOV instead of the beauty.
    #[arg(long, value_name = "NAME")]
    pub aov_display: Option<String>,
    #[command(flatten)]
    pub adaptive: AdaptiveArgs,
}

/// Adaptive sampling (docs/shading.md#adaptive-sampling), for `render` and `turntable`.
#[derive(Args, Debug, Default)]
pub struct AdaptiveArgs {
    /// Adaptive sampling: each pixel stops once the estimated relative error of its mean
    /// luminance is below X (e.g. 0.02); --spp is then the most a pixel takes.
    #[arg(long, value_name = "X")]
    pub noise_threshold: Option<f32>,
    /// With --noise-threshold: the samples every pixel takes before it may stop (default 16).
    #[arg(long, value_name = "N")]
    pub min_spp: Option<u32>,
}

impl AdaptiveArgs {
    /// Sets these options in `overrides`.
    pub fn apply(&self, overrides: &mut Overrides) {
        overrides.noise_threshold = self.noise_threshold;
        overrides.min_spp = self.min_spp;
    }
}

/// One render, read back for output.
struct Rendered {
    width: u32,
    height: u32,
    /// Display pixels, RGBA8 sRGB, after exposure and the tone map; empty unless asked for.
    display: Vec<u8>,
    /// Linear radiance, for EXR output.
    radiance: Option<Vec<[f32; 4]>>,
    /// The AOVs asked for, as EXR layers.
    aovs: Vec<aov::Layer>,
    stats: RenderStats,
}

impl Rendered {
    /// The render filtered down by the g-buffer's supersampling `factor`
    /// (crate::render::downsample): the display pixels are made again from the filtered radiance.
    fn downsampled(self, factor: u32, settings: &Settings) -> Rendered {
        if factor == 1 {
            return self;
        }
        let radiance = self.radiance.map(|r| downsample::box_filter(&r, self.width, factor));
        let display = match &radiance {
            Some(r) if !self.display.is_empty() => {
                downsample::display(r, settings.exposure, settings.tonemap, settings.lighting.background)
            }
            _ => Vec::new(),
        };
        Rendered {
            width: self.width / factor,
            height: self.height / factor,
            display,
            radiance,
            aovs: self.aovs.into_iter().map(|layer| downsample::layer(layer, self.width, factor)).collect(),
            stats: self.stats,
        }
    }
}

/// Relights `scene` on `ctx` with `kernels` (specialised for the settings and `aovs`, see
/// [`kernels_for`]) and reads back what the output needs: the radiance, the AOVs `aovs`, and
/// the display pixels when `display` is set. With `last_use`, what only the upload needed is
/// let go of once uploaded.
#[allow(clippy::too_many_arguments)]
fn render(
    ctx: &Context,
    scene: &mut Scene,
    kernels: KernelSource,
    aovs: &[Aov],
    display: bool,
    label: &str,
    quiet: bool,
    last_use: bool,
) -> Result<Rendered> {
    scene.check_device(ctx.info())?;
    let settings = &scene.settings;
    let timing = crate::timings::phase("renderer");
    let mut renderer = Renderer::with_kernels(ctx, &scene.gbuffer, &scene.environment, settings.sampling, kernels)?;
    // The device holds the visibility now; the host's copy, as large as the rest of the
    // g-buffer or larger, is kept only for the occlusion AOV or another render of the scene.
    if last_use && !aovs.contains(&Aov::Occlusion) {
        scene.gbuffer.visibility = None;
    }
    // The noise threshold before the AOVs: together they give the kernels' specialisation.
    renderer.set_noise_threshold(settings.noise)?;
    renderer.set_accumulate(aov::accumulate(aovs))?;
    renderer.set_stacks(&scene.stacks)?;
    renderer.set_lighting(settings.lighting);
    renderer.set_backdrop(&scene.backdrop)?;
    renderer.set_seed(settings.seed);
    drop(timing);
    let timing = crate::timings::phase("render");
    let mut progress = Progress::new(settings.spp as u64, label, quiet);
    let stats = progressive::accumulate(&mut renderer, settings.spp, |done| progress.update(done as u64))?;
    progress.finish();
    drop(timing);
    let _timing = crate::timings::phase("read back");
    let sources = aov::Sources { gbuffer: &scene.gbuffer, look: &scene.look, renderer: &renderer };
    let rendered = Rendered {
        width: renderer.width,
        height: renderer.height,
        display: if display { renderer.read_display(settings.exposure, settings.tonemap)? } else { Vec::new() },
        radiance: Some(renderer.read_radiance()?),
        aovs: aov::layers(aovs, &sources)?,
        stats,
    };
    Ok(rendered.downsampled(scene.gbuffer.supersample, settings))
}

pub fn run(args: RenderArgs) -> Result<()> {
    let format = OutputFormat::from_path(&args.out)?;
    if let Some(parent) = args.out.parent().filter(|p| !p.as_os_str().is_empty()) {
        if !parent.is_dir() {
            return Err(Error::input_file(&args.out, "the output folder does not exist"));
        }
    }
    if format == OutputFormat::Png && !args.aovs.is_empty() {
        return Err(Error::input(format!(
            "--aov {}: a PNG holds only the image; write an .exr to keep AOVs, or show one in the PNG with --aov-display NAME",
            args.aovs.join(" --aov ")
        )));
    }
    let mut spec = args.scene.spec(args.look.as_deref(), &args.aovs, args.quiet)?;
    args.adaptive.apply(&mut spec.overrides);
    if let Some(second) = &args.compare {
        return run_compare(&args, format, second.as_deref(), &spec);
    }
    let display = args.aov_display.as_deref().map(|name| display_aov(name, format)).transpose()?;
    // The device opens while the scene loads, and the kernels compile while the scene uploads
    // (crate::render::startup).
    let options = ContextOptions::from_env(args.device.clone());
    let (scene, mut rendered, device_name) = std::thread::scope(|threads| -> Result<_> {
        let specialize = |scene: &Scene| kernels_for(scene, &output_aovs(format, display, &scene.settings));
        let Started { mut scene, ctx, kernels } = startup::start(threads, &spec, options, specialize)?;
        // Every input is read by now: refuse before the work, not after it.
        crate::input::refuse_replacing_input(&args.out)?;
        let counter = ctx.validation_counter();
        let device_name = ctx.info().name.clone();
        let aovs = output_aovs(format, display, &scene.settings);
        if format == OutputFormat::Png && !scene.settings.aovs.is_empty() {
            crate::warn(format!(
                "the look's [render] aovs are not written into a PNG ({}): write an .exr to keep them",
                args.out.display()
            ));
        }
        // Only a PNG of the beauty shows the display pixels.
        let beauty_png = format == OutputFormat::Png && display.is_none();
        let rendered =
            render(&ctx, &mut scene, KernelSource::Pending(kernels), &aovs, beauty_png, "rendering", args.quiet, true)?;
        drop(ctx);
        super::check_validation(&counter)?;
        Ok((scene, rendered, device_name))
    })?;
    let settings = &scene.settings;
    let _timing = crate::timings::phase("write");
    let metadata = Metadata::of_render(&scene.look, settings, &scene.environment, &scene.recorded);
    match display {
        Some(aov) => write_aov_png(&args.out, &rendered, aov, settings)?,
        None => write(&args.out, format, &mut rendered, settings.lighting.background, &metadata)?,
    }
    if !args.quiet {
        let spp = match rendered.stats.mean_spp {
            Some(mean) => format!("{mean:.1} spp on average, at most {}", settings.spp),
            None => format!("{} spp", settings.spp),
        };
        eprintln!(
            "lookdev: wrote {} ({}x{}{}, {spp}, {:.2} s on {device_name})",
            args.out.display(),
            rendered.width,
            rendered.height,
            match scene.gbuffer.supersample {
                1 => String::new(),
                n => format!(" from a g-buffer supersampled {n}x{n}"),
            },
            rendered.stats.wall.as_secs_f64()
        );
    }
    Ok(())
}

/// The AOVs the output writes: an EXR the ones asked for, a PNG the one it shows.
fn output_aovs(format: OutputFormat, display: Option<Aov>, settings: &Settings) -> Vec<Aov> {
    match (format, display) {
        (OutputFormat::Exr, _) => settings.aovs.clone(),
        (OutputFormat::Png, Some(aov)) => vec![aov],
        (OutputFormat::Png, None) => Vec::new(),
    }
}

/// The kernels a render of `scene` writing `aovs` needs.
fn kernels_for(scene: &Scene, aovs: &[Aov]) -> Specialization {
    Specialization::of_render(scene, aov::accumulate(aovs))
}

/// The one AOV `--aov-display` shows in a PNG.
fn display_aov(name: &str, format: OutputFormat) -> Result<Aov> {
    if format != OutputFormat::Png {
        return Err(Error::input(format!("--aov-display {name}: only a PNG shows one AOV; an EXR takes --aov")));
    }
    match Aov::parse(name).map_err(|e| Error::input(format!("--aov-display: {e}")))?[..] {
        [aov] if !matches!(aov, Aov::Layers | Aov::Masks | Aov::Maps) => Ok(aov),
        _ => Err(Error::input(format!("--aov-display {name}: name one AOV, not a group"))),
    }
}

/// A PNG of one AOV: radiance and colours through exposure and the tone map, like the beauty;
/// other values as they are (normals and view vectors mapped from [-1, 1], ids as distinct
/// colours, variance as its square root, the standard error).
fn write_aov_png(
    path: &Path,
    rendered: &Rendered,
    aov: Aov,
    settings: &crate::render::settings::Settings,
) -> Result<()> {
    let layer = rendered.aovs.first().expect("the displayed AOV was computed");
    let pixels = (rendered.width * rendered.height) as usize;
    let channel = |k: usize| &layer.channels[k.min(layer.channels.len() - 1)].1;
    let mut rgba = Vec::with_capacity(pixels * 4);
    for p in 0..pixels {
        let value = glam::Vec3::new(channel(0)[p], channel(1)[p], channel(2)[p]);
        let rgb = match aov {
            a if a.is_radiance() => crate::shading::tonemap::display_pixel(value, settings.exposure, settings.tonemap),
            Aov::Normal | Aov::View => encode(value * 0.5 + 0.5),
            Aov::ObjectId => crate::render::aov::id_colour(value.x as u32),
            Aov::Variance => encode(glam::Vec3::splat(value.x.sqrt())),
            _ => encode(value),
        };
        rgba.extend([rgb[0], rgb[1], rgb[2], 255]);
    }
    output::write_png(path, rendered.width, rendered.height, &rgba, false)
}

/// A value in [0, 1] as sRGB bytes.
fn encode(v: glam::Vec3) -> [u8; 3] {
    v.to_array().map(|c| (crate::shading::tonemap::srgb_encode(c.clamp(0.0, 1.0)) * 255.0 + 0.5) as u8)
}

fn write(
    path: &Path,
    format: OutputFormat,
    rendered: &mut Rendered,
    background: bool,
    metadata: &Metadata,
) -> Result<()> {
    let (width, height) = (rendered.width, rendered.height);
    let aovs = std::mem::take(&mut rendered.aovs);
    match (format, &rendered.radiance) {
        (OutputFormat::Exr, Some(radiance)) => {
            output::write_exr_with(path, width, height, radiance, background, aovs, &metadata.entries)
        }
        (_, radiance) => {
            // The display pixels are 8-bit; the radiance behind them shows whether any is not finite.
            radiance.as_deref().map_or(Ok(()), |radiance| output::check_finite(path, radiance))?;
            output::write_png(path, width, height, &rendered.display, !background)
        }
    }
}

/// `--compare`: renders A and B, writes them side by side and their difference, and prints the
/// difference's statistics.
fn run_compare(args: &RenderArgs, format: OutputFormat, second_look: Option<&Path>, spec: &SceneSpec) -> Result<()> {
    let overrides = &spec.overrides;
    let with_look = |look: &Path| SceneSpec { look: LookSource::File(look.to_path_buf()), ..spec.clone() };
    let look_name = |look: Option<&Path>| match look.and_then(Path::file_name) {
        Some(name) => name.to_string_lossy().into_owned(),
        None if spec.gbuffer.file.is_none() => "built-in look".to_string(),
        None => "default material".to_string(),
    };
    // B is either a second look, read on its own, or A's scene with another model: then the
    // g-buffer and environment are read once and only the model changes between the renders.
    enum Second {
        Look(Box<Scene>),
        Model(Model),
    }
    let (mut a, second_scene) = match second_look {
        Some(b_look) => (Scene::load(spec)?, Second::Look(Box::new(Scene::load(&with_look(b_look))?))),
        None if !overrides.model.is_empty() => {
            let a = Scene::load(&SceneSpec {
                overrides: Overrides { model: Vec::new(), ..overrides.clone() },
                ..spec.clone()
            })?;
            let mut model = a.settings.model;
            for text in &overrides.model {
                model.set_from_text(text).map_err(Error::input)?;
            }
            (a, Second::Model(model))
        }
        None => {
            return Err(Error::input(
                "--compare needs something to compare with: a second look (--compare B.toml) or --model KEY=VALUE",
            ))
        }
    };
    let label = |model: &Model, look: Option<&Path>| format!("{}, model: {model}", look_name(look));
    let a_label = label(&a.settings.model, args.look.as_deref());
    let b_label = match &second_scene {
        Second::Look(b) => label(&b.settings.model, second_look),
        Second::Model(model) => label(model, args.look.as_deref()),
    };

    let ctx = super::context(args.device.clone())?;
    let counter = ctx.validation_counter();
    let device_name = ctx.info().name.clone();
    let kernels = |scene: &Scene| KernelSource::Compile(kernels_for(scene, &[]));
    let a_kernels = kernels(&a);
    let first = render(&ctx, &mut a, a_kernels, &[], true, "rendering A", args.quiet, false)?;
    let second = match second_scene {
        Second::Look(mut b) => {
            let b_kernels = kernels(&b);
            render(&ctx, &mut b, b_kernels, &[], true, "rendering B", args.quiet, true)?
        }
        Second::Model(model) => {
            a.settings.model = model;
            let a_kernels = kernels(&a);
            render(&ctx, &mut a, a_kernels, &[], true, "rendering B", args.quiet, true)?
        }
    };
    drop(ctx);
    super::check_validation(&counter)?;

    let (width, height) = (first.width, first.height);
    let differences = compare::delta_e_image(&first.display, &second.display);
    let coverage = &a.gbuffer.coverage;
    let summary = Summary::of(&differences, |i| coverage[i] > 0.0);
    let diff_path = diff_path(&args.out);
    output::write_png_image(&diff_path, &compare::heat_map(&differences, width, height))?;
    match format {
        OutputFormat::Exr => {
            // Data, not a picture: A's pixels then B's, in one image twice as wide.
            let (ra, rb) =
                (first.radiance.as_ref().expect("read for EXR"), second.radiance.as_ref().expect("read for EXR"));
            let rows = (0..height as usize).flat_map(|y| {
                let row = y * width as usize..(y + 1) * width as usize;
                ra[row.clone()].iter().chain(&rb[row]).copied()
            });
            let both: Vec<[f32; 4]> = rows.collect();
            output::write_exr(&args.out, 2 * width, height, &both, a.settings.lighting.background)?;
        }
        OutputFormat::Png => {
            let image =
                |r: &Rendered| image::RgbaImage::from_raw(width, height, r.display.clone()).expect("sizes match");
            output::write_png_image(
                &args.out,
                &compare::side_by_side(image(&first), &a_label, image(&second), &b_label),
            )?;
        }
    }
    // The statistics are the command's result, so they print even with --quiet.
    match summary {
        Some(s) => println!(
            "ΔE*ab (CIELAB, D65) of B against A over {} shaded pixels: mean {:.2}, median {:.2}, 95th percentile {:.2}, \
             max {:.2}; {:.1}% at or above {} (just noticeable)",
            s.pixels,
            s.mean,
            s.median,
            s.p95,
            s.max,
            100.0 * s.noticeable,
            compare::JUST_NOTICEABLE
        ),
        None => println!("ΔE*ab: the g-buffer has no shaded pixels to compare"),
    }
    if !args.quiet {
        eprintln!(
            "lookdev: wrote {} (A: {a_label}; B: {b_label}) and {} ({}x{}, {} spp each, {:.2} s on {device_name})",
            args.out.display(),
            diff_path.display(),
            width,
            height,
            a.settings.spp,
            (first.stats.wall + second.stats.wall).as_secs_f64()
        );
    }
    Ok(())
}

/// `<out>.diff.png` beside `--out`: `shots/ball.png` gives `shots/ball.diff.png`.
fn diff_path(out: &Path) -> PathBuf {
    let stem = out.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    out.with_file_name(format!("{stem}.diff.png"))
}
