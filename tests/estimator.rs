//! The estimators of `--sampling` (docs/shading.md#sampling): each one's environment sampling
//! against its own pdf on the GPU (chi-square), each one's mean against the plain estimator's
//! on real HDRIs (unbiased), with visibility and without, and the command-line switch and
//! `bench --convergence`.

mod common;

use common::cli::{assert_bad_input, assert_success, lookdev};
use common::probes::environment_samples;
use common::random::Random;
use common::scenes::{one_material, orthographic_sphere, renderer};
use common::stats::chi_square;
use glam::{Vec2, Vec3};
use lookdev::environment::{sampling, Builtin, Distribution, Environment, GpuEnvironment};
use lookdev::gpu::Context;
use lookdev::material::Params;
use lookdev::render::renderer::Accumulate;
use lookdev::render::sampling::Sampling;
use lookdev::render::{progressive, Lighting};

/// sample_probe.comp's environment routine.
const ENVIRONMENT: u32 = 4;

/// Environment samples drawn on the GPU from `distribution`: (direction, pdf the sampler
/// reports, or −1 where the pdf looked up from the direction disagrees).
fn gpu_environment_samples(
    ctx: &Context,
    env: &Environment,
    distribution: &Distribution,
    count: usize,
) -> Vec<(Vec3, f32)> {
    let mut rng = Random::new(7);
    let u: Vec<Vec2> = (0..count).map(|_| Vec2::new(rng.uniform(), rng.uniform())).collect();
    let gpu_env = GpuEnvironment::upload(ctx, env, distribution).unwrap();
    environment_samples(ctx, &gpu_env, ENVIRONMENT, 0, 0.0, &u)
}

/// The compensated tables sample what they say, cell by cell (grouped into 16 × 8 blocks of
/// cells for the chi-square test), never a cell they give pdf 0, and report the pdf the Rust
/// reference looks up; on real HDRIs and on a map with a sun.
#[test]
fn compensated_environment_sampling_matches_its_pdf() {
    let ctx = common::gpu::context();
    let sun = {
        let (w, h) = (300u32, 150u32);
        let texels = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let sky = if y < h / 2 { 0.3 + (h / 2 - y) as f32 / h as f32 } else { 0.05 };
                if (x as i32 - 90).abs() < 3 && (y as i32 - 30).abs() < 3 {
                    [4000.0; 3]
                } else {
                    [sky, sky, 1.3 * sky]
                }
            })
            .collect();
        Environment::new(w, h, texels, "sun and sky")
    };
    let envs = [Builtin::find("studio").unwrap().load(), Builtin::find("sunrise").unwrap().load(), sun];
    let count = 400_000;
    for env in &envs {
        let d = Distribution::compensated_with_max_cells(env, 4096);
        let plain = Distribution::build(env);
        assert_ne!(d.cell_pdf, plain.cell_pdf, "{}: compensation changed nothing", env.source);
        assert!(d.cell_pdf.contains(&0.0), "{}: nothing was left to the BRDF sample", env.source);
        let samples = gpu_environment_samples(&ctx, env, &d, count);
        let (cols, rows) = (d.columns, d.rows);
        let (bx, by) = (cols.div_ceil(16), rows.div_ceil(8));
        let nx = cols.div_ceil(bx) as usize;
        let mut expected = vec![0.0; nx * rows.div_ceil(by) as usize];
        for r in 0..rows {
            for c in 0..cols {
                let p = d.cell_pdf[(r * cols + c) as usize] as f64 * d.cell_solid_angle(r, c);
                expected[(r / by) as usize * nx + (c / bx) as usize] += p * count as f64;
            }
        }
        let mut observed = vec![0.0; expected.len()];
        let (mut mismatched, mut in_zero_cells) = (0, 0);
        for (dir, pdf) in &samples {
            let uv = sampling::direction_to_uv(*dir);
            let t = sampling::texel_of(d.width, d.height, uv);
            observed[(t.y / d.block_y / by) as usize * nx + (t.x / d.block_x / bx) as usize] += 1.0;
            let reference = d.pdf(uv);
            in_zero_cells += (reference == 0.0) as usize;
            mismatched += (*pdf < 0.0 || (pdf - reference).abs() > 1e-3 * reference) as usize;
        }
        // Only where the direction's round trip crosses a cell boundary, a sliver of each cell.
        assert!(mismatched * 1000 < count, "{}: {mismatched} samples' pdf disagrees with the reference", env.source);
        assert!(in_zero_cells * 1000 < count, "{}: {in_zero_cells} samples in cells of pdf 0", env.source);
        let result = chi_square(&observed, &expected).unwrap_or_else(|e| panic!("{}: {e}", env.source));
        assert!(result.p_value > 1e-3, "{}: {result:?}", env.source);
    }
    common::gpu::finish(ctx);
}

/// Every estimator's image has the plain one's mean, within the noise its variance AOV
/// reports: over the whole sphere and pixel by pixel, on real HDRIs with a rough dielectric
/// and a glossy metal.
#[test]
fn every_estimator_is_unbiased() {
    every_estimator_is_unbiased_with(orthographic_sphere(32));
}

/// With visibility, blocked directions carry no light in every strategy of every estimator
/// alike: here a wall of cells (every direction with x + z/2 > 0.2, an occluder to one side of
/// the sphere, the same for each pixel) that the environment's rotation turns against.
#[test]
fn every_estimator_is_unbiased_with_visibility() {
    let mut gbuffer = orthographic_sphere(32);
    let grid = lookdev::visibility::Grid::new(16).unwrap();
    let mut words = vec![0u32; grid.words()];
    for cell in 0..grid.cells() {
        let d = grid.centre(cell);
        if d.x + 0.5 * d.z <= 0.2 {
            words[cell / 32] |= 1 << (cell % 32);
        }
    }
    let words = words.repeat(gbuffer.pixel_count());
    gbuffer.visibility = Some(lookdev::visibility::Visibility { grid, words });
    every_estimator_is_unbiased_with(gbuffer);
}

fn every_estimator_is_unbiased_with(gbuffer: lookdev::gbuffer::GBuffer) {
    let ctx = common::gpu::context();
    let covered: Vec<usize> = (0..gbuffer.coverage.len()).filter(|&i| gbuffer.coverage[i] == 1.0).collect();
    let n = covered.len() as f64;
    let materials = [
        Params { base_color: [0.7, 0.5, 0.3], roughness: 0.7, ..Params::default() },
        Params { base_color: [0.9, 0.8, 0.6], metallic: 1.0, roughness: 0.25, ..Params::default() },
    ];
    for name in ["interior", "sunrise"] {
        let env = Builtin::find(name).unwrap().load();
        for params in &materials {
            let lighting = Lighting { rotation_degrees: 40.0, intensity: 1.0, background: false };
            let mut r = renderer(&ctx, &gbuffer, &env, &one_material(*params), lighting);
            r.set_accumulate(Accumulate { variance: true, ..Accumulate::default() }).unwrap();
            let mut images = Vec::new();
            for sampling in Sampling::ALL {
                r.set_sampling(sampling, &env).unwrap();
                r.set_seed(11);
                progressive::accumulate(&mut r, 512, |_| {}).unwrap();
                let radiance = r.read_radiance().unwrap();
                let variance = r.read_variance(&gbuffer.coverage).unwrap();
                let luminance: Vec<f64> = covered
                    .iter()
                    .map(|&i| lookdev::shading::common::luminance(Vec3::from_slice(&radiance[i][..3])) as f64)
                    .collect();
                let variance: Vec<f64> = covered.iter().map(|&i| variance[i] as f64).collect();
                images.push((sampling, luminance, variance));
            }
            let (_, plain, plain_variance) = &images[0];
            for (sampling, image, variance) in &images[1..] {
                let what = format!("{name}, {params:?}, {sampling} against plain");
                let difference = image.iter().zip(plain).map(|(a, b)| a - b).sum::<f64>() / n;
                let sigma = (variance.iter().chain(plain_variance).sum::<f64>()).sqrt() / n;
                assert!(difference.abs() < 5.0 * sigma, "{what}: means differ by {difference:e}, σ = {sigma:e}");
                // The squared differences in units of their variance average about 1 (less:
                // the variance AOV treats stratified samples as independent); a bias confined to
                // part of the sphere would raise it.
                let z2 = image
                    .iter()
                    .zip(plain)
                    .zip(variance.iter().zip(plain_variance))
                    .map(|((a, b), (va, vb))| (a - b) * (a - b) / (va + vb).max(1e-12))
                    .sum::<f64>()
                    / n;
                assert!(z2 < 1.5, "{what}: mean squared z-score {z2}");
            }
        }
    }
    common::gpu::finish(ctx);
}

#[test]
fn the_sampling_flag_chooses_the_estimator_and_refuses_unknown_names() {
    let dir = tempfile::tempdir().unwrap();
    let mut images = Vec::new();
    for sampling in Sampling::ALL.map(Sampling::name) {
        let out = dir.path().join(format!("{sampling}.exr"));
        let out_text = out.to_str().unwrap();
        let args = ["render", "--size", "24", "24", "--spp", "2", "--sampling", sampling, "--out", out_text, "-q"];
        assert_success(&lookdev(&args));
        images.push(std::fs::read(&out).unwrap());
    }
    for (i, a) in images.iter().enumerate() {
        for b in &images[i + 1..] {
            assert_ne!(a, b, "--sampling made no difference");
        }
    }
    let out = dir.path().join("x.png");
    let output = lookdev(&["render", "--size", "8", "8", "--sampling", "best", "--out", out.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(2), "{}", common::cli::stderr(&output));
    let text = common::cli::stderr(&output);
    assert!(text.contains("--sampling") && text.contains("'best'") && text.contains("plain, compensated"), "{text}");
}

#[test]
fn bench_convergence_measures_every_estimator_against_a_reference() {
    let args = ["bench", "--convergence", "--size", "24", "24", "--reference-spp", "16", "--convergence-spp", "1,4"];
    let output = lookdev(&args);
    assert_success(&output);
    let text = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(text.contains("reference: 16 spp"), "{text}");
    for sampling in Sampling::ALL {
        for spp in [1, 4] {
            let row: Vec<&str> = text
                .lines()
                .map(|l| l.split_whitespace().collect::<Vec<_>>())
                .find(|w| w.len() == 7 && w[0] == sampling.name() && w[1] == spp.to_string())
                .unwrap_or_else(|| panic!("no row for {sampling} at {spp} spp: {text}"));
            let error: f64 = row[2].parse().unwrap();
            assert!(error.is_finite() && error > 0.0, "{text}");
        }
    }
    let bad = lookdev(&["bench", "--convergence", "--reference-spp", "8", "--convergence-spp", "4,16"]);
    assert_bad_input(&bad, &["--reference-spp 8", "16"]);
}
