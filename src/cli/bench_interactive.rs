//! `lookdev bench --interactive`: how long the viewer's image lags an edit. Each edit turns the
//! light (which changes every pixel), and the time is taken from the change to a complete frame
//! at the new state: by a first full-resolution pass, as the viewer showed it before it had a
//! preview (a lower bound: it swept the pass in bands, a frame each), and by the preview, one
//! sample per block. See
//! docs/commands.md#lookdev-bench---device-name---spp-n---passes-n---aov-name---interactive---edits-n.

use super::bench::BenchArgs;
use crate::render::{Lighting, Renderer};
use crate::Result;
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
        let scene = super::bench::builtin_scene(width, height)?;
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
