//! Hostile and broken inputs through the command line, as an outside tester fed them: every
//! reproducer of a failure found ends in exit code 2 and one line naming the file and the
//! problem, in under 60 s and 200 MiB (100 MiB where only a header is read), except the inputs
//! that are valid but render black, which render with a warning. The parsers behind these
//! commands are fuzzed in `fuzz.rs`, with these reproducers among its regression cases.

mod common;

use common::cli::{assert_bad_input, lookdev_measured, stderr, Measured};
use exr::prelude::WritableImage;
use std::path::{Path, PathBuf};

/// The reproducers kept as the fuzz suite's regression cases.
fn regression(target: &str, name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz/regressions").join(target).join(name);
    assert!(path.is_file(), "{} is missing", path.display());
    path.to_string_lossy().into_owned()
}

/// Runs `lookdev` in `dir` and checks the exit code 2, the one error line with every fragment,
/// and the time and memory bounds.
fn refused(dir: &Path, args: &[&str], fragments: &[&str], max_mib: u64) -> Measured {
    let run = lookdev_measured(dir, args, 60.0, Some(max_mib));
    assert_bad_input(&run.output, fragments);
    assert!(run.peak_mib < max_mib as f64, "lookdev {}: peak {:.0} MiB, over {max_mib}", args.join(" "), run.peak_mib);
    run
}

/// Runs `lookdev` in `dir` and checks it succeeds, with every warning fragment on stderr.
fn succeeds_warning(dir: &Path, args: &[&str], warnings: &[&str]) -> String {
    let run = lookdev_measured(dir, args, 60.0, None);
    let text = stderr(&run.output);
    assert!(run.output.status.success(), "lookdev {}: {text}", args.join(" "));
    for warning in warnings {
        assert!(
            text.lines().any(|l| l.starts_with("lookdev: warning:") && l.contains(warning)),
            "no warning with '{warning}': {text}"
        );
    }
    text
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[cfg(unix)]
fn fifo(dir: &Path, name: &str) -> PathBuf {
    let path = dir.join(name);
    let c = std::ffi::CString::new(path.as_os_str().as_encoded_bytes()).unwrap();
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    path
}

#[test]
fn gltf_the_reader_panicked_on_is_refused_by_bake_and_import() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "position-accessor-99-of-2.gltf",
            "meshes[0].primitives[0].attributes[\"POSITION\"]: accessor 99 does not exist",
        ),
        ("index-accessor-of-floats.gltf", "meshes[0].primitives[0].indices: accessor 1 is FLOAT SCALAR"),
    ];
    for (file, problem) in cases {
        let model = regression("gltf", file);
        refused(dir.path(), &["bake", &model, "--out", "g.exr", "--size", "16", "16"], &[file, problem], 200);
        let import = ["import", &model, "--presets", "p", "--look", "l.toml"];
        refused(dir.path(), &import, &[file, problem], 200);
    }
    assert!(!dir.path().join("g.exr").exists() && !dir.path().join("l.toml").exists());
}

#[test]
fn headers_that_claim_huge_images_are_refused_in_little_memory() {
    let dir = tempfile::tempdir().unwrap();
    let render = |flag: &str, file: &str| {
        [
            "render".to_string(),
            flag.to_string(),
            file.to_string(),
            "--out".into(),
            "x.png".into(),
            "--spp".into(),
            "1".into(),
        ]
    };
    let cases = [
        ("--gbuffer", regression("gbuffer", "header-claims-100000x100000.exr"), "100000x100000 pixels, larger than"),
        ("--gbuffer", regression("gbuffer", "header-claims-20000x20000.exr"), "more than the 4.0 GiB lookdev decodes"),
        ("--env", regression("environment", "header-claims-200000x100000.exr"), "200000x100000 pixels, larger than"),
        ("--env", regression("environment", "dwa-chunk-counter-claims-2-to-the-49-bytes.exr"), "a DWA chunk claims"),
        ("--env", regression("hdr", "header-claims-200000x100000.hdr"), "200000x100000 pixels, larger than"),
    ];
    for (flag, file, problem) in cases {
        let args = render(flag, &file);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let name = Path::new(&file).file_name().unwrap().to_str().unwrap();
        let run = refused(dir.path(), &args, &[name, problem], 100);
        assert!(run.seconds < 10.0, "{name}: {:.1} s", run.seconds);
    }
}

#[test]
fn files_that_never_end_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let look = write(dir.path(), "zero.toml", "[[object]]\n[[object.layer]]\npreset = \"/dev/zero\"\n");
    let look = look.to_str().unwrap();
    let problem = ["zero.toml:3", "/dev/zero", "not a regular file (a character device)"];
    refused(dir.path(), &["render", "--look", look, "--out", "x.png"], &problem, 200);
    refused(dir.path(), &["lint", look], &problem, 200);

    let buffer = regression("gltf", "buffer-uri-dev-zero.gltf");
    let problem = ["buffer-uri-dev-zero.gltf", "buffer 0", "/dev/zero", "not a regular file"];
    refused(dir.path(), &["bake", &buffer, "--out", "g.exr"], &problem, 200);
    refused(dir.path(), &["import", &buffer, "--presets", "p", "--look", "l.toml"], &problem, 200);

    // An image URI of /dev/zero, used by a material.
    let mut json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&buffer).unwrap()).unwrap();
    json["buffers"][0]["uri"] = valid_buffer_uri();
    json["images"] = serde_json::json!([{ "uri": "/dev/zero" }]);
    json["textures"] = serde_json::json!([{ "source": 0 }]);
    json["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = serde_json::json!({ "index": 0 });
    let image = write(dir.path(), "image.gltf", &json.to_string());
    let image = image.to_str().unwrap();
    let problem = ["image.gltf", "image 0", "/dev/zero", "not a regular file"];
    refused(dir.path(), &["bake", image, "--out", "g.exr"], &problem, 200);
    refused(dir.path(), &["import", image, "--presets", "p", "--look", "l.toml"], &problem, 200);
}

/// A valid triangle's buffer, from the reproducer that reads (an out-of-range factor).
fn valid_buffer_uri() -> serde_json::Value {
    let valid = std::fs::read_to_string(regression("gltf", "ok-factors-out-of-range.gltf")).unwrap();
    serde_json::from_str::<serde_json::Value>(&valid).unwrap()["buffers"][0]["uri"].clone()
}

#[cfg(unix)]
#[test]
fn fifos_are_refused_without_waiting_for_a_writer() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fifo(d, "pipe.exr");
    fifo(d, "pipe.toml");
    write(d, "env.toml", "[environment]\nfile = \"pipe.exr\"\n");
    write(d, "preset.toml", "[[object]]\n[[object.layer]]\npreset = \"pipe.toml\"\n");
    let fifo_problem = "not a regular file (a FIFO)";
    let cases: [(&[&str], &[&str]); 6] = [
        (&["render", "--env", "pipe.exr", "--out", "x.png"], &["pipe.exr", fifo_problem]),
        (&["render", "--look", "env.toml", "--out", "x.png"], &["pipe.exr", fifo_problem]),
        (&["render", "--look", "preset.toml", "--out", "x.png"], &["preset.toml:3", "pipe.toml", fifo_problem]),
        (&["lint", "preset.toml"], &["preset.toml:3", "pipe.toml", fifo_problem]),
        (&["render", "--gbuffer", "pipe.exr", "--out", "x.png"], &["pipe.exr", fifo_problem]),
        (&["render", "--look", "pipe.toml", "--out", "x.png"], &["pipe.toml", fifo_problem]),
    ];
    for (args, fragments) in cases {
        let run = refused(d, args, fragments, 200);
        assert!(run.seconds < 10.0, "lookdev {}: {:.1} s", args.join(" "), run.seconds);
    }
}

#[test]
fn a_material_name_of_any_length_bakes_to_a_file_every_reader_reads() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let model = regression("gltf", "ok-material-name-300-characters.gltf");
    let bake = lookdev_measured(d, &["bake", &model, "--out", "g.exr", "--size", "16", "16", "--quiet"], 60.0, None);
    assert!(bake.output.status.success(), "{}", stderr(&bake.output));
    let gbuffer = lookdev::gbuffer::GBuffer::read(&d.join("g.exr")).expect("lookdev reads what it baked");
    let (mask, name) = gbuffer.mask_names.iter().next().expect("the shortened mask records its name");
    assert!(mask.len() <= 64 && name == &"m".repeat(300), "{mask} -> {name}");
    assert!(gbuffer.masks.contains_key(mask));
    // OpenEXR's own tools read it too, where installed (CI installs them).
    for (tool, args) in [("exrheader", vec![]), ("exrinfo", vec!["-v"]), ("exrcheck", vec![])] {
        let mut command = std::process::Command::new(tool);
        command.args(&args).arg(d.join("g.exr"));
        match command.output() {
            Ok(output) => assert!(output.status.success(), "{tool}: {}", String::from_utf8_lossy(&output.stderr)),
            Err(_) if tool == "exrcheck" || std::env::var_os("CI").is_none() => {}
            Err(e) => panic!("{tool} is not installed ({e}); CI installs Debian's openexr"),
        }
    }
    let import = lookdev_measured(d, &["import", &model, "--presets", "p", "--look", "l.toml"], 60.0, None);
    assert!(import.output.status.success(), "{}", stderr(&import.output));
    let presets: Vec<String> = std::fs::read_dir(d.join("p"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(presets, vec![format!("{mask}.toml")], "the preset is named like its mask");
    let render = lookdev_measured(
        d,
        &["render", "--gbuffer", "g.exr", "--look", "l.toml", "--out", "x.png", "--spp", "2", "--quiet"],
        60.0,
        None,
    );
    assert!(render.output.status.success(), "{}", stderr(&render.output));
}

#[test]
fn one_bad_save_never_breaks_the_library() {
    let dir = tempfile::tempdir().unwrap();
    let library = dir.path().join("library");
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_lookdev"))
            .args(args)
            .env("LOOKDEV_PRESETS", &library)
            .env("LOOKDEV_VALIDATION", "1")
            .output()
            .unwrap()
    };
    assert_bad_input(
        &run(&["presets", "save", "mine", "--set", "roughness=0.3", "--tags", ",,"]),
        &["--tags ,,", "a tag must not be empty"],
    );
    assert!(!library.join("mine.toml").exists());
    let long = "a".repeat(300);
    assert_bad_input(
        &run(&["presets", "save", &long, "--set", "roughness=0.3"]),
        &["is not a preset name", "at most 64"],
    );

    // A broken file in the library (written by hand, or by an older version) is skipped by name.
    std::fs::create_dir_all(&library).unwrap();
    std::fs::write(library.join("broken.toml"), "name = \"broken\"\ntags = [\"\", \"\"]\n").unwrap();
    assert!(run(&["presets", "save", "mine", "--set", "roughness=0.3", "--tags", "a, b"]).status.success());
    let list = run(&["presets", "list"]);
    let (out, err) = (String::from_utf8_lossy(&list.stdout), stderr(&list));
    assert!(list.status.success(), "{err}");
    assert!(err.contains("lookdev: warning:") && err.contains("broken.toml:2") && err.contains("skipped"), "{err}");
    assert!(out.lines().any(|l| l.starts_with("mine ")) && out.lines().any(|l| l.starts_with("gold ")), "{out}");
    let sheet = run(&[
        "presets",
        "sheet",
        "--out",
        dir.path().join("s.png").to_str().unwrap(),
        "--size",
        "16",
        "--spp",
        "1",
        "--tag",
        "metal",
        "--quiet",
    ]);
    assert!(sheet.status.success(), "{}", stderr(&sheet));
    assert!(stderr(&sheet).contains("broken.toml:2"));

    // A save killed mid-write leaves a temporary; the next save of that preset removes it.
    let stale = library.join(format!(".mine.toml.{}-0.tmp", i32::MAX));
    std::fs::write(&stale, "name = \"mi").unwrap();
    assert!(run(&["presets", "save", "mine", "--set", "roughness=0.4", "--force"]).status.success());
    assert!(!stale.exists(), "the dead process's temporary is removed");
}

#[test]
fn finite_inputs_never_render_infinite_pixels() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    refused(
        d,
        &["render", "--intensity", "3e38", "--out", "x.png"],
        &["--intensity 3e38 must be a number from 0 to 1e6"],
        200,
    );
    let look = write(d, "bright.toml", "[environment]\nintensity = 1e38\n");
    refused(
        d,
        &["render", "--look", look.to_str().unwrap(), "--out", "x.png"],
        &["bright.toml:2", "intensity = 1e38"],
        200,
    );
    let hdr = regression("hdr", "exponent-255-everywhere.hdr");
    refused(
        d,
        &["render", "--env", &hdr, "--env-any-aspect", "--out", "x.png"],
        &["exponent-255-everywhere.hdr", "brighter than 1e18"],
        200,
    );
    // Every texel f32::MAX.
    let pixels = exr::prelude::SpecificChannels::rgb(|_: exr::prelude::Vec2<usize>| (f32::MAX, f32::MAX, f32::MAX));
    exr::prelude::Image::from_channels((16, 8), pixels).write().to_file(d.join("max.exr")).unwrap();
    refused(d, &["render", "--env", "max.exr", "--out", "x.png"], &["max.exr", "128 brighter than 1e18"], 200);
    // The largest accepted, together, stay finite in the image.
    let uniform = exr::prelude::SpecificChannels::rgb(|_: exr::prelude::Vec2<usize>| (1e18f32, 1e18f32, 1e18f32));
    exr::prelude::Image::from_channels((16, 8), uniform).write().to_file(d.join("limit.exr")).unwrap();
    let args = ["render", "--env", "limit.exr", "--intensity", "1e6", "--out", "x.exr", "--spp", "4", "--quiet"];
    let run = lookdev_measured(d, &args, 60.0, None);
    assert!(run.output.status.success(), "{}", stderr(&run.output));
    let image = exr::prelude::read_all_flat_layers_from_file(d.join("x.exr")).unwrap();
    for channel in &image.layer_data[0].channel_data.list {
        assert!(channel.sample_data.values_as_f32().all(f32::is_finite), "{:?} is not finite everywhere", channel.name);
    }

    // The squared sums behind the variance AOV and adaptive sampling hold the brightest light
    // the bounds allow: at 2^78 (a 2^59 texel at intensity 2^19) the variance AOV is finite and
    // adaptive sampling takes as many samples as at 2^10 (bright enough that every pixel's
    // error is relative), where they once overflowed, failing the AOV and stopping every pixel
    // at --min-spp. Scaling by a power of two is exact, so the counts should match.
    let mean_spp = |texel: f32, intensity: &str| {
        let uniform = exr::prelude::SpecificChannels::rgb(move |_: exr::prelude::Vec2<usize>| (texel, texel, texel));
        exr::prelude::Image::from_channels((16, 8), uniform).write().to_file(d.join("env.exr")).unwrap();
        let args = [
            "render",
            "--env",
            "env.exr",
            "--intensity",
            intensity,
            "--size",
            "48",
            "48",
            "--spp",
            "256",
            "--noise-threshold",
            "0.1",
            "--aov",
            "variance",
            "--out",
            "v.exr",
        ];
        let run = lookdev_measured(d, &args, 60.0, None);
        let text = stderr(&run.output);
        assert!(run.output.status.success(), "{text}");
        let image = exr::prelude::read_all_flat_layers_from_file(d.join("v.exr")).unwrap();
        for channel in &image.layer_data[0].channel_data.list {
            assert!(channel.sample_data.values_as_f32().all(f32::is_finite), "{:?} at {texel}: {text}", channel.name);
        }
        let mean: f64 = text.split(" spp on average").next().unwrap().rsplit(", ").next().unwrap().parse().unwrap();
        mean
    };
    let (bright, brightest) = (mean_spp(1024.0, "1"), mean_spp(2f32.powi(59), "524288"));
    assert!(bright > 17.0, "the scene needs more than --min-spp: {bright}");
    assert!((brightest / bright - 1.0).abs() < 0.01, "{brightest} spp at 2^78 against {bright} at 2^10");
}

#[test]
fn renders_that_come_out_black_say_why() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let black = exr::prelude::SpecificChannels::rgb(|_: exr::prelude::Vec2<usize>| (0f32, 0f32, 0f32));
    exr::prelude::Image::from_channels((16, 8), black).write().to_file(d.join("black.exr")).unwrap();
    let small = ["--out", "x.png", "--spp", "1", "--quiet"];
    let with = |first: &[&'static str]| -> Vec<&'static str> { first.iter().chain(small.iter()).copied().collect() };
    succeeds_warning(
        d,
        &with(&["render", "--env", "black.exr"]),
        &["black.exr: every texel is 0, so the render is black"],
    );
    succeeds_warning(d, &with(&["render", "--intensity", "0"]), &["intensity is 0, so the render is black"]);
    let model = regression("gltf", "ok-node-scaled-1e30.gltf");
    succeeds_warning(
        d,
        &["bake", &model, "--out", "g.exr", "--size", "16", "16", "--quiet"],
        &["the camera sees none of the asset"],
    );
    succeeds_warning(d, &with(&["render", "--gbuffer", "g.exr"]), &["g.exr: no pixel is covered"]);
}

#[test]
fn invalid_gltf_is_refused_naming_the_json_path() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "index-count-1000-on-6-bytes.gltf",
            "accessors[1]: 1000 elements of 2 bytes from byte 0 run past buffer view 1",
        ),
        ("position-vec2.gltf", "attributes[\"POSITION\"]: accessor 0 is FLOAT VEC2, which glTF does not allow"),
        ("version-3.gltf", "asset.version: \"3.0\" is not a glTF 2.x version"),
        ("node-with-two-parents.gltf", "nodes[1].children[0]: node 2 is already a child of node 0"),
        ("node-cycle.gltf", "nodes[0]: the node is its own ancestor"),
        ("image-without-uri-or-view.gltf", "images[0]: it has neither a uri nor a bufferView"),
    ];
    for (file, problem) in cases {
        refused(
            dir.path(),
            &["bake", &regression("gltf", file), "--out", "g.exr", "--size", "16", "16"],
            &[file, problem],
            200,
        );
    }
    let factors = regression("gltf", "ok-factors-out-of-range.gltf");
    succeeds_warning(
        dir.path(),
        &["bake", &factors, "--out", "g.exr", "--size", "16", "16", "--quiet"],
        &["materials[0].pbrMetallicRoughness.metallicFactor = -5 lies outside [0, 1]", "roughnessFactor = 7"],
    );
}

#[test]
fn messages_name_what_is_wrong_and_only_that() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let look = write(d, "shot.toml", "[render]\nexposure = 100\n");
    let run = refused(
        d,
        &["render", "--look", look.to_str().unwrap(), "--out", "x.png"],
        &["shot.toml:2", "exposure = 100 must be within ±64 stops"],
        200,
    );
    assert!(!stderr(&run.output).contains("--exposure"));
    refused(
        d,
        &["gbuffer", "--builtin", "shaderball"],
        &["required arguments were not provided: --out <FILE.exr>"],
        200,
    );
    refused(d, &["render", "--sp", "4", "--out", "x.png"], &["'--sp'", "did you mean '--spp'?"], 200);
    refused(d, &["rendr", "--out", "x.png"], &["'rendr'", "did you mean 'render'?"], 200);
    refused(
        d,
        &["render", "--set", "rougness=0.3", "--out", "x.png"],
        &["unknown parameter 'rougness'", "did you mean 'roughness'?"],
        200,
    );

    // AOVs cannot go into a PNG: asked for on the command line, an error; in the look, a warning.
    refused(d, &["render", "--aov", "diffuse", "--out", "x.png"], &["--aov diffuse", "--aov-display NAME"], 200);
    write(d, "aovs.toml", "[render]\naovs = [\"diffuse\"]\n");
    succeeds_warning(
        d,
        &["render", "--look", "aovs.toml", "--size", "16", "16", "--spp", "1", "--out", "x.png"],
        &["the look's [render] aovs are not written into a PNG (x.png)"],
    );

    // An environment the look names is reported at the look's line, with the path it resolved to.
    std::fs::create_dir(d.join("shots")).unwrap();
    write(d, "shots/env.toml", "[render]\nspp = 1\n[environment]\nfile = \"nope.exr\"\n");
    refused(
        d,
        &["render", "--look", "shots/env.toml", "--out", "x.png"],
        &["shots/env.toml:4: [environment] file: shots/nope.exr: file not found"],
        200,
    );
    write(d, "shots/jpeg.toml", "[environment]\nfile = \"sky.jpg\"\n");
    write(d, "shots/sky.jpg", "not an image");
    refused(
        d,
        &["render", "--look", "shots/jpeg.toml", "--out", "x.png"],
        &["shots/jpeg.toml:2: [environment] file: shots/sky.jpg"],
        200,
    );

    // A folder given as the environment is called a folder, as formats.md promises.
    std::fs::create_dir(d.join("envs")).unwrap();
    refused(d, &["render", "--env", "envs", "--out", "x.png"], &["envs", "not a regular file (a folder)"], 200);

    // Names read from files are escaped: no terminal escape or NUL reaches stderr.
    // TOML's own escapes put ESC and NUL into the name.
    write(d, "escape.toml", "[[object]]\n[[object.layer]]\npreset = \"\\u001b[31mred\\u0000\"\n");
    let run = refused(d, &["lint", "escape.toml"], &["escape.toml:3", "\\x1b[31mred\\0"], 200);
    assert!(!run.output.stderr.iter().any(|&b| b == 0x1b || b == 0), "{}", stderr(&run.output));

    // The suggestions are presets: not the name asked for, nor the looks beside it.
    write(d, "gold2.toml", "[[object]]\n[[object.layer]]\npreset = \"gold2\"\n");
    write(d, "gold3.toml", "[render]\nspp = 4\n");
    let run = refused(d, &["lint", "gold2.toml"], &["no preset named 'gold2' (closest: gold,"], 200);
    let text = stderr(&run.output);
    assert!(!text.contains("closest: gold, gold2") && !text.contains("gold3"), "{text}");
}

/// Every flag that sizes an output is bounded, and checked before any render: a sheet of a
/// million columns once ran for 43 s to a 12.6 GB, 24-million-pixel-wide PNG.
#[test]
fn size_flags_are_bounded_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for columns in ["1000000", "0", "65"] {
        let run = refused(
            d,
            &["presets", "sheet", "--columns", columns, "--out", "s.png"],
            &[&format!("--columns {columns}: a sheet has 1 to 64 columns")],
            200,
        );
        assert!(run.seconds < 10.0, "--columns {columns}: {:.1} s", run.seconds);
    }
    let values: Vec<String> = (0..65).map(|i| format!("{}", i as f32 / 64.0)).collect();
    let values = values.join(",");
    refused(
        d,
        &["wedge", "--param", "roughness", "--values", &values, "--out", "w.png"],
        &["--values: 65 values, more than the 64 a wedge shows"],
        200,
    );
    for frames in ["0", "10801"] {
        refused(
            d,
            &["turntable", "--frames", frames, "--out", "t%d.png"],
            &[&format!("--frames {frames}: a turntable has 1 to 10800 frames")],
            200,
        );
    }
    assert!(!d.join("s.png").exists() && !d.join("w.png").exists());
}

/// An output is never one of the command's own inputs, by any path: `--out g.exr` once replaced
/// the g-buffer it rendered, and `import s.gltf --look s.gltf --force` the asset it read.
#[test]
fn outputs_never_replace_the_commands_own_inputs() {
    use serde_json::json;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let ok = |args: &[&str]| {
        let run = lookdev_measured(d, args, 120.0, None);
        assert!(run.output.status.success(), "lookdev {}: {}", args.join(" "), stderr(&run.output));
    };
    ok(&["gbuffer", "--builtin", "shaderball", "--size", "16", "16", "--out", "g.exr"]);
    let studio = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/environment/studio.exr");
    std::fs::copy(&studio, d.join("e.exr")).unwrap();
    std::fs::hard_link(d.join("e.exr"), d.join("link.exr")).unwrap();
    write(d, "look.toml", "[render]\nspp = 1\n");
    let before: Vec<Vec<u8>> =
        ["g.exr", "e.exr", "look.toml"].iter().map(|f| std::fs::read(d.join(f)).unwrap()).collect();
    let render =
        ["render", "--gbuffer", "g.exr", "--env", "e.exr", "--env-clamp", "--look", "look.toml", "--spp", "1", "--out"];
    for (out, what) in [
        ("g.exr", "a g-buffer, g.exr"),
        ("./e.exr", "an environment, e.exr"),
        ("link.exr", "an environment, e.exr"),
        ("look.toml.exr", ""),
    ] {
        if what.is_empty() {
            ok(&[&render[..], &[out]].concat());
            continue;
        }
        refused(d, &[&render[..], &[out]].concat(), &[out, &format!("the output would replace {what}")], 200);
    }
    // The same through the other writers: a turntable's frames, a g-buffer, an import's look.
    std::fs::hard_link(d.join("e.exr"), d.join("e2.exr")).unwrap();
    refused(
        d,
        &[
            "turntable",
            "--gbuffer",
            "g.exr",
            "--env",
            "e.exr",
            "--env-clamp",
            "--spp",
            "1",
            "--frames",
            "2",
            "--out",
            "e%d.exr",
        ],
        &["e2.exr", "the output would replace an environment"],
        200,
    );
    assert!(!d.join("e1.exr").exists(), "refused before the first frame");
    let after: Vec<Vec<u8>> =
        ["g.exr", "e.exr", "look.toml"].iter().map(|f| std::fs::read(d.join(f)).unwrap()).collect();
    assert!(before == after, "an input was changed");

    let mut gltf = common::gltf::Gltf::new();
    let material = gltf.material(json!({ "name": "painted", "pbrMetallicRoughness": { "roughnessFactor": 0.4 } }));
    let mesh = gltf.mesh("ball", &[(&common::gltf::uv_sphere(1.0, 16, 8), Some(material))]);
    gltf.node(json!({ "name": "ball", "mesh": mesh }));
    let model = gltf.write_gltf(d, "s");
    let model = model.file_name().unwrap().to_str().unwrap();
    let asset = std::fs::read(d.join(model)).unwrap();
    refused(
        d,
        &["import", model, "--presets", "pr", "--look", model, "--force"],
        &[model, "the output would replace a glTF file"],
        200,
    );
    std::fs::hard_link(d.join(model), d.join("linked.exr")).unwrap();
    refused(
        d,
        &["bake", model, "--size", "8", "8", "--out", "linked.exr"],
        &["linked.exr", "the output would replace a glTF file"],
        200,
    );
    assert!(std::fs::read(d.join(model)).unwrap() == asset, "the asset was changed");
    // The look may not take the place of a preset the import writes beside it.
    std::fs::create_dir(d.join("pr")).unwrap();
    refused(
        d,
        &["import", model, "--presets", "pr", "--look", "pr/painted.toml"],
        &["pr/painted.toml", "the look would replace the preset 'painted' this import writes there"],
        200,
    );
    assert!(!d.join("pr/painted.toml").exists(), "nothing is written when the import is refused");
}

/// Vertex attributes that are not finite are refused by the bake, naming the accessor; a vertex
/// colour beyond [0, 1] is clamped with a warning. Both once baked silently into files that
/// `render` then refused.
#[test]
fn bake_refuses_attributes_that_are_not_finite_and_clamps_colours() {
    use serde_json::json;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let model = |name: &str, change: &dyn Fn(&mut common::gltf::Mesh)| {
        let mut mesh = common::gltf::uv_sphere(1.0, 16, 8);
        mesh.colors = Some(vec![[0.5, 0.5, 0.5, 1.0]; mesh.positions.len()]);
        change(&mut mesh);
        let mut gltf = common::gltf::Gltf::new();
        let mesh = gltf.mesh("ball", &[(&mesh, None)]);
        gltf.node(json!({ "name": "ball", "mesh": mesh }));
        gltf.write_gltf(d, name).file_name().unwrap().to_string_lossy().into_owned()
    };
    let nan_uv = model("nan-uv", &|m| m.uvs[5][0] = f32::NAN);
    let infinite_colour = model("inf-color", &|m| m.colors.as_mut().unwrap()[3][1] = f32::INFINITY);
    let huge_colour = model("huge-color", &|m| m.colors.as_mut().unwrap()[3][0] = 3e38);
    for (file, attribute) in [(&nan_uv, "TEXCOORD_0 (accessor 2)"), (&infinite_colour, "COLOR_0 (accessor 3)")] {
        refused(
            d,
            &["bake", file, "--size", "16", "16", "--out", "g.exr"],
            &[file, "mesh 0 'ball' primitive 0", &format!("{attribute} has values that are not finite")],
            200,
        );
        assert!(!d.join("g.exr").exists());
    }
    succeeds_warning(
        d,
        &["bake", &huge_colour, "--size", "16", "16", "--visibility", "off", "--quiet", "--out", "g.exr"],
        &["COLOR_0 (accessor 3) holds values from 0.5 to 3e38, outside [0, 1]; clamped"],
    );
    let run =
        lookdev_measured(d, &["render", "--gbuffer", "g.exr", "--spp", "1", "--quiet", "--out", "x.exr"], 60.0, None);
    assert!(run.output.status.success(), "the bake's own file renders: {}", stderr(&run.output));
}
