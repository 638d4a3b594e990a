//! `lookdev bench --adaptive`: adaptive sampling (`--noise-threshold`) against uniform
//! sampling. Each is timed as `lookdev render` runs it, and its relative MSE measured against a
//! 2048-spp reference of another seed: mean over fully covered pixels and rgb of
//! (x − r)² / (r² + 0.01). For each threshold it prints the time uniform sampling takes to the
//! same error, interpolated log-log between the uniform rows.

use super::bench::BenchArgs;
use crate::render::progressive;
use crate::render::renderer::NoiseThreshold;
use crate::render::scene::Scene;
use crate::render::Renderer;
use crate::Result;

const REFERENCE_SPP: u32 = 2048;
const UNIFORM_SPP: [u32; 8] = [8, 16, 32, 64, 128, 256, 512, 1024];
const THRESHOLDS: [f32; 4] = [0.1, 0.05, 0.03, 0.02];
/// The most samples an adaptive render takes, and the least.
const MAX_SPP: u32 = 2048;
const MIN_SPP: u32 = 16;

/// One render: its wall time, mean samples per covered pixel and relative MSE.
struct Row {
    seconds: f64,
    spp: f64,
    error: f64,
}

pub fn run(args: &BenchArgs) -> Result<()> {
    let ctx = super::context(args.device.clone())?;
    let counter = ctx.validation_counter();
    let scene = Scene::load(&args.convergence_args.scene_spec()?)?;
    scene.check_device(ctx.info())?;
    let gbuffer = &scene.gbuffer;
    println!("device: {}", ctx.info().name);
    println!("scene: {} ({}x{})", scene.gbuffer_name.display(), gbuffer.width, gbuffer.height);
    let mut renderer = Renderer::with_model(&ctx, gbuffer, &scene.environment, &scene.settings.model)?;
    renderer.set_stacks(&scene.stacks)?;
    renderer.set_lighting(scene.settings.lighting);
    let mut render = |seed: u32, spp: u32, noise: Option<NoiseThreshold>| -> Result<(Vec<[f32; 4]>, Row)> {
        renderer.set_seed(seed);
        renderer.set_noise_threshold(noise)?;
        renderer.restart();
        let stats = progressive::accumulate(&mut renderer, spp, |_| {})?;
        let row = Row { seconds: stats.wall.as_secs_f64(), spp: stats.mean_spp.unwrap_or(spp as f64), error: 0.0 };
        Ok((renderer.read_radiance()?, row))
    };
    render(0, 1, None)?; // warm-up: pipelines and caches
    let (reference, row) = render(1, REFERENCE_SPP, None)?;
    println!("reference: {REFERENCE_SPP} spp, seed 1, {:.1} s", row.seconds);
    let full: Vec<bool> = gbuffer.coverage.iter().map(|&a| a == 1.0).collect();
    let rel_mse = |image: &[[f32; 4]]| super::bench_convergence::relative_mse(image, &reference, &gbuffer.coverage);
    // The bias, with noise: the image's sum over fully covered pixels and rgb against the
    // reference's, less 1.
    let sum = |image: &[[f32; 4]]| -> f64 {
        image.iter().zip(&full).filter(|(_, &f)| f).map(|(p, _)| p[..3].iter().map(|&c| c as f64).sum::<f64>()).sum()
    };
    let reference_sum = sum(&reference);
    let offset = |image: &[[f32; 4]]| format!("{:+.2}%", 100.0 * (sum(image) / reference_sum - 1.0));
    println!(
        "{:<10} {:>9} {:>10} {:>10} {:>11} {:>22}",
        "sampling", "threshold", "mean spp", "wall", "relMSE (mean vs ref)", "uniform to same relMSE"
    );
    let mut uniform = Vec::new();
    for spp in UNIFORM_SPP {
        let (image, mut row) = render(0, spp, None)?;
        row.error = rel_mse(&image);
        println!(
            "{:<10} {:>9} {:>10.1} {:>8.3} s {:>11.3e} ({})",
            "uniform",
            "-",
            row.spp,
            row.seconds,
            row.error,
            offset(&image)
        );
        uniform.push(row);
    }
    for threshold in THRESHOLDS {
        let noise = NoiseThreshold::new(threshold, MIN_SPP)?;
        let (image, mut row) = render(0, MAX_SPP, Some(noise))?;
        row.error = rel_mse(&image);
        let same = match (uniform_to(&uniform, row.error, |r| r.seconds), uniform_to(&uniform, row.error, |r| r.spp)) {
            (Some(t), Some(spp)) => format!("{t:.3} s ({:.2}x), {spp:.1} spp ({:.2}x)", t / row.seconds, spp / row.spp),
            _ => "out of range".into(),
        };
        println!(
            "{:<10} {:>9} {:>10.1} {:>8.3} s {:>11.3e} ({}) {}",
            "adaptive",
            threshold,
            row.spp,
            row.seconds,
            row.error,
            offset(&image),
            same
        );
    }
    drop(renderer);
    drop(ctx);
    super::check_validation(&counter)
}

/// The uniform renders' `value` (time or spp) at `error`, interpolated log-log between the two
/// rows around it.
fn uniform_to(rows: &[Row], error: f64, value: impl Fn(&Row) -> f64) -> Option<f64> {
    rows.windows(2).find_map(|pair| {
        let (a, b) = (&pair[0], &pair[1]);
        if !(b.error <= error && error <= a.error) || a.error == b.error {
            return None;
        }
        let t = (error.ln() - a.error.ln()) / (b.error.ln() - a.error.ln());
        Some((value(a).ln() + t * (value(b).ln() - value(a).ln())).exp())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_time_is_interpolated_log_log() {
        let rows = [Row { seconds: 1.0, spp: 8.0, error: 1e-2 }, Row { seconds: 4.0, spp: 32.0, error: 1e-4 }];
        assert!((uniform_to(&rows, 1e-3, |r| r.seconds).unwrap() - 2.0).abs() < 1e-9);
        assert!((uniform_to(&rows, 1e-3, |r| r.spp).unwrap() - 16.0).abs() < 1e-9);
        assert_eq!(uniform_to(&rows, 1e-5, |r| r.seconds), None);
    }
}
