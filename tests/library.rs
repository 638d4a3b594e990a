//! The preset library and the batch outputs, through the command line: resolution order and
//! shadowing, saving (atomic, refusing to overwrite), listing, contact sheets, wedges,
//! turntables and lint. Every run has Vulkan validation on; each uses its own user library.

mod common;

use common::golden::golden;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

struct Setup {
    dir: tempfile::TempDir,
}

impl Setup {
    fn new() -> Setup {
        let setup = Setup { dir: tempfile::tempdir().unwrap() };
        std::fs::create_dir_all(setup.library()).unwrap();
        setup
    }

    fn library(&self) -> PathBuf {
        self.dir.path().join("library")
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    fn arg(&self, name: &str) -> String {
        self.path(name).to_string_lossy().into_owned()
    }

    fn write(&self, name: &str, text: &str) -> String {
        let path = self.path(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, text).unwrap();
        path.to_string_lossy().into_owned()
    }

    fn run(&self, args: &[&str]) -> Output {
        Command::new(env!("CARGO_BIN_EXE_lookdev"))
            .args(args)
            .env("LOOKDEV_PRESETS", self.library())
            .env("LOOKDEV_VALIDATION", "1")
            .output()
            .unwrap()
    }
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn ok(o: Output) -> Output {
    assert!(o.status.success(), "failed: {}", stderr(&o));
    o
}

fn preset(roughness: f32, tags: &str) -> String {
    format!("description = \"test\"\ntags = [{tags}]\nroughness = {roughness}\n")
}

/// Saves a look's default-stack bottom layer as a preset and reads back its roughness: which
/// preset the look's `preset = "..."` resolved to.
fn resolved_roughness(s: &Setup, look: &str, name: &str) -> f32 {
    ok(s.run(&["presets", "save", name, "--from-look", look, "--object", "default", "--layer", "0"]));
    let text = std::fs::read_to_string(s.library().join(format!("{name}.toml"))).unwrap();
    text.lines().find_map(|l| l.strip_prefix("roughness = ")).map(|v| v.parse().unwrap()).unwrap_or(0.5)
}

#[test]
fn names_resolve_look_folder_then_user_library_then_built_ins() {
    let s = Setup::new();
    s.write("library/shiny.toml", &preset(0.11, "\"x\""));
    s.write("shots/shiny.toml", &preset(0.22, "\"x\""));
    s.write("library/gold.toml", &preset(0.33, "\"x\""));
    let layer = |p: &str| format!("[[object]]\n[[object.layer]]\npreset = \"{p}\"\n");
    let shot = s.write("shots/shot.toml", &layer("shiny"));
    assert_eq!(resolved_roughness(&s, &shot, "r1"), 0.22, "the look's folder comes first");
    let elsewhere = s.write("other/shot.toml", &layer("shiny"));
    assert_eq!(resolved_roughness(&s, &elsewhere, "r2"), 0.11, "then the user library");
    let silver = s.write("other/silver.toml", &layer("silver"));
    let builtin = lookdev::material::library::builtin("silver").unwrap().params.roughness;
    assert_eq!(resolved_roughness(&s, &silver, "r3"), builtin, "then the built-ins");
    let by_path = s.write("third/shot.toml", &layer("../shots/shiny.toml"));
    assert_eq!(resolved_roughness(&s, &by_path, "r4"), 0.22, "a path works");

    // The user's gold shadows the built-in one, reported once however often it is used.
    let gold_twice = s
        .write("g/shot.toml", "[[object]]\n[[object.layer]]\npreset = \"gold\"\n[[object.layer]]\npreset = \"gold\"\n");
    let o = ok(s.run(&["presets", "save", "g1", "--from-look", &gold_twice, "--object", "default", "--layer", "1"]));
    assert_eq!(stderr(&o).matches("shadows the built-in").count(), 1, "{}", stderr(&o));
    assert!(std::fs::read_to_string(s.library().join("g1.toml")).unwrap().contains("roughness = 0.33"));

    let typo = s.write("t/shot.toml", &layer("golld"));
    let o = s.run(&["lint", &typo]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("no preset named 'golld'") && stderr(&o).contains("closest: gold"), "{}", stderr(&o));
}

#[test]
fn save_round_trips_and_never_clobbers() {
    let s = Setup::new();
    let out = ok(s.run(&[
        "presets",
        "save",
        "teal-tile",
        "--set",
        "base_color=0.05,0.3,0.3",
        "--set",
        "roughness=0.2",
        "--description",
        "Glazed teal tile.",
        "--tags",
        "ceramic,test",
    ]));
    let path = s.library().join("teal-tile.toml");
    assert_eq!(stdout(&out).trim(), path.display().to_string());
    let show = stdout(&ok(s.run(&["presets", "show", "teal-tile"])));
    assert!(show.contains("base_color = [0.05, 0.3, 0.3]") && show.contains("roughness = 0.2\n"), "{show}");
    assert!(show.contains("metallic = 0  # default") && show.contains(&path.display().to_string()), "{show}");
    let listed = stdout(&ok(s.run(&["presets", "list", "--tag", "test"])));
    assert_eq!(listed.lines().count(), 1, "{listed}");
    assert!(listed.starts_with("teal-tile") && listed.contains("(user)") && listed.contains("Glazed teal tile."));

    // Without --force an existing preset is refused and left exactly as it was.
    let before = std::fs::read(&path).unwrap();
    let refused = s.run(&["presets", "save", "teal-tile", "--set", "roughness=0.9"]);
    assert_eq!(refused.status.code(), Some(2), "{}", stderr(&refused));
    assert!(stderr(&refused).contains("already exists"));
    assert_eq!(std::fs::read(&path).unwrap(), before);
    ok(s.run(&["presets", "save", "teal-tile", "--set", "roughness=0.9", "--force"]));
    assert!(std::fs::read_to_string(&path).unwrap().contains("roughness = 0.9"));
    let leftovers: Vec<_> = std::fs::read_dir(s.library()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(leftovers.len(), 1, "no temporary files left: {leftovers:?}");

    // A built-in's name would shadow the built-in in every look: refused unless --force.
    let refused = s.run(&["presets", "save", "gold", "--set", "roughness=0.9"]);
    assert_eq!(refused.status.code(), Some(2), "{}", stderr(&refused));
    assert!(stderr(&refused).contains("'gold' would shadow the built-in preset 'gold'"), "{}", stderr(&refused));
    assert!(!s.library().join("gold.toml").exists());
    ok(s.run(&["presets", "save", "gold", "--set", "roughness=0.9", "--force"]));
    assert!(s.library().join("gold.toml").exists());
    std::fs::remove_file(s.library().join("gold.toml")).unwrap();

    for bad in [
        vec!["presets", "save", "Bad Name", "--set", "roughness=0.5"],
        vec!["presets", "save", "nothing"],
        vec!["presets", "save", "x", "--set", "roughness=7"],
        vec!["presets", "list", "--tag", "no-such-tag"],
        vec!["presets", "show", "no-such-preset"],
    ] {
        let o = s.run(&bad);
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", stderr(&o));
    }
}

#[test]
fn every_builtin_preset_resolves_and_renders() {
    use lookdev::environment::Environment;
    use lookdev::gbuffer::GBuffer;
    use lookdev::material::library;
    use lookdev::render::batch::Batch;
    use lookdev::render::settings::{Overrides, Settings};

    let ctx = common::gpu::context();
    let gbuffer = GBuffer::shaderball(32, 32);
    let env = Environment::studio();
    {
        let mut batch = Batch::new(&ctx, &gbuffer, Path::new("ball"), &env).unwrap();
        for name in library::builtin_names() {
            let look = common::scenes::look(&format!("[[object]]\n[[object.layer]]\npreset = \"{name}\"\n"));
            let settings = Settings::resolve(&look, &Overrides { spp: Some(4), ..Overrides::default() }).unwrap();
            batch.render(&look, &settings, |_| {}).unwrap();
            let radiance = batch.radiance().unwrap();
            let ball = (16 * 32 + 16) as usize;
            assert!(radiance.iter().all(|p| p.iter().all(|v| v.is_finite())), "{name}: not finite");
            assert!(radiance[ball][0] + radiance[ball][1] + radiance[ball][2] > 1e-3, "{name}: black ball");
        }
    }
    common::gpu::finish(ctx);
}

#[test]
fn contact_sheet_matches_its_golden_image() {
    let s = Setup::new();
    for (name, roughness) in [("sheet-a", 0.1), ("sheet-b", 0.4), ("sheet-c", 0.7), ("sheet-d", 1.0)] {
        s.write(&format!("library/{name}.toml"), &preset(roughness, "\"sheet-test\""));
    }
    let out = s.arg("sheet.png");
    let run = ok(s.run(&["presets", "sheet", "--tag", "sheet-test", "--size", "96", "--spp", "64", "--out", &out]));
    let image = image::open(&out).unwrap().to_rgba8();
    let said = format!("lookdev: wrote {out} (4 presets in 2 columns, {}x{})", image.width(), image.height());
    assert!(stderr(&run).contains(&said), "{}", stderr(&run));
    golden("sheet.png", image.width(), image.height(), image.as_raw());
}

#[test]
fn wedge_matches_its_golden_image() {
    let s = Setup::new();
    let out = s.arg("wedge.png");
    let run = ok(s.run(&[
        "wedge",
        "--param",
        "roughness",
        "--values",
        "0,0.5,1",
        "--size",
        "96",
        "--spp",
        "64",
        "--out",
        &out,
    ]));
    let image = image::open(&out).unwrap().to_rgba8();
    let said = format!("lookdev: wrote {out} (1 × 3 renders, {}x{})", image.width(), image.height());
    assert!(stderr(&run).contains(&said), "{}", stderr(&run));
    golden("wedge_roughness.png", image.width(), image.height(), image.as_raw());
    let bad = s.run(&["wedge", "--param", "shininess", "--out", &out]);
    assert_eq!(bad.status.code(), Some(2));
    let bad = s.run(&["wedge", "--param", "roughnes", "--out", &out]);
    assert!(stderr(&bad).contains("--param roughnes: unknown parameter 'roughnes'"), "{}", stderr(&bad));
    assert!(stderr(&bad).contains("did you mean 'roughness'?"), "{}", stderr(&bad));
    let bad = s.run(&["presets", "list", "--tag", "metl"]);
    assert!(stderr(&bad).contains("--tag metl: no preset has this tag"), "{}", stderr(&bad));
    assert!(stderr(&bad).contains("did you mean 'metal'?"), "{}", stderr(&bad));
    // A PNG-only image with another extension is refused before any render.
    for command in [&["wedge", "--param", "roughness"][..], &["presets", "sheet"][..]] {
        let exr = s.arg("sheet.exr");
        let bad = s.run(&[command, &["--spp", "4096", "--out", &exr][..]].concat());
        assert_eq!(bad.status.code(), Some(2), "{}", stderr(&bad));
        assert!(
            stderr(&bad).contains("this image is written only as PNG: name the output FILE.png"),
            "{}",
            stderr(&bad)
        );
    }
    let bad = s.run(&["wedge", "--param", "metallic", "--values", "0,2", "--out", &out]);
    assert_eq!(bad.status.code(), Some(2));
}

#[test]
fn wedges_and_sheets_render_the_model_they_are_given() {
    let s = Setup::new();
    s.write("library/model-test.toml", &preset(0.8, "\"model-test\""));
    let render = |command: &[&str], name: &str, model: Option<&str>| {
        let out = s.arg(name);
        let mut args: Vec<&str> = command.to_vec();
        args.extend(["--size", "32", "--spp", "4", "--quiet", "--out", &out]);
        if let Some(model) = model {
            args.extend(["--model", model]);
        }
        ok(s.run(&args));
        image::open(&out).unwrap().to_rgba8()
    };
    let wedge = ["wedge", "--param", "roughness", "--values", "0.3,0.9"];
    let sheet = ["presets", "sheet", "--tag", "model-test"];
    for (command, name) in [(&wedge[..], "wedge"), (&sheet[..], "sheet")] {
        let plain = render(command, &format!("{name}.png"), None);
        let oren_nayar = render(command, &format!("{name}-on.png"), Some("diffuse=oren-nayar"));
        assert_eq!(plain.dimensions(), oren_nayar.dimensions());
        assert_ne!(plain, oren_nayar, "{name}: --model changes the renders");
        let again = render(command, &format!("{name}-default.png"), Some("diffuse=burley2012"));
        assert_eq!(plain, again, "{name}: the default model, named, is the default render");
    }
    let out = s.arg("bad.png");
    let bad = s.run(&["wedge", "--param", "roughness", "--model", "diffuse=velvet", "--out", &out]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("velvet"));
}

#[test]
fn turntable_frames_are_independent_of_how_the_range_is_split() {
    let s = Setup::new();
    let g = s.arg("g.exr");
    ok(s.run(&["gbuffer", "--builtin", "shaderball", "--size", "48", "48", "--out", &g]));
    let turn = |dir: &str, range: Option<&str>| {
        let pattern = s.arg(&format!("{dir}/turn_%03d.exr"));
        let mut args = vec!["turntable", "--gbuffer", &g, "--spp", "8", "--frames", "4", "--quiet", "--out", &pattern];
        if let Some(r) = range {
            args.extend(["--range", r]);
        }
        ok(s.run(&args));
    };
    turn("whole", None);
    turn("split", Some("1-2"));
    turn("split", Some("3-4"));
    let read = |dir: &str, f: u32| std::fs::read(s.path(&format!("{dir}/turn_{f:03}.exr"))).unwrap();
    for frame in 1..=4 {
        assert_eq!(read("whole", frame), read("split", frame), "frame {frame} differs between runs");
    }
    assert_ne!(read("whole", 1), read("whole", 2), "the environment turns between frames");
    assert!(!s.path("whole/turn_005.exr").exists());
    let bad = s.run(&["turntable", "--frames", "4", "--range", "3-9", "--out", &s.arg("x_%04d.png")]);
    assert_eq!(bad.status.code(), Some(2));
    let bad = s.run(&["turntable", "--frames", "4", "--out", &s.arg("no_pattern.png")]);
    assert_eq!(bad.status.code(), Some(2));
}

#[test]
fn lint_knows_the_maps_and_presets_saved_from_a_bound_layer_keep_their_factors() {
    let s = Setup::new();
    // A white factor times a map: no finding on its own, whatever the map holds.
    let look = s.write(
        "bound.toml",
        "[[object]]\n[[object.layer]]\n[object.layer.set]\nbase_color = [1.0, 1.0, 1.0]\nmetallic = 1.0\n\
         [object.layer.map]\nbase_color = \"tex\"\nmetallic = \"metal\"\n",
    );
    let o = s.run(&["lint", &look]);
    assert!(o.status.success() && stdout(&o).is_empty(), "{}{}", stdout(&o), stderr(&o));

    // With the g-buffer: its pixels are checked with the maps. Half of the covered pixels are
    // half metal, a tenth are dark dielectric.
    let mut g = lookdev::gbuffer::GBuffer::shaderball(32, 32);
    let covered: Vec<usize> = (0..g.pixel_count()).filter(|&i| g.coverage[i] > 0.0).collect();
    let n = g.pixel_count();
    g.maps.insert("tex.R".into(), vec![0.5; n]);
    g.maps.insert("tex.G".into(), vec![0.5; n]);
    g.maps.insert("tex.B".into(), vec![0.5; n]);
    g.maps.insert("metal".into(), vec![1.0; n]);
    for (k, &i) in covered.iter().enumerate() {
        if k % 2 == 0 {
            g.maps.get_mut("metal").unwrap()[i] = 0.5;
        }
    }
    g.write(&s.path("g.exr")).unwrap();
    let o = s.run(&["lint", &look, "--gbuffer", &s.arg("g.exr")]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(
        out.contains(&format!(
            "bound.toml:2: default stack, layer 0: with its maps, 50.0% of the {} pixels",
            covered.len()
        )),
        "{out}"
    );
    assert!(out.contains("metallic = 0.5 is in between"), "{out}");
    assert_eq!(out.lines().count(), 1, "{out}");
    // A bound layer that another covers wholly shows nowhere: no finding.
    let covered_over = s.write(
        "covered.toml",
        "[[object]]\n[[object.layer]]\n[object.layer.set]\nmetallic = 1.0\n[object.layer.map]\nmetallic = \"metal\"\n\
         [[object.layer]]\npreset = \"gold\"\n",
    );
    let o = s.run(&["lint", &covered_over, "--gbuffer", &s.arg("g.exr")]);
    assert!(o.status.success() && stdout(&o).is_empty(), "{}{}", stdout(&o), stderr(&o));
    // A map the g-buffer lacks is an error, as for a render.
    let missing = s.write("missing.toml", "[[object]]\n[[object.layer]]\n[object.layer.map]\nroughness = \"rough\"\n");
    let o = s.run(&["lint", &missing, "--gbuffer", &s.arg("g.exr")]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("missing.toml:2: map 'rough' (bound to roughness) is not in the g-buffer"),
        "{}",
        stderr(&o)
    );

    // Saved as a preset, the bound layer keeps its constants, and says the maps were dropped.
    let o = ok(s.run(&["presets", "save", "factors", "--from-look", &look, "--object", "default", "--layer", "0"]));
    assert!(
        stderr(&o).contains("dropped the maps of base_color (map 'tex'), metallic (map 'metal')"),
        "{}",
        stderr(&o)
    );
    let saved = lookdev::material::Preset::load(&s.library().join("factors.toml")).unwrap();
    assert_eq!((saved.params.base_color, saved.params.metallic), ([1.0; 3], 1.0));
}

#[test]
fn lint_reports_implausible_values_with_reasons_and_passes_clean_looks() {
    let s = Setup::new();
    let clean = s.write(
        "clean.toml",
        "[[object]]\n[[object.layer]]\npreset = \"gold\"\n[[object.layer]]\npreset = \"blue-rubber\"\nmask = \"m\"\n",
    );
    let o = s.run(&["lint", &clean]);
    assert!(o.status.success() && stdout(&o).is_empty() && stderr(&o).is_empty(), "{}{}", stdout(&o), stderr(&o));

    let bad = s.write(
        "bad.toml",
        "[[object]]\nid = 3\n[[object.layer]]\npreset = \"gold\"\n[object.layer.set]\nmetallic = 0.5\n\
         [[object.layer]]\n[object.layer.set]\nbase_color = [0.95, 0.95, 0.95]\nspecular = 1.5\n\
         [[object.layer]]\npreset = \"silver\"\n[object.layer.set]\nbase_color = [0.2, 0.2, 0.2]\n",
    );
    let o = s.run(&["lint", &bad]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let out = stdout(&o);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 4, "{out}");
    assert!(lines[0].contains("bad.toml:3: object 3, layer 0 (gold): metallic = 0.5 is in between"), "{out}");
    assert!(lines[1].contains("bad.toml:7: object 3, layer 1: base_color luminance 0.950"), "{out}");
    assert!(lines[2].contains("specular = 1.5 is above 1"), "{out}");
    assert!(lines[3].contains("layer 2 (silver): metal F0"), "{out}");
}
