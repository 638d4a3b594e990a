//! The overlapped start-up (`lookdev::render::startup`): the kernels compiled on the device
//! thread while the scene loads give the image a serial start-up gives, bit for bit; a failure
//! on either side ends the process with one clear error and a non-zero exit, never a hang or a
//! panic, and a bad scene is still reported before a device that failed. An environment file's
//! decoded texels come from the cache the second time, by content, and give the same image.

mod common;

use common::cli::stderr;
use lookdev::gpu::ContextOptions;
use lookdev::render::batch::Batch;
use lookdev::render::renderer::{Accumulate, KernelSource, Specialization};
use lookdev::render::sampling::Sampling;
use lookdev::render::scene::{GBufferSpec, Scene, SceneSpec};
use lookdev::render::settings::Overrides;
use lookdev::render::startup::{self, Started};
use lookdev::render::Renderer;
use lookdev::render::{aov, progressive};
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// The built-in ball at 64², with settings that each change the kernels or the uploads: a
/// BRDF model variant, the plain estimator, a noise threshold.
fn spec() -> SceneSpec {
    SceneSpec {
        gbuffer: GBufferSpec { builtin_size: Some((64, 64)), size_given: true, ..Default::default() },
        overrides: Overrides {
            spp: Some(24),
            seed: Some(7),
            model: vec!["diffuse=oren-nayar".into()],
            sampling: Some(Sampling::Plain),
            noise_threshold: Some(0.05),
            min_spp: Some(8),
            ..Default::default()
        },
        quiet: true,
        ..Default::default()
    }
}

/// Sets what a render needs, in the order `lookdev render` sets it, renders and reads back the
/// radiance and the display pixels.
fn render(mut renderer: Renderer, scene: &Scene, wanted: Accumulate) -> (Vec<u32>, Vec<u8>) {
    let settings = &scene.settings;
    renderer.set_noise_threshold(settings.noise).unwrap();
    renderer.set_accumulate(wanted).unwrap();
    renderer.set_sampling(settings.sampling, &scene.environment).unwrap();
    renderer.set_stacks(&scene.stacks).unwrap();
    renderer.set_lighting(settings.lighting);
    renderer.set_seed(settings.seed);
    progressive::accumulate(&mut renderer, settings.spp, |_| {}).unwrap();
    let radiance = renderer.read_radiance().unwrap().iter().flatten().map(|v| v.to_bits()).collect();
    (radiance, renderer.read_display(settings.exposure, settings.tonemap).unwrap())
}

#[test]
fn the_overlapped_start_up_renders_what_a_serial_one_renders() {
    let wanted = Accumulate { lobes: true, variance: false };
    let options =
        ContextOptions { validation: true, ..ContextOptions::from_env(std::env::var("LOOKDEV_TEST_DEVICE").ok()) };
    let threaded = std::thread::scope(|threads| {
        let specialize = |scene: &_| Specialization::of_render(scene, wanted);
        let Started { scene, ctx, kernels } = startup::start(threads, &spec(), options, specialize).unwrap();
        // The noise threshold needs the variance: the kernels are compiled with it already.
        assert_eq!(kernels.specialization.accumulate, Accumulate { lobes: true, variance: true });
        assert_eq!(kernels.specialization.model, scene.settings.model);
        let sampling = scene.settings.sampling;
        let pending = KernelSource::Pending(kernels);
        let renderer = Renderer::with_kernels(&ctx, &scene.gbuffer, &scene.environment, sampling, pending).unwrap();
        let image = render(renderer, &scene, wanted);
        common::gpu::finish(ctx);
        image
    });
    let scene = Scene::load(&spec()).unwrap();
    let ctx = common::gpu::context();
    let renderer = Renderer::with_model(&ctx, &scene.gbuffer, &scene.environment, &scene.settings.model).unwrap();
    let serial = render(renderer, &scene, wanted);
    common::gpu::finish(ctx);
    assert!(threaded.0 == serial.0, "the radiance differs");
    assert!(threaded.1 == serial.1, "the display pixels differ");
    assert!(serial.0.iter().any(|&bits| f32::from_bits(bits) > 0.0), "a black render proves nothing");
}

#[test]
fn a_batch_started_overlapped_renders_what_a_serial_one_renders() {
    // As `lookdev turntable` starts: kernels for the settings' AOVs, compiled while the scene
    // uploads; then two frames, the second turned.
    let mut spec = spec();
    spec.overrides.aovs = vec!["diffuse".into(), "variance".into()];
    let frames = |batch: &mut Batch, scene: &Scene| -> Vec<Vec<u32>> {
        let mut settings = scene.settings.clone();
        (0..2)
            .map(|frame| {
                settings.lighting.rotation_degrees = 90.0 * frame as f32;
                batch.render(&scene.look, &settings, |_| {}).unwrap();
                let mut bits: Vec<u32> = batch.radiance().unwrap().iter().flatten().map(|v| v.to_bits()).collect();
                for layer in batch.aovs(&scene.look, &settings).unwrap() {
                    bits.extend(layer.channels.iter().flat_map(|(_, values)| values.iter().map(|v| v.to_bits())));
                }
                bits
            })
            .collect()
    };
    let options =
        ContextOptions { validation: true, ..ContextOptions::from_env(std::env::var("LOOKDEV_TEST_DEVICE").ok()) };
    let threaded = std::thread::scope(|threads| {
        let specialize = |scene: &Scene| Specialization::of_render(scene, aov::accumulate(&scene.settings.aovs));
        let Started { scene, ctx, kernels } = startup::start(threads, &spec, options, specialize).unwrap();
        let (name, sampling) = (Path::new("built-in"), scene.settings.sampling);
        let kernels = KernelSource::Pending(kernels);
        let mut batch = Batch::with_kernels(&ctx, &scene.gbuffer, name, &scene.environment, sampling, kernels).unwrap();
        let images = frames(&mut batch, &scene);
        drop(batch);
        common::gpu::finish(ctx);
        images
    });
    let scene = Scene::load(&spec).unwrap();
    let ctx = common::gpu::context();
    let mut batch = Batch::new(&ctx, &scene.gbuffer, Path::new("built-in"), &scene.environment).unwrap();
    let serial = frames(&mut batch, &scene);
    drop(batch);
    common::gpu::finish(ctx);
    assert!(threaded == serial, "the frames differ");
    assert!(serial[0] != serial[1], "the light turned");
}

/// Runs `lookdev render` of the built-in ball at 64², 1 spp unless `extra` says, to
/// `dir/out.exr`, with validation and timings on, `dir/cache` the cache folder, `extra`
/// arguments and `LOOKDEV_FAIL_AT=fail_at` if given; fails if it runs a minute.
fn render_cli(dir: &Path, fail_at: Option<&str>, extra: &[&str]) -> Output {
    let out = dir.join("out.exr");
    let mut command = Command::new(env!("CARGO_BIN_EXE_lookdev"));
    command.args(["render", "--size", "64", "64", "--quiet", "--out", out.to_str().unwrap()]);
    if !extra.contains(&"--spp") {
        command.args(["--spp", "1"]);
    }
    command.args(extra).env("LOOKDEV_VALIDATION", "1").env("LOOKDEV_TIMINGS", "1");
    command.env("XDG_CACHE_HOME", dir.join("cache"));
    match fail_at {
        Some(step) => command.env("LOOKDEV_FAIL_AT", step),
        None => command.env_remove("LOOKDEV_FAIL_AT"),
    };
    // stderr to a file: a pipe nobody reads while waiting could fill and stall the process.
    let log = dir.join("stderr.txt");
    command.stdout(Stdio::null()).stderr(std::fs::File::create(&log).unwrap());
    let mut child = command.spawn().unwrap();
    let started = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if started.elapsed() > Duration::from_secs(60) {
            child.kill().unwrap();
            panic!("lookdev render hung (LOOKDEV_FAIL_AT={fail_at:?}, {extra:?})");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    Output { status, stdout: Vec::new(), stderr: std::fs::read(&log).unwrap() }
}

/// Exit code `code`, no panic, no validation error, no image, and one error line with every
/// fragment.
fn assert_fails(output: &Output, dir: &Path, code: i32, fragments: &[&str]) {
    let text = stderr(output);
    assert_eq!(output.status.code(), Some(code), "{text}");
    assert!(!text.contains("panicked") && !text.contains("validation error"), "{text}");
    let errors: Vec<&str> = text.lines().filter(|l| l.starts_with("lookdev: error:")).collect();
    assert_eq!(errors.len(), 1, "one error line: {text}");
    for fragment in fragments {
        assert!(errors[0].contains(fragment), "the error lacks '{fragment}': {text}");
    }
    assert!(!dir.join("out.exr").exists(), "no image is written");
}

#[test]
fn a_kernel_that_fails_to_compile_on_the_device_thread_fails_the_render_cleanly() {
    for step in ["set-layout", "pipeline-layout", "pipeline"] {
        let dir = tempfile::tempdir().unwrap();
        let output = render_cli(dir.path(), Some(step), &[]);
        assert_fails(&output, dir.path(), 1, &[&format!("injected failure at {step}")]);
    }
}

#[test]
fn a_device_that_fails_to_open_fails_the_render_cleanly() {
    for step in ["device", "context-ready"] {
        let dir = tempfile::tempdir().unwrap();
        let output = render_cli(dir.path(), Some(step), &[]);
        assert_fails(&output, dir.path(), 1, &[&format!("injected failure at {step}")]);
    }
}

#[test]
fn a_bad_scene_is_reported_first_whatever_the_device_thread_does() {
    let dir = tempfile::tempdir().unwrap();
    let look = dir.path().join("missing.toml");
    // The look: the settings are never known.
    for fail_at in [None, Some("device"), Some("pipeline")] {
        let output = render_cli(dir.path(), fail_at, &["--look", look.to_str().unwrap()]);
        assert_fails(&output, dir.path(), 2, &["missing.toml"]);
    }
    // The g-buffer, read after the look and the environment.
    let gbuffer = dir.path().join("garbage.exr");
    std::fs::write(&gbuffer, b"not an image at all").unwrap();
    for fail_at in [None, Some("device"), Some("pipeline")] {
        let output = render_cli(dir.path(), fail_at, &["--gbuffer", gbuffer.to_str().unwrap()]);
        assert_fails(&output, dir.path(), 2, &["garbage.exr"]);
    }
}

/// Every channel of an EXR's layers, as bits (its header names the map, which may differ).
fn pixels(path: &Path) -> Vec<Vec<u32>> {
    use exr::prelude::*;
    let image = read_all_flat_layers_from_file(path).unwrap();
    let layers = image.layer_data.iter().flat_map(|layer| &layer.channel_data.list);
    layers.map(|channel| channel.sample_data.values_as_f32().map(f32::to_bits).collect()).collect()
}

#[test]
fn an_environment_files_decoded_texels_are_cached_by_content() {
    let dir = tempfile::tempdir().unwrap();
    let map = dir.path().join("a.exr");
    std::fs::copy(concat!(env!("CARGO_MANIFEST_DIR"), "/src/environment/studio.exr"), &map).unwrap();
    let render = |map: &Path| {
        let output = render_cli(dir.path(), None, &["--env", map.to_str().unwrap(), "--env-clamp"]);
        assert!(output.status.success(), "{}", stderr(&output));
        let text = stderr(&output);
        // The checks run on cached texels as on decoded ones: the clamp's warning each time.
        assert!(text.contains("clamped 0 NaN, 0 infinite and 3 negative texels"), "{text}");
        (text, pixels(&dir.path().join("out.exr")))
    };
    let loaded = |text: &str| text.contains(".exr loaded from") && text.contains(".texels");
    let stored = |text: &str| text.lines().any(|l| l.contains("cache: wrote") && l.contains("file-"));
    let (cold, image) = render(&map);
    assert!(!loaded(&cold) && stored(&cold), "{cold}");
    let (warm, warm_image) = render(&map);
    assert!(loaded(&warm) && !stored(&warm), "{warm}");
    assert!(warm_image == image, "the cached texels render another image");
    // The same bytes under another name: the same entry.
    let copy = dir.path().join("b.exr");
    std::fs::copy(&map, &copy).unwrap();
    let (text, copy_image) = render(&copy);
    assert!(loaded(&text) && !stored(&text), "{text}");
    assert!(copy_image == image);
    // A damaged entry is decoded again, with the same image, and rewritten.
    let entries: Vec<_> = std::fs::read_dir(dir.path().join("cache/lookdev/environments"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with("file-"))
        .collect();
    assert_eq!(entries.len(), 1, "{entries:?}");
    let bytes = std::fs::read(&entries[0]).unwrap();
    std::fs::write(&entries[0], &bytes[..bytes.len() / 2]).unwrap();
    let (text, repaired) = render(&map);
    assert!(!loaded(&text) && stored(&text), "{text}");
    assert!(repaired == image);
    assert_eq!(std::fs::read(&entries[0]).unwrap(), bytes, "rewritten whole");
}

#[test]
fn each_kernel_and_the_environment_are_made_once() {
    // The renderer is made with the settings' specialisation and estimator, so the options that
    // change them cost no second compile or upload (the timings name each compile and each
    // look-up of the tables).
    let dir = tempfile::tempdir().unwrap();
    let count = |extra: &[&str], what: &str| {
        let output = render_cli(dir.path(), None, extra);
        assert!(output.status.success(), "{}", stderr(&output));
        stderr(&output).lines().filter(|l| l.starts_with(&format!("lookdev: timing: {what} "))).count()
    };
    let threshold = ["--noise-threshold", "0.1", "--min-spp", "2", "--spp", "4"];
    for extra in [&threshold[..], &["--aov", "all"], &["--model", "diffuse=oren-nayar"]] {
        assert_eq!(count(extra, "pipeline relight"), 1, "{extra:?}");
        assert_eq!(count(extra, "pipeline resolve"), 1, "{extra:?}");
    }
    assert_eq!(count(&["--sampling", "plain"], "environment tables"), 1);
}
