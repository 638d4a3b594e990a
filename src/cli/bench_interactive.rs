//! `lookdev bench --interactive`: how long the viewer's image lags an edit. Each edit turns the
//! light (which changes every pixel), and the time is taken from the change to a complete frame
//! at the new state: by a first full-resolution pass, as the viewer showed it before it had a
//! preview (a lower bound: it swept the pass in bands, a frame each), and by the preview, one
//! sample per block. See
//! docs/commands.md#lookdev-bench---device-name---spp-n---passes-n---aov-name---interactive---edits-n.
//!
//! With `--local-edit`, it measures edit-local re-convergence instead: the time from an edit of
//! one object's stack until that object is back at the sample count it had, against the time a
//! full restart takes to reach that count.

use super::bench::BenchArgs;
use crate::gbuffer::{BALL_ID, PEDESTAL_ID};
use crate::material::stack::PackedStacks;
use crate::material::{Param, Value};
use crate::render::{progressive, Lighting, Renderer};
use crate::Result;
use std::path::Path;
use std::time::{Duration, Instant};

const SIZES: [(u32, u32); 2] = [(1024, 1024), (1920, 1080)];
/// The preview blocks the viewer chooses between.
const BLOCKS: [u32; 3] = [2, 4, 8];
/// Degrees the light turns per edit: enough that no pixel keeps its value.
const TURN: f32 = 37.0;

pub fn run(args: &BenchArgs) -> Result<()> {
    if args.edits == 0 {
        return Err(crate::Error::input("--edits 0: at least one edit is timed"));
    }
    if args.local_edit {
        return run_local_edit(args);
    }
    let ctx = super::context(args.device.clone())?;
    let counter = ctx.validation_counter();
    println!("device: {}", ctx.info().name);
    println!("scene: built-in shader ball, built-in default look, embedded studio environment");
    println!(
        "time from an edit (a turn of the light) to a complete frame at the new state, over {} edits:",
        args.edits
    );
    println!("{:>10}  {:<34} {:>12} {:>12}", "size", "complete frame by", "median", "95th pct");
    for (width, height) in SIZES {
        let scene = super::bench::builtin_scene(width, height, true)?;
        let mut renderer = Renderer::new(&ctx, &scene.gbuffer, &scene.environment)?;
        renderer.set_stacks(&scene.stacks)?;
        let (exposure, tonemap) = (scene.settings.exposure, scene.settings.tonemap);
        let mut lighting = scene.settings.lighting;
        // Warm-up: pipelines and caches.
        renderer.render_samples(1)?;
        let mut edit = |renderer: &mut Renderer| {
            lighting = Lighting { rotation_degrees: lighting.rotation_degrees + TURN, ..lighting };
            renderer.set_lighting(lighting);
            Instant::now()
        };
        let full_pass = |renderer: &mut Renderer| -> Result<()> {
            renderer.render_rows(0, height, 1)?;
            renderer.finalize_rows(0, height, exposure, tonemap)
        };
        let mut rows: Vec<(String, Vec<Duration>)> = Vec::new();
        let mut old = Vec::new();
        for _ in 0..args.edits {
            let start = edit(&mut renderer);
            full_pass(&mut renderer)?;
            old.push(start.elapsed());
        }
        rows.push(("first full pass (without preview)".into(), old));
        for block in BLOCKS {
            let (mut preview, mut then_full) = (Vec::new(), Vec::new());
            for _ in 0..args.edits {
                let start = edit(&mut renderer);
                renderer.render_preview(block)?;
                renderer.finalize_rows(0, height, exposure, tonemap)?;
                preview.push(start.elapsed());
                full_pass(&mut renderer)?;
                then_full.push(start.elapsed());
            }
            rows.push((format!("preview, {block}x{block} blocks"), preview));
            rows.push(("  then the first full pass".into(), then_full));
        }
        for (what, mut times) in rows {
            let (median, p95) = percentiles(&mut times);
            println!("{:>10}  {what:<34} {:>9.1} ms {:>9.1} ms", format!("{width}x{height}"), median, p95);
        }
    }
    drop(ctx);
    super::check_validation(&counter)
}

/// The image size and sample count of `--local-edit`.
const LOCAL_SIZE: (u32, u32) = (1024, 1024);
const LOCAL_SPP: u32 = 16;

/// `--local-edit`: for the ball, the ball's striped layer and the pedestal, over `--edits` edits
/// of that layer's roughness, the time from the edit (resolve included) until the object is back at
/// [`LOCAL_SPP`] while the rest keep theirs, against the time from the same edit restarting
/// every pixel to the whole image at [`LOCAL_SPP`]: each as `lookdev render` accumulates.
fn run_local_edit(args: &BenchArgs) -> Result<()> {
    let ctx = super::context(args.device.clone())?;
    let counter = ctx.validation_counter();
    let (width, height) = LOCAL_SIZE;
    let scene = super::bench::builtin_scene(width, height, true)?;
    println!("device: {}", ctx.info().name);
    println!("scene: built-in shader ball {width}x{height}, built-in default look, default environment");
    println!("time from an edit of one object's stack until it is back at {LOCAL_SPP} spp, over {} edits:", args.edits);
    println!(
        "{:>10} {:>10}  {:>22}  {:>22}  {:>7}",
        "object", "pixels", "local: median / 95th", "full: median / 95th", "ratio"
    );
    let mut renderer = Renderer::new(&ctx, &scene.gbuffer, &scene.environment)?;
    renderer.set_lighting(scene.settings.lighting);
    renderer.set_seed(scene.settings.seed);
    renderer.set_stacks(&scene.stacks)?;
    progressive::accumulate(&mut renderer, 1, |_| {})?; // warm-up: pipelines and caches
    let objects = crate::render::scene::covered_object_ids(&scene.gbuffer);
    // The object and the layer of its stack whose roughness is edited: the ball's bottom layer,
    // the gold under the ball's stripes mask, the pedestal's bottom layer.
    for (name, id, layer) in [("ball", BALL_ID, 0), ("stripes", BALL_ID, 1), ("pedestal", PEDESTAL_ID, 0)] {
        // Two looks that differ in this layer's roughness, edited in turn.
        let mut looks = [scene.look.clone(), scene.look.clone()];
        for (look, roughness) in looks.iter_mut().zip([0.2, 0.7]) {
            let stack = look
                .objects
                .iter_mut()
                .find(|o| o.id == Some(id))
                .ok_or_else(|| crate::Error::input(format!("the default look has no stack for the {name}")))?;
            let edited = stack
                .layers
                .get_mut(layer)
                .ok_or_else(|| crate::Error::input(format!("the default look's {name} has no layer {layer}")))?;
            edited.params.set(Param::Roughness, Value::Scalar(roughness)).map_err(crate::Error::input)?;
        }
        let packed: Vec<PackedStacks> = looks
            .iter()
            .map(|look| PackedStacks::pack(look, objects.iter().copied(), &scene.gbuffer, Path::new("built-in")))
            .collect::<Result<_>>()?;
        renderer.set_stacks(&packed[0])?;
        progressive::accumulate(&mut renderer, LOCAL_SPP, |_| {})?;
        let (mut local, mut full, mut pixels) = (Vec::new(), Vec::new(), 0);
        for edit in 0..args.edits as usize {
            let stacks = &packed[(edit + 1) % 2];
            let start = Instant::now();
            pixels = renderer
                .set_stacks_local(stacks)?
                .ok_or_else(|| crate::Error::gpu("the edit changed the scene's lobes: everything restarted"))?;
            progressive::accumulate(&mut renderer, LOCAL_SPP, |_| {})?;
            local.push(start.elapsed());
            if renderer.restarted_region().is_some() {
                return Err(crate::Error::gpu("the restarted pixels did not catch up"));
            }
        }
        for edit in 0..args.edits as usize {
            let start = Instant::now();
            renderer.set_stacks(&packed[edit % 2])?;
            progressive::accumulate(&mut renderer, LOCAL_SPP, |_| {})?;
            full.push(start.elapsed());
        }
        let (local_median, local_p95) = percentiles(&mut local);
        let (full_median, full_p95) = percentiles(&mut full);
        println!(
            "{name:>10} {pixels:>10}  {:>22}  {:>22}  {:>6.3}",
            format!("{local_median:.1} / {local_p95:.1} ms"),
            format!("{full_median:.1} / {full_p95:.1} ms"),
            local_median / full_median
        );
    }
    drop(renderer);
    drop(ctx);
    super::check_validation(&counter)
}

/// The median and 95th percentile, in milliseconds.
fn percentiles(times: &mut [Duration]) -> (f64, f64) {
    times.sort();
    let at = |q: f64| times[((times.len() - 1) as f64 * q).round() as usize].as_secs_f64() * 1e3;
    (at(0.5), at(0.95))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_pick_the_nearest_rank() {
        let mut times: Vec<Duration> = (1..=20).rev().map(Duration::from_millis).collect();
        assert_eq!(percentiles(&mut times), (11.0, 19.0));
        assert_eq!(percentiles(&mut [Duration::from_millis(7)]), (7.0, 7.0));
    }
}
