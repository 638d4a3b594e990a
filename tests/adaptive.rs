//! Adaptive sampling (`--noise-threshold`, `Renderer::set_noise_threshold`): each pixel stops
//! once its estimated relative error is below the threshold, tested at fixed sample counts, so
//! a flat region stops at the minimum while a noisy one goes on; where each stops, and so the
//! image, does not depend on how the passes are split; each pixel holds exactly what a uniform
//! render at its own count holds; and at the same mean sample count its error is lower than
//! uniform sampling's.

mod common;

use common::cli::{assert_bad_input, assert_success, exr_bits, lookdev, stderr};
use common::scenes::{look, renderer};
use lookdev::environment::Environment;
use lookdev::gbuffer::GBuffer;
use lookdev::gpu::Context;
use lookdev::render::progressive;
use lookdev::render::renderer::NoiseThreshold;
use lookdev::render::{Lighting, Renderer};

const SIZE: u32 = 64;
const BALL: u32 = 1;

/// A rough metal ball, noisy under the studio environment, on a black emissive pedestal whose
/// estimate is its emission and hardly anything else.
const LOOK: &str = r#"
[[object]]
[[object.layer]]
[object.layer.set]
base_color = [0.0, 0.0, 0.0]
specular = 0.0
emission = [2.0, 1.0, 0.5]

[[object]]
id = 1
[[object.layer]]
[object.layer.set]
base_color = [0.9, 0.6, 0.3]
metallic = 1.0
roughness = 0.35
"#;

fn scene(ctx: &Context, seed: u32) -> (GBuffer, Renderer) {
    // Without its visibility: the shadows under the ball, mostly blocked with a rare bright
    // direction, are what an early stop misjudges, and are left to their own test.
    let gbuffer = GBuffer::shaderball_with(SIZE, SIZE, false);
    let mut r = renderer(ctx, &gbuffer, &Environment::studio(), &look(LOOK), Lighting::default());
    r.set_seed(seed);
    (gbuffer, r)
}

fn bits(values: &[[f32; 4]]) -> Vec<u32> {
    values.iter().flatten().map(|v| v.to_bits()).collect()
}

/// The relative MSE of `image` against `reference` over fully covered pixels and rgb.
fn rel_mse(gbuffer: &GBuffer, image: &[[f32; 4]], reference: &[[f32; 4]]) -> f64 {
    let (mut total, mut n) = (0.0, 0);
    for p in (0..image.len()).filter(|&p| gbuffer.coverage[p] == 1.0) {
        for c in 0..3 {
            let (x, r) = (image[p][c] as f64, reference[p][c] as f64);
            total += (x - r) * (x - r) / (r * r + 1e-2);
            n += 1;
        }
    }
    total / n as f64
}

#[test]
fn a_flat_region_stops_at_the_minimum_and_a_noisy_one_goes_on() {
    let ctx = common::gpu::context();
    let (gbuffer, mut r) = scene(&ctx, 0);
    r.set_noise_threshold(Some(NoiseThreshold { threshold: 0.02, min_samples: 16 })).unwrap();
    assert_eq!(r.active_pixels(), Some(r.covered_pixels() as u64), "every pixel is active before a pass");
    let stats = progressive::accumulate(&mut r, 256, |_| {}).unwrap();
    let counts = r.read_sample_counts().unwrap();
    let covered = |p: &usize| gbuffer.coverage[*p] > 0.0;
    let pedestal: Vec<u32> =
        (0..counts.len()).filter(covered).filter(|&p| gbuffer.object_id[p] != BALL).map(|p| counts[p]).collect();
    let ball: Vec<u32> =
        (0..counts.len()).filter(covered).filter(|&p| gbuffer.object_id[p] == BALL).map(|p| counts[p]).collect();
    assert!(!pedestal.is_empty() && !ball.is_empty());
    assert!(pedestal.iter().all(|&n| n == 16), "the flat pedestal stops at 16: {:?}", pedestal.iter().max());
    let ball_mean = ball.iter().sum::<u32>() as f64 / ball.len() as f64;
    assert!(ball_mean > 32.0, "the noisy ball goes on: {ball_mean} spp on average");
    assert!(ball.iter().all(|&n| n >= 16 && n.is_power_of_two()), "stops only at the tests");
    assert!(ball.iter().any(|&n| n < 256) || r.active_pixels().unwrap() > 0);
    // The render ends when every pixel has stopped, or at the most samples.
    assert!(r.active_pixels() == Some(0) || r.samples() == 256);
    let mean = stats.mean_spp.unwrap();
    let expected = counts.iter().map(|&n| n as f64).sum::<f64>() / r.covered_pixels() as f64;
    assert!((mean - expected).abs() < 1e-9, "{mean} vs {expected}");
    common::gpu::finish(ctx);
}

#[test]
fn a_black_region_stops_at_the_minimum() {
    let ctx = common::gpu::context();
    let (_, mut r) = scene(&ctx, 0);
    // No light and no emission: every estimate is 0.
    r.set_stacks(
        &lookdev::material::stack::PackedStacks::pack(
            &look("[[object]]\n[[object.layer]]\n[object.layer.set]\nbase_color = [0.5, 0.5, 0.5]\n"),
            lookdev::render::scene::covered_object_ids(&GBuffer::shaderball(SIZE, SIZE)),
            &GBuffer::shaderball(SIZE, SIZE),
            std::path::Path::new("test g-buffer"),
        )
        .unwrap(),
    )
    .unwrap();
    r.set_lighting(Lighting { intensity: 0.0, ..Lighting::default() });
    r.set_noise_threshold(Some(NoiseThreshold { threshold: 0.01, min_samples: 8 })).unwrap();
    progressive::accumulate(&mut r, 64, |_| {}).unwrap();
    assert_eq!(r.active_pixels(), Some(0));
    assert!(r.samples() < 64, "stopped early: no pass after every pixel had stopped");
    assert!(r.read_sample_counts().unwrap().iter().all(|&n| n == 0 || n == 8));
    common::gpu::finish(ctx);
}

/// The same seed gives the same bits under any split into passes and bands, and each pixel
/// holds what a uniform render at its own count holds.
#[test]
fn the_stops_do_not_depend_on_the_split_and_each_pixel_is_a_uniform_render_at_its_count() {
    let ctx = common::gpu::context();
    let noise = Some(NoiseThreshold { threshold: 0.03, min_samples: 8 });
    let max = 40;
    let (gbuffer, mut batched) = scene(&ctx, 7);
    batched.set_noise_threshold(noise).unwrap();
    progressive::accumulate(&mut batched, max, |_| {}).unwrap();
    let expected = bits(&batched.read_radiance().unwrap());
    let counts = batched.read_sample_counts().unwrap();

    let (_, mut single) = scene(&ctx, 7);
    single.set_noise_threshold(noise).unwrap();
    for _ in 0..max {
        single.render_samples(1).unwrap();
    }
    assert_eq!(bits(&single.read_radiance().unwrap()), expected, "one sample a pass");
    assert_eq!(single.read_sample_counts().unwrap(), counts);

    let (_, mut banded) = scene(&ctx, 7);
    banded.set_noise_threshold(noise).unwrap();
    for (band, count) in [(13, 3), (29, 7), (7, 30)] {
        let mut first = 0;
        while first < SIZE {
            let n = count.min(max - banded.row_samples(first));
            banded.render_rows(first, band, n).unwrap();
            first += band;
        }
    }
    assert_eq!(banded.samples(), max);
    assert_eq!(bits(&banded.read_radiance().unwrap()), expected, "bands");

    let distinct: std::collections::BTreeSet<u32> = counts.iter().copied().filter(|&n| n > 0).collect();
    assert!(distinct.len() > 1, "some pixels stop early and some go on: {distinct:?}");
    let radiance = batched.read_radiance().unwrap();
    for &n in &distinct {
        let (_, mut uniform) = scene(&ctx, 7);
        uniform.render_samples(n).unwrap();
        let reference = uniform.read_radiance().unwrap();
        for p in (0..counts.len()).filter(|&p| counts[p] == n && gbuffer.coverage[p] == 1.0) {
            assert_eq!(bits(&[radiance[p]]), bits(&[reference[p]]), "pixel {p} at {n} spp");
        }
    }
    common::gpu::finish(ctx);
}

/// Pixels restarted alone under a threshold, stopped or still sampling, start again from sample
/// 0 and stop where a fresh render stops them: with nothing changed, the image ends as a fresh
/// adaptive render's, bit for bit, and so do the counts. (The pixels still sampling are read
/// from a compacted list after a row's first pass; a restart sends the row back to the covered
/// list, or a stopped pixel restarted would never sample again.)
#[test]
fn restarted_pixels_under_a_threshold_end_as_a_fresh_render_has_them() {
    let ctx = common::gpu::context();
    let noise = Some(NoiseThreshold { threshold: 0.03, min_samples: 8 });
    let max = 40;
    let (gbuffer, mut fresh) = scene(&ctx, 7);
    fresh.set_noise_threshold(noise).unwrap();
    progressive::accumulate(&mut fresh, max, |_| {}).unwrap();
    let counts = fresh.read_sample_counts().unwrap();

    let (_, mut edited) = scene(&ctx, 7);
    edited.set_noise_threshold(noise).unwrap();
    progressive::accumulate(&mut edited, 20, |_| {}).unwrap();
    let stopped = edited.read_sample_counts().unwrap().iter().filter(|&&n| n > 0 && n < 20).count();
    assert!(stopped > 0, "some pixels stopped before the restart");
    let ball: Vec<u32> = (0..gbuffer.object_id.len() as u32)
        .filter(|&p| gbuffer.object_id[p as usize] == BALL && gbuffer.coverage[p as usize] > 0.0)
        .collect();
    edited.restart_pixels(&ball);
    progressive::accumulate(&mut edited, max, |_| {}).unwrap();
    assert_eq!(edited.read_sample_counts().unwrap(), counts);
    assert_eq!(bits(&edited.read_radiance().unwrap()), bits(&fresh.read_radiance().unwrap()));
    common::gpu::finish(ctx);
}

/// At the mean sample count adaptive sampling spent, uniform sampling's relative MSE against a
/// 1024-spp reference of another seed is higher: the threshold buys the same error with fewer
/// samples. (Counted in samples, not timed.)
#[test]
fn at_equal_samples_the_threshold_lowers_the_error() {
    let ctx = common::gpu::context();
    let (gbuffer, mut reference) = scene(&ctx, 1000);
    reference.render_samples(1024).unwrap();
    let reference = reference.read_radiance().unwrap();
    let (_, mut adaptive) = scene(&ctx, 3);
    adaptive.set_noise_threshold(Some(NoiseThreshold { threshold: 0.03, min_samples: 16 })).unwrap();
    let stats = progressive::accumulate(&mut adaptive, 512, |_| {}).unwrap();
    let spent = stats.mean_spp.unwrap();
    let adaptive_error = rel_mse(&gbuffer, &adaptive.read_radiance().unwrap(), &reference);
    let (_, mut uniform) = scene(&ctx, 3);
    uniform.render_samples(spent.ceil() as u32).unwrap();
    let uniform_error = rel_mse(&gbuffer, &uniform.read_radiance().unwrap(), &reference);
    eprintln!("at {spent:.1} spp on average: adaptive {adaptive_error:.3e}, uniform {uniform_error:.3e}");
    assert!(
        adaptive_error < uniform_error,
        "at {spent:.1} spp on average: adaptive {adaptive_error:.3e}, uniform {uniform_error:.3e}"
    );
    common::gpu::finish(ctx);
}

#[test]
fn render_takes_a_noise_threshold_and_refuses_bad_values() {
    let dir = tempfile::tempdir().unwrap();
    let arg = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let g = arg("g.exr");
    assert_success(&lookdev(&["gbuffer", "--builtin", "shaderball", "--size", "40", "40", "--out", &g]));
    let out = arg("a.png");
    let output = lookdev(&["render", "--gbuffer", &g, "--spp", "64", "--noise-threshold", "0.05", "--out", &out]);
    assert_success(&output);
    assert!(stderr(&output).contains("spp on average, at most 64"), "{}", stderr(&output));
    let frames = arg("t_%02d.png");
    let args = ["turntable", "--gbuffer", &g, "--frames", "2", "--spp", "32", "--noise-threshold", "0.05"];
    assert_success(&lookdev(&[&args[..], &["--min-spp", "8", "--quiet", "--out", &frames]].concat()));
    assert!(dir.path().join("t_02.png").is_file());
    let render =
        |extra: &[&str]| lookdev(&[&["render", "--gbuffer", &g, "--spp", "16", "--out", &out][..], extra].concat());
    assert_bad_input(&render(&["--min-spp", "4"]), &["--min-spp 4", "--noise-threshold"]);
    assert_bad_input(&render(&["--noise-threshold", "0"]), &["--noise-threshold 0"]);
    assert_bad_input(&render(&["--noise-threshold", "NaN"]), &["--noise-threshold NaN"]);
    assert_bad_input(&render(&["--noise-threshold", "0.1", "--min-spp", "1"]), &["--min-spp 1", "at least 2"]);
    assert_bad_input(
        &render(&["--noise-threshold", "0.1", "--min-spp", "32"]),
        &["--min-spp 32", "above spp, the most samples a pixel takes (16)"],
    );
}

#[test]
fn a_look_can_ask_for_adaptive_sampling() {
    let dir = tempfile::tempdir().unwrap();
    let arg = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let g = arg("g.exr");
    assert_success(&lookdev(&["gbuffer", "--builtin", "shaderball", "--size", "40", "40", "--out", &g]));
    let look = |name: &str, render: &str| {
        let path = arg(name);
        std::fs::write(&path, format!("[render]\nspp = 64\n{render}")).unwrap();
        path
    };
    let adaptive = look("adaptive.toml", "noise_threshold = 0.05\nmin_spp = 8\n");
    let render = |look: &str, extra: &[&str]| {
        let out = arg("a.exr");
        lookdev(&[&["render", "--gbuffer", &g, "--look", look, "--out", &out][..], extra].concat())
    };
    let output = render(&adaptive, &[]);
    assert_success(&output);
    assert!(stderr(&output).contains("spp on average, at most 64"), "{}", stderr(&output));
    // The look's values are those of the flags: the same image, bit for bit.
    let pixels = || exr_bits(&dir.path().join("a.exr"));
    let from_look = pixels();
    assert_success(&render(&look("plain.toml", ""), &["--noise-threshold", "0.05", "--min-spp", "8"]));
    assert!(pixels() == from_look);
    // A flag overrides the look's threshold.
    let output = render(&adaptive, &["--noise-threshold", "0.5"]);
    assert_success(&output);
    assert!(pixels() != from_look);

    let lone = look("lone.toml", "min_spp = 8\n");
    assert_bad_input(
        &render(&lone, &[]),
        &["lone.toml:3: [render] min_spp = 8", "only adaptive sampling takes it", "[render] noise_threshold"],
    );
    let over = look("over.toml", "noise_threshold = 0.1\nmin_spp = 128\n");
    assert_bad_input(&render(&over, &[]), &["over.toml:4: [render] min_spp = 128", "above spp"]);
    assert_success(&render(&over, &["--min-spp", "16"]));
}
