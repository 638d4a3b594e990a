//! `lookdev bench`: relighting throughput on the built-in scene with the default look.
//!
//! One sample is one environment sample plus one BRDF sample, combined by MIS, for one pixel.
//! Throughput is reported over all pixels (as image renderers count) and over covered pixels
//! only (the pixels that actually shade; the background costs one lookup per pixel and pass).

use crate::render::scene::{GBufferSpec, Scene, SceneSpec};
use crate::render::{progressive, Renderer};
use crate::Result;
use clap::Args;

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Vulkan device to use: part of its name (lavapipe is "llvmpipe").
    #[arg(long, value_name = "NAME")]
    pub device: Option<String>,
    /// Samples per pixel for the wall-time figure.
    #[arg(long, default_value_t = 64)]
    pub spp: u32,
    /// Single-sample passes timed for the per-pass kernel time (the median is reported).
    #[arg(long, default_value_t = 8)]
    pub passes: u32,
    /// AOVs to accumulate beside the beauty, as `render --aov` takes them (e.g. light), to
    /// measure what they cost.
    #[arg(long = "aov", value_name = "NAME")]
    pub aovs: Vec<String>,
    /// The built-in scene's pedestal catches shadows (docs/formats.md#shadow-catchers), to
    /// measure what a shadow catcher costs.
    #[arg(long)]
    pub shadow_catcher: bool,
    /// Instead of throughput, the viewer's wait after an edit: time from a change of the light
    /// to a complete frame at the new state, by a first full pass and by the preview.
    #[arg(long)]
    pub interactive: bool,
    /// With --interactive: how many edits (turns of the light) are timed.
    #[arg(long, default_value_t = 12, value_name = "N")]
    pub edits: u32,
    /// Instead of throughput, each estimator's error against a high-spp reference, at equal
    /// samples and at equal time (relMSE, time, efficiency), on the built-in scene at 256² or
    /// on the g-buffer, look and environment given.
    #[arg(long)]
    pub convergence: bool,
    #[command(flatten)]
    pub convergence_args: super::bench_convergence::ConvergenceArgs,
    /// Instead of throughput, adaptive sampling (--noise-threshold) against uniform sampling:
    /// wall time, mean spp and relative MSE against a 2048-spp reference of another seed.
    #[arg(long)]
    pub adaptive: bool,
    /// With --interactive: instead, the time from an edit of one object's stack until that
    /// object is back at 16 spp (the rest keeping their samples), against a full restart's.
    #[arg(long, requires = "interactive")]
    pub local_edit: bool,
}

const SIZES: [(u32, u32); 2] = [(512, 512), (1920, 1080)];

/// The built-in scene at `width`×`height`, with the default look and environment, and with its
/// visibility or without: what every benchmark measures.
pub fn builtin_scene(width: u32, height: u32, visibility: bool) -> Result<Scene> {
    Scene::load(&SceneSpec {
        gbuffer: GBufferSpec {
            builtin_size: Some((width, height)),
            ignore_visibility: !visibility,
            ..GBufferSpec::default()
        },
        quiet: true,
        ..SceneSpec::default()
    })
}

/// The built-in scene's pedestal.
const PEDESTAL: u32 = 2;

/// Makes object `id` of `scene` catch shadows.
fn catch_shadows_on(scene: &mut Scene, id: u32) -> Result<()> {
    let stack = scene.look.objects.iter_mut().find(|o| o.id == Some(id));
    stack.ok_or_else(|| crate::Error::input(format!("the look has no stack for object {id}")))?.shadow_catcher = true;
    let covered = crate::render::scene::covered_object_ids(&scene.gbuffer);
    scene.stacks =
        crate::material::stack::PackedStacks::pack(&scene.look, covered, &scene.gbuffer, &scene.gbuffer_name)?;
    Ok(())
}

pub fn run(args: BenchArgs) -> Result<()> {
    if args.interactive {
        return super::bench_interactive::run(&args);
    }
    if args.convergence {
        return super::bench_convergence::run(&args);
    }
    if args.adaptive {
        return super::bench_adaptive::run(&args);
    }
    let ctx = super::context(args.device.clone())?;
    let counter = ctx.validation_counter();
    let info = ctx.info().clone();
    println!("device: {} (subgroup size {})", info.name, info.subgroup_size);
    println!(
        "scene: built-in shader ball, built-in default look, default environment ({})",
        crate::environment::builtin::DEFAULT
    );
    let aovs =
        crate::render::aov::Aov::parse_all(&args.aovs).map_err(|e| crate::Error::input(format!("--aov: {e}")))?;
    let accumulate = crate::render::aov::accumulate(&aovs);
    let beside: Vec<&str> = [(accumulate.lobes, "each lobe's share"), (accumulate.variance, "squared luminance")]
        .into_iter()
        .filter_map(|(on, what)| on.then_some(what))
        .collect();
    println!("accumulated beside the beauty: {}", if beside.is_empty() { "nothing".into() } else { beside.join(", ") });
    if args.shadow_catcher {
        println!("shadow catcher: the pedestal (object {PEDESTAL})");
    }
    println!(
        "{:>10} {:>10} {:>9} {:>16} {:>16} {:>14} {:>12}",
        "size", "visibility", "coverage", "Msamples/s", "Msamples/s", "kernel/1spp", "wall"
    );
    println!(
        "{:>10} {:>10} {:>9} {:>16} {:>16} {:>14} {:>12}",
        "",
        "",
        "",
        "(all pixels)",
        "(covered)",
        "(GPU, median)",
        format!("({} spp)", args.spp)
    );
    // Per size: covered samples per second over the wall time, and per kernel time at 1 spp,
    // with the scene's visibility and then without.
    let mut rates: Vec<(f64, Option<f64>)> = Vec::new();
    let mut without_visibility: Vec<(f64, Option<f64>)> = Vec::new();
    for ((width, height), visibility) in SIZES.into_iter().flat_map(|size| [(size, true), (size, false)]) {
        let mut scene = builtin_scene(width, height, visibility)?;
        if args.shadow_catcher {
            catch_shadows_on(&mut scene, PEDESTAL)?;
        }
        let gbuffer = &scene.gbuffer;
        let coverage = gbuffer.coverage.iter().filter(|&&a| a > 0.0).count() as f64 / gbuffer.pixel_count() as f64;
        let mut renderer = Renderer::new(&ctx, gbuffer, &scene.environment)?;
        renderer.set_accumulate(accumulate)?;
        renderer.set_stacks(&scene.stacks)?;
        renderer.set_lighting(scene.settings.lighting);

        // Warm-up, then single-sample passes for the kernel time.
        renderer.render_samples(1)?;
        let mut kernel: Vec<f64> = Vec::new();
        for _ in 0..args.passes {
            if let Some(t) = renderer.render_samples(1)? {
                kernel.push(t);
            }
        }
        kernel.sort_by(f64::total_cmp);
        let median = kernel.get(kernel.len() / 2).copied();
        let kernel_ms = median.map(|t| format!("{:.2} ms", t * 1e3)).unwrap_or("n/a".into());

        // Wall time to the target from a fresh accumulation, as `lookdev render` does it.
        renderer.restart();
        let stats = progressive::accumulate(&mut renderer, args.spp, |_| {})?;
        let samples = gbuffer.pixel_count() as f64 * args.spp as f64;
        let wall = stats.wall.as_secs_f64();
        println!(
            "{:>10} {:>10} {:>8.1}% {:>16.2} {:>16.2} {:>14} {:>10.3} s",
            format!("{width}x{height}"),
            if visibility { "on" } else { "off" },
            coverage * 100.0,
            samples / wall / 1e6,
            samples * coverage / wall / 1e6,
            kernel_ms,
            wall
        );
        let covered = gbuffer.pixel_count() as f64 * coverage;
        let rate = (samples * coverage / wall, median.map(|t| covered / t));
        if visibility {
            rates.push(rate);
        } else {
            without_visibility.push(rate);
        }
    }
    for (((width, height), (wall, kernel)), (wall_off, kernel_off)) in SIZES.iter().zip(&rates).zip(&without_visibility)
    {
        let kernel = match (kernel, kernel_off) {
            (Some(a), Some(b)) => format!(", {:.0}% by kernel time", 100.0 * a / b),
            _ => String::new(),
        };
        println!(
            "covered rate with visibility at {width}x{height}: {:.0}% of without by wall time{kernel}",
            100.0 * wall / wall_off
        );
    }
    // What a sampler that skipped blocked directions could save (docs/decisions.md).
    let scene = builtin_scene(SIZES[0].0, SIZES[0].1, true)?;
    let tables = crate::environment::Distribution::for_device(&scene.environment, info.max_image_dimension_2d);
    let turn = glam::Quat::from_rotation_y(scene.settings.lighting.rotation_degrees.to_radians());
    if let Some(share) = crate::visibility::blocked_share(&scene.gbuffer, |u| turn * tables.sample(u).0, 8) {
        println!(
            "environment samples the visibility blocks at {}x{}: {:.1}% of those above the horizon",
            SIZES[0].0,
            SIZES[0].1,
            100.0 * share
        );
    }
    // How far partly covered frames fall behind: the covered rate of the last size against
    // the first's, by wall time (batches as `render` makes them) and by kernel time at 1 spp.
    if let [(first_wall, first_kernel), .., (last_wall, last_kernel)] = rates[..] {
        let (w, h) = SIZES[SIZES.len() - 1];
        let (w0, h0) = SIZES[0];
        let kernel = match (first_kernel, last_kernel) {
            (Some(a), Some(b)) => format!(", {:.0}% by kernel time", 100.0 * b / a),
            _ => String::new(),
        };
        println!("covered rate at {w}x{h}: {:.0}% of {w0}x{h0}'s by wall time{kernel}", 100.0 * last_wall / first_wall);
    }
    drop(ctx);
    super::check_validation(&counter)
}
