//! AOVs: the light AOVs sum to the beauty, each lobe under a white furnace is that lobe's own
//! albedo, the material AOVs are the CPU's blend and the model's albedo, the layers read back in
//! OpenEXR's layout with the render's metadata, and AOVs change neither the beauty nor its
//! determinism.

mod common;

use common::cli::{assert_bad_input, assert_success, lookdev, stderr};
use common::scenes::{look, orthographic_sphere, renderer};
use glam::Vec3;
use lookdev::environment::Environment;
use lookdev::gbuffer::GBuffer;
use lookdev::lab::{lobe_albedos, Subject};
use lookdev::material::stack::PackedStacks;
use lookdev::material::{Look, Param, Params};
use lookdev::render::aov::{self, Aov, Layer};
use lookdev::render::renderer::{Accumulate, LOBES};
use lookdev::render::{Lighting, Renderer};
use std::path::Path;

const EVERYTHING: Accumulate = Accumulate { lobes: true, variance: true };

/// The shader ball with every lobe at work: a coated, sheened, subsurface base; gold through
/// the stripes; an emissive layer through the gradient.
fn every_lobe_look() -> Look {
    look(
        r#"
[[object]]
[[object.layer]]
[object.layer.set]
base_color = [0.6, 0.3, 0.2]
subsurface = 0.5
roughness = 0.35
sheen = 1.0
clearcoat = 1.0
clearcoat_gloss = 0.8
[[object.layer]]
preset = "gold"
mask = "stripes"
[[object.layer]]
mask = "gradient"
opacity = 0.7
[object.layer.set]
emission = [2.0, 1.0, 0.25]
metallic = 0.4
"#,
    )
}

fn layer<'a>(layers: &'a [Layer], name: &str) -> &'a Layer {
    layers.iter().find(|l| l.name == name).unwrap_or_else(|| panic!("no layer {name}"))
}

fn rgb(layer: &Layer, p: usize) -> Vec3 {
    Vec3::new(layer.channels[0].1[p], layer.channels[1].1[p], layer.channels[2].1[p])
}

fn render_with_aovs(r: &mut Renderer, spp: u32) {
    r.set_accumulate(EVERYTHING).unwrap();
    lookdev::render::progressive::accumulate(r, spp, |_| {}).unwrap();
}

/// With the background off, diffuse + specular + clearcoat + sheen + emission is the beauty,
/// pixel by pixel, within 1e-5 relative: the shares are accumulated beside the total from the
/// same samples.
#[test]
fn light_aovs_sum_to_the_beauty() {
    let ctx = common::gpu::context();
    let gbuffer = GBuffer::shaderball(64, 64);
    let look = every_lobe_look();
    let lighting = Lighting { background: false, ..Lighting::default() };
    let mut r = renderer(&ctx, &gbuffer, &Environment::studio(), &look, lighting);
    render_with_aovs(&mut r, 64);
    let aovs = Aov::parse("light").unwrap();
    let layers = aov::layers(&aovs, &aov::Sources { gbuffer: &gbuffer, look: &look, renderer: &r }).unwrap();
    let beauty = r.read_radiance().unwrap();
    let (mut worst, mut lobe_totals) = (0.0f64, [0.0f64; 5]);
    for (p, b) in beauty.iter().enumerate() {
        let beauty = Vec3::new(b[0], b[1], b[2]);
        let mut sum = Vec3::ZERO;
        for (k, layer) in layers.iter().enumerate() {
            let share = rgb(layer, p);
            sum += share;
            lobe_totals[k] += share.element_sum() as f64;
        }
        for c in 0..3 {
            let error = (sum[c] - beauty[c]).abs() as f64 / (beauty[c].abs() as f64).max(1e-3);
            worst = worst.max(error);
        }
    }
    println!("worst relative difference {worst:.2e}; lobe totals {lobe_totals:?}");
    assert!(worst <= 1e-5, "the light AOVs differ from the beauty by {worst:.2e} relative");
    // Every lobe is at work, so a share written to the wrong AOV would show in the furnace test.
    assert!(lobe_totals.iter().all(|&t| t > 1.0), "a lobe is empty: {lobe_totals:?}");
    drop(r);
    common::gpu::finish(ctx);
}

/// Under a uniform white environment, each lobe AOV at a pixel is that lobe's directional
/// albedo at the pixel's view angle, as the lab integrator computes it from the Rust mirror.
#[test]
fn each_lobe_under_a_white_furnace_is_its_albedo() {
    let ctx = common::gpu::context();
    let size = 32;
    let gbuffer = orthographic_sphere(size);
    let env = Environment::uniform([1.0; 3], 64, 32);
    let params = Params {
        base_color: [0.7, 0.5, 0.3],
        subsurface: 0.5,
        metallic: 0.3,
        roughness: 0.4,
        sheen: 1.0,
        clearcoat: 1.0,
        clearcoat_gloss: 0.6,
        ..Params::default()
    };
    let mut one = Look::default_material();
    one.objects[0].layers[0].params = params;
    let mut r = renderer(&ctx, &gbuffer, &env, &one, Lighting::default());
    render_with_aovs(&mut r, 1024);
    let lobes = r.read_lobes(&gbuffer.coverage).unwrap();
    let subject = Subject { label: String::new(), params, shading: r.shading().clone() };
    // Pixels seen at up to 60°, every third one: the GPU's mean per lobe against the integrator's.
    let pixels: Vec<usize> = (0..gbuffer.pixel_count())
        .step_by(3)
        .filter(|&p| gbuffer.coverage[p] > 0.0 && gbuffer.normal[p][2] > 0.5)
        .collect();
    let (mut gpu, mut cpu) = ([Vec3::ZERO; 4], [Vec3::ZERO; 4]);
    for &p in &pixels {
        let integrated = lobe_albedos(&subject, gbuffer.normal[p][2].acos(), 48);
        for k in 0..LOBES.len() {
            gpu[k] += Vec3::from(lobes[k][p]) / pixels.len() as f32;
            cpu[k] += integrated[k] / pixels.len() as f32;
        }
    }
    for k in 0..LOBES.len() {
        println!("{}: rendered {:.4} integrated {:.4}", LOBES[k], gpu[k], cpu[k]);
        assert!(cpu[k].min_element() > 0.002, "{}: the material has this lobe", LOBES[k]);
        for c in 0..3 {
            let tolerance = 0.02 * cpu[k][c] + 0.0005;
            assert!(
                (gpu[k][c] - cpu[k][c]).abs() <= tolerance,
                "{} channel {c}: rendered {} integrated {}",
                LOBES[k],
                gpu[k][c],
                cpu[k][c]
            );
        }
    }
    drop(r);
    common::gpu::finish(ctx);
}

/// Each parameter AOV is the CPU's blend of the stacks at the pixel; the albedo AOV is the
/// model's directional albedo there; the layers' shares of each stack sum to 1 where it shades.
#[test]
fn material_aovs_are_the_cpu_blend_and_the_model_albedo() {
    let ctx = common::gpu::context();
    let gbuffer = GBuffer::shaderball(48, 48);
    let look = every_lobe_look();
    let ids = lookdev::render::scene::covered_object_ids(&gbuffer);
    let stacks = PackedStacks::pack(&look, ids, &gbuffer, Path::new("shader ball")).unwrap();
    let mut r = renderer(&ctx, &gbuffer, &Environment::studio(), &look, Lighting::default());
    render_with_aovs(&mut r, 4);
    let aovs = Aov::parse_all(&["material".into(), "layers".into(), "emission".into()]).unwrap();
    let layers = aov::layers(&aovs, &aov::Sources { gbuffer: &gbuffer, look: &look, renderer: &r }).unwrap();
    let covered: Vec<usize> = (0..gbuffer.pixel_count()).filter(|&p| gbuffer.coverage[p] > 0.0).collect();
    for param in Param::ALL.into_iter().filter(|&p| p != Param::Emission) {
        let layer = layer(&layers, &Aov::Param(param).name());
        for &p in &covered {
            let cpu = stacks.resolve_gbuffer_pixel(&gbuffer, p);
            let expected: Vec<f32> = match cpu.get(param) {
                lookdev::material::Value::Color(c) => c.to_vec(),
                lookdev::material::Value::Scalar(x) => vec![x],
            };
            for (c, value) in expected.iter().enumerate() {
                let got = layer.channels[c].1[p];
                assert!((got - value).abs() <= 1e-6 * value.abs().max(1.0), "{} at {p}: {got} vs {value}", layer.name);
            }
        }
    }
    let emission = layer(&layers, "emission");
    let lit = covered.iter().filter(|&&p| rgb(emission, p).x > 0.1).count();
    assert!(lit > 20, "the emissive layer shows on {lit} pixels");

    let albedo = layer(&layers, "albedo");
    let mut worst = 0.0f32;
    for &p in covered.iter().step_by(37) {
        let params = stacks.resolve_gbuffer_pixel(&gbuffer, p);
        let subject = Subject { label: String::new(), params, shading: r.shading().clone() };
        let mu = Vec3::from(gbuffer.normal[p]).dot(Vec3::from(gbuffer.view[p])).clamp(0.0, 1.0);
        let integrated = lookdev::lab::directional_albedo_with(&subject, mu.acos(), 64);
        let error = (rgb(albedo, p) - integrated).abs().max_element() / integrated.max_element().max(0.05);
        worst = worst.max(error);
    }
    println!("albedo: worst relative difference {worst:.4}");
    assert!(worst < 0.03, "the albedo AOV differs from the integrator by {worst}");

    let shares: Vec<&Layer> = layers.iter().filter(|l| l.name.starts_with("layers_default_")).collect();
    assert_eq!(shares.len(), 3, "one per layer of the default stack");
    for &p in &covered {
        let sum: f32 = shares.iter().map(|l| l.channels[0].1[p]).sum();
        assert!((sum - 1.0).abs() < 1e-5, "the shares at {p} sum to {sum}");
    }
    let gold = shares[1];
    assert!(
        covered.iter().any(|&p| gold.channels[0].1[p] > 0.9) && covered.iter().any(|&p| gold.channels[0].1[p] < 0.1)
    );
    drop(r);
    common::gpu::finish(ctx);
}

/// Accumulating the AOVs changes nothing in the beauty.
#[test]
fn aovs_leave_the_beauty_as_it_was() {
    let ctx = common::gpu::context();
    let gbuffer = GBuffer::shaderball(48, 48);
    let look = every_lobe_look();
    let mut r = renderer(&ctx, &gbuffer, &Environment::studio(), &look, Lighting::default());
    lookdev::render::progressive::accumulate(&mut r, 16, |_| {}).unwrap();
    let plain = r.read_radiance().unwrap();
    render_with_aovs(&mut r, 16);
    let with_aovs = r.read_radiance().unwrap();
    let worst = plain
        .iter()
        .zip(&with_aovs)
        .flat_map(|(a, b)| (0..4).map(move |c| (a[c] - b[c]).abs() / a[c].abs().max(1e-3)))
        .fold(0.0f32, f32::max);
    assert!(worst <= 1e-6, "the beauty changed by {worst} relative with AOVs on");
    drop(r);
    common::gpu::finish(ctx);
}

/// The channel names of an EXR, from its header.
fn exr_channels(path: &Path) -> Vec<String> {
    let meta = exr::meta::MetaData::read_from_file(path, false).unwrap();
    meta.headers[0].channels.list.iter().map(|c| c.name.to_string()).collect()
}

/// One text attribute of an EXR's header.
fn exr_text(path: &Path, name: &str) -> Option<String> {
    let meta = exr::meta::MetaData::read_from_file(path, false).unwrap();
    meta.headers[0].own_attributes.other.iter().find_map(|(key, value)| match value {
        exr::meta::attribute::AttributeValue::Text(text) if key == name => Some(text.to_string()),
        _ => None,
    })
}

/// `render --aov all` writes every AOV as `<name>.R/.G/.B` or `.Y`, and the metadata; OpenEXR's
/// `exrheader` reads the same names (required where CI installs it); a look's `[render] aovs`
/// is used when no flag is given.
#[test]
fn exr_layers_and_metadata_read_back() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("all.exr");
    let out_arg = out.to_string_lossy().into_owned();
    assert_success(&lookdev(&["render", "--out", &out_arg, "--spp", "2", "--seed", "7", "--quiet", "--aov", "all"]));
    let channels = exr_channels(&out);
    let mut expected: Vec<String> = ["R", "G", "B", "A"].map(String::from).to_vec();
    for name in ["diffuse", "specular", "clearcoat", "sheen", "emission", "albedo", "param_base_color", "N", "V"] {
        expected.extend(["R", "G", "B"].map(|c| format!("{name}.{c}")));
    }
    for name in ["param_roughness", "param_metallic", "objectId", "variance", "layers_ball_1_gold"] {
        expected.push(format!("{name}.Y"));
    }
    for name in &expected {
        assert!(channels.contains(name), "no channel {name} in {channels:?}");
    }
    assert_eq!(channels.iter().filter(|c| c.starts_with("param_")).count(), 3 + 10, "every parameter but emission");

    assert_eq!(exr_text(&out, "lookdev/version").as_deref(), Some(env!("CARGO_PKG_VERSION")));
    assert_eq!(exr_text(&out, "lookdev/seed").as_deref(), Some("7"));
    assert_eq!(exr_text(&out, "lookdev/spp").as_deref(), Some("2"));
    assert_eq!(exr_text(&out, "lookdev/environment").as_deref(), Some("built-in city"));
    assert_eq!(exr_text(&out, "lookdev/environmentHash").map(|h| h.len()), Some(16));
    assert!(exr_text(&out, "lookdev/model").is_some_and(|m| !m.is_empty()));
    let look_text = exr_text(&out, "lookdev/look").unwrap();
    Look::parse(&look_text, Path::new("from the header")).expect("the recorded look reads back");

    match std::process::Command::new("exrheader").arg(&out).output() {
        Ok(output) => {
            assert!(output.status.success(), "exrheader: {}", String::from_utf8_lossy(&output.stderr));
            let text = String::from_utf8_lossy(&output.stdout);
            for name in &expected {
                assert!(
                    text.contains(&format!("    {name}, 32-bit floating-point")),
                    "exrheader lacks {name}:\n{text}"
                );
            }
            assert!(text.contains("lookdev/seed (type string): \"7\""), "{text}");
        }
        Err(_) if std::env::var_os("CI").is_none() => {}
        Err(e) => panic!("exrheader is not installed ({e}); CI installs Debian's openexr"),
    }

    // The look's list, when no flag names any; a beauty-only render has no AOV channels.
    let look = dir.path().join("look.toml");
    std::fs::write(&look, "[render]\naovs = [\"specular\", \"N\"]\n").unwrap();
    let listed = dir.path().join("listed.exr");
    let look_arg = look.to_string_lossy().into_owned();
    let listed_arg = listed.to_string_lossy().into_owned();
    assert_success(&lookdev(&["render", "--look", &look_arg, "--out", &listed_arg, "--spp", "1", "--quiet"]));
    let mut channels = exr_channels(&listed);
    channels.sort();
    assert_eq!(channels, ["A", "B", "G", "N.B", "N.G", "N.R", "R", "specular.B", "specular.G", "specular.R"]);
}

/// The same inputs and seed give the same file, AOVs and all; the beauty is the same with and
/// without them.
#[test]
fn renders_with_aovs_are_deterministic() {
    let dir = tempfile::tempdir().unwrap();
    let render = |name: &str, aovs: &[&str]| {
        let out = dir.path().join(name);
        let out_arg = out.to_string_lossy().into_owned();
        let mut args = vec!["render", "--out", &out_arg, "--spp", "8", "--quiet"];
        for aov in aovs {
            args.extend(["--aov", aov]);
        }
        assert_success(&lookdev(&args));
        out
    };
    let a = render("a.exr", &["light", "variance", "albedo"]);
    let b = render("b.exr", &["light", "variance", "albedo"]);
    assert!(std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap(), "two renders differ");
    let plain = render("plain.exr", &[]);
    let beauty = |path: &Path| {
        let image = exr::prelude::read_all_flat_layers_from_file(path).unwrap();
        let layer = &image.layer_data[0];
        ["R", "G", "B", "A"]
            .map(|name| {
                let channel = layer.channel_data.list.iter().find(|c| c.name.to_string() == name).unwrap();
                channel.sample_data.values_as_f32().collect::<Vec<f32>>()
            })
            .to_vec()
    };
    let (with, without) = (beauty(&a), beauty(&plain));
    for (x, y) in with.iter().flatten().zip(without.iter().flatten()) {
        assert!((x - y).abs() <= 1e-6 * y.abs().max(1e-3), "the beauty changed with AOVs: {x} vs {y}");
    }
}

/// `--aov-display` writes one AOV as a PNG: normals mapped from [-1, 1], lobes tone-mapped; a
/// group, an unknown name or an EXR output is one clear error.
#[test]
fn aov_display_writes_a_png_of_one_aov() {
    let dir = tempfile::tempdir().unwrap();
    let g = dir.path().join("g.exr").to_string_lossy().into_owned();
    assert_success(&lookdev(&["gbuffer", "--builtin", "shaderball", "--size", "32", "32", "--out", &g]));
    let png = dir.path().join("n.png").to_string_lossy().into_owned();
    assert_success(&lookdev(&[
        "render",
        "--gbuffer",
        &g,
        "--out",
        &png,
        "--spp",
        "1",
        "--quiet",
        "--aov-display",
        "N",
    ]));
    let image = image::open(&png).unwrap().to_rgb8();
    // The ball faces the camera at its centre: N = (0, 0, 1), shown as (0.5, 0.5, 1).
    let centre = GBuffer::read(Path::new(&g)).unwrap();
    let p = (0..centre.pixel_count())
        .filter(|&p| centre.coverage[p] >= 1.0)
        .max_by(|&a, &b| centre.normal[a][2].total_cmp(&centre.normal[b][2]))
        .unwrap();
    let pixel = image.get_pixel(p as u32 % 32, p as u32 / 32).0;
    assert!(pixel[2] > 250 && (pixel[0] as i32 - 188).abs() < 25 && (pixel[1] as i32 - 188).abs() < 25, "{pixel:?}");

    let specular = dir.path().join("s.png").to_string_lossy().into_owned();
    assert_success(&lookdev(&[
        "render",
        "--gbuffer",
        &g,
        "--out",
        &specular,
        "--spp",
        "4",
        "--quiet",
        "--aov-display",
        "specular",
    ]));
    let image = image::open(&specular).unwrap().to_rgb8();
    assert!(image.pixels().any(|p| p.0 != [0, 0, 0]), "the specular AOV is not black");

    let bad = |aov: &str, out: &str, fragments: &[&str]| {
        let out = dir.path().join(out).to_string_lossy().into_owned();
        assert_bad_input(&lookdev(&["render", "--gbuffer", &g, "--out", &out, "--aov-display", aov]), fragments);
    };
    bad("specullar", "x.png", &["unknown AOV 'specullar'", "did you mean 'specular'?"]);
    bad("light", "x.png", &["name one AOV, not a group"]);
    bad("N", "x.exr", &["only a PNG shows one AOV"]);
    let output = lookdev(&["render", "--gbuffer", &g, "--out", "x.exr", "--aov", "defuse"]);
    assert_bad_input(&output, &["--aov", "unknown AOV 'defuse'", "did you mean 'diffuse'?"]);
    assert!(!stderr(&output).contains("panicked"));
}

/// `turntable --aov` writes the AOVs into every EXR frame.
#[test]
fn turntable_frames_carry_aovs() {
    let dir = tempfile::tempdir().unwrap();
    let g = dir.path().join("g.exr").to_string_lossy().into_owned();
    assert_success(&lookdev(&["gbuffer", "--builtin", "shaderball", "--size", "24", "24", "--out", &g]));
    let out = dir.path().join("frame_%02d.exr").to_string_lossy().into_owned();
    let args = ["turntable", "--gbuffer", &g, "--frames", "2", "--spp", "2", "--quiet", "--aov", "specular"];
    assert_success(&lookdev(&[&args[..], &["--aov", "objectId", "--out", &out]].concat()));
    for frame in ["frame_01.exr", "frame_02.exr"] {
        let channels = exr_channels(&dir.path().join(frame));
        for name in ["specular.R", "specular.G", "specular.B", "objectId.Y"] {
            assert!(channels.iter().any(|c| c == name), "{frame} lacks {name}: {channels:?}");
        }
        assert_eq!(exr_text(&dir.path().join(frame), "lookdev/spp").as_deref(), Some("2"));
    }
}

/// An EXR's provenance re-renders it: its recorded look, rendered from another folder with its
/// recorded flags, gives the same pixels, bit for bit, through every flag that changes the image.
/// The look once dropped --rotation, --env, --intensity, --spp and the rest.
#[test]
fn the_recorded_look_and_flags_render_the_same_image() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let arg = |name: &str| d.join(name).to_string_lossy().into_owned();
    assert_success(&lookdev(&["gbuffer", "--builtin", "shaderball", "--size", "32", "32", "--out", &arg("g.exr")]));
    let sunrise = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/environment/sunrise.exr");
    std::fs::copy(&sunrise, d.join("sky.exr")).unwrap();
    std::fs::create_dir(d.join("shots")).unwrap();
    std::fs::write(d.join("shots/shiny.toml"), "roughness = 0.15\nmetallic = 1\n").unwrap();
    std::fs::write(
        d.join("shots/look.toml"),
        "[environment]\nrotation = 10\n[[object]]\n[[object.layer]]\npreset = \"shiny\"\n[[object.layer]]\npreset = \"gold\"\nmask = \"stripes\"\n",
    )
    .unwrap();
    let sky = arg("sky.exr");
    let cases: Vec<Vec<&str>> = vec![
        vec!["--size", "32", "32", "--spp", "4", "--rotation", "33"],
        vec![
            "--size",
            "24",
            "16",
            "--spp",
            "3",
            "--seed",
            "9",
            "--env",
            "sunrise",
            "--intensity",
            "2.5",
            "--exposure",
            "1",
        ],
        vec![
            "--size",
            "32",
            "32",
            "--spp",
            "8",
            "--set",
            "roughness=0.2",
            "--model",
            "specular_d=gtr",
            "--model",
            "gtr_gamma=1.5",
        ],
        vec!["--size", "32", "32", "--spp", "16", "--noise-threshold", "0.2", "--min-spp", "4", "--no-background"],
        vec!["--size", "32", "32", "--spp", "4", "--sampling", "plain", "--tonemap", "aces", "--aov", "diffuse"],
        vec!["--gbuffer", "g.exr", "--spp", "4", "--env", &sky, "--env-clamp", "--supersample", "2", "--no-visibility"],
        vec!["--gbuffer", "g.exr", "--spp", "2", "--look", "shots/look.toml", "--rotation", "-45"],
    ];
    std::fs::create_dir(d.join("elsewhere")).unwrap();
    for (i, flags) in cases.iter().enumerate() {
        let out = arg(&format!("{i}.exr"));
        let mut args = vec!["render", "--quiet", "--out", &out];
        args.extend(flags);
        let run =
            std::process::Command::new(env!("CARGO_BIN_EXE_lookdev")).args(&args).current_dir(d).output().unwrap();
        assert_success(&run);
        let look = exr_text(Path::new(&out), "lookdev/look").unwrap();
        let recorded_flags = exr_text(Path::new(&out), "lookdev/flags").unwrap();
        // Saved and rendered elsewhere, with nothing but the recorded look and flags.
        let saved = d.join("elsewhere").join(format!("{i}.toml"));
        std::fs::write(&saved, &look).unwrap();
        let again = arg(&format!("again-{i}.exr"));
        let mut args = vec!["render", "--quiet", "--look", saved.to_str().unwrap(), "--out", &again];
        args.extend(recorded_flags.split_whitespace());
        let run = std::process::Command::new(env!("CARGO_BIN_EXE_lookdev"))
            .args(&args)
            .current_dir(d.join("elsewhere"))
            .output()
            .unwrap();
        assert_success(&run);
        assert!(
            common::cli::exr_bits(Path::new(&out)) == common::cli::exr_bits(Path::new(&again)),
            "case {i} ({flags:?}) does not re-render from its look ({recorded_flags}):\n{look}"
        );
        assert_eq!(
            exr_text(Path::new(&again), "lookdev/look").as_deref(),
            Some(look.as_str()),
            "case {i}: the look is a fixed point"
        );
    }
}
