//! G-buffers of other renderers, written here from the published conventions: Arnold-style
//! AOV files (`N`, `P`, `Z`, `crypto_object` and `crypto_material`, `worldToCamera`), single-
//! and multi-part, must give the same g-buffer as the equivalent lookdev file. And the errors
//! of sources: ambiguous files, unknown layers, broken manifests, explicit mappings.

mod common;

use common::cli::{assert_bad_input, lookdev};
use exr::prelude::*;
use glam::Vec3;
use lookdev::gbuffer::source::cryptomatte::{hash_to_float, murmur3_32};
use lookdev::gbuffer::{GBuffer, SourceOptions};
use std::path::Path;

const WIDTH: usize = 48;
const HEIGHT: usize = 36;
const EYE: Vec3 = Vec3::new(0.0, 0.0, 4.0);
const OBJECTS: [&str; 2] = ["ball", "moon"];
const MATERIALS: [&str; 2] = ["Red Paint", "Gold"];

/// Two spheres seen by a pinhole at EYE looking down −Z: per pixel, which object (0 for
/// none), its position and normal, and the camera ray.
struct Scene {
    object: Vec<usize>,
    position: Vec<Vec3>,
    normal: Vec<Vec3>,
    ray: Vec<Vec3>,
}

fn scene() -> Scene {
    let spheres = [(Vec3::ZERO, 1.0f32), (Vec3::new(1.3, 0.5, -1.0), 0.4)];
    let mut s = Scene { object: vec![], position: vec![], normal: vec![], ray: vec![] };
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            let u = ((x as f32 + 0.5) / WIDTH as f32 - 0.5) * 1.2;
            let v = (0.5 - (y as f32 + 0.5) / HEIGHT as f32) * 0.9;
            let ray = Vec3::new(u, v, -1.0).normalize();
            let mut hit = (0, f32::INFINITY);
            for (i, (centre, radius)) in spheres.iter().enumerate() {
                let oc = EYE - *centre;
                let b = oc.dot(ray);
                let disc = b * b - (oc.length_squared() - radius * radius);
                if disc > 0.0 && -b - disc.sqrt() < hit.1 {
                    hit = (i + 1, -b - disc.sqrt());
                }
            }
            let (object, t) = hit;
            let position = if object > 0 { EYE + ray * t } else { Vec3::ZERO };
            let normal = if object > 0 { (position - spheres[object - 1].0).normalize() } else { Vec3::ZERO };
            s.object.push(object);
            s.position.push(position);
            s.normal.push(normal);
            s.ray.push(ray);
        }
    }
    s
}

fn channel(name: &str, values: Vec<f32>) -> AnyChannel<FlatSamples> {
    AnyChannel::new(Text::from(name), FlatSamples::F32(values))
}

fn vector(layer: &str, suffixes: [&str; 3], vectors: &[Vec3]) -> Vec<AnyChannel<FlatSamples>> {
    (0..3).map(|k| channel(&format!("{layer}.{}", suffixes[k]), vectors.iter().map(|v| v[k]).collect())).collect()
}

/// One Cryptomatte rank (two id/coverage pairs), with every pixel wholly one entry or none.
fn crypto_rank(layer: &str, entry: impl Fn(usize) -> Option<&'static str>) -> Vec<AnyChannel<FlatSamples>> {
    let pixels = WIDTH * HEIGHT;
    let id = |p: usize| entry(p).map_or(0.0, |name| hash_to_float(murmur3_32(name.as_bytes())));
    let coverage = |p: usize| if entry(p).is_some() { 1.0 } else { 0.0 };
    vec![
        channel(&format!("{layer}00.R"), (0..pixels).map(id).collect()),
        channel(&format!("{layer}00.G"), (0..pixels).map(coverage).collect()),
        channel(&format!("{layer}00.B"), vec![0.0; pixels]),
        channel(&format!("{layer}00.A"), vec![0.0; pixels]),
    ]
}

fn manifest_attributes(attributes: &mut LayerAttributes, layer: &str, names: &[&str]) {
    let key = &format!("{:08x}", murmur3_32(layer.as_bytes()))[..7];
    let manifest: Vec<String> = names.iter().map(|n| format!("\"{n}\":\"{:08x}\"", murmur3_32(n.as_bytes()))).collect();
    for (field, value) in [
        ("name", layer.to_string()),
        ("hash", "MurmurHash3_32".into()),
        ("conversion", "uint32_to_float32".into()),
        ("manifest", format!("{{{}}}", manifest.join(","))),
    ] {
        attributes.other.insert(
            Text::from(format!("cryptomatte/{key}/{field}").as_str()),
            AttributeValue::Text(Text::from(value.as_str())),
        );
    }
}

/// An AOV's name and its channels.
type ChannelGroup = (String, Vec<AnyChannel<FlatSamples>>);

/// The Arnold-style AOVs of the scene: N and P (`.R .G .B`), Z, and Cryptomatte for objects
/// and materials, with the camera as OpenEXR's worldToCamera (row vectors).
fn arnold_channels(s: &Scene) -> (Vec<ChannelGroup>, LayerAttributes) {
    let mut attributes = LayerAttributes {
        world_to_camera: Some([1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., -EYE.x, -EYE.y, -EYE.z, 1.]),
        ..LayerAttributes::default()
    };
    manifest_attributes(&mut attributes, "crypto_object", &OBJECTS);
    manifest_attributes(&mut attributes, "crypto_material", &MATERIALS);
    let object = |p: usize| (s.object[p] > 0).then(|| OBJECTS[s.object[p] - 1]);
    let material = |p: usize| (s.object[p] > 0).then(|| MATERIALS[s.object[p] - 1]);
    let depth: Vec<f32> =
        s.position.iter().zip(&s.object).map(|(p, &o)| if o > 0 { EYE.z - p.z } else { 0.0 }).collect();
    let groups = vec![
        ("N".to_string(), vector("N", ["R", "G", "B"], &s.normal)),
        ("P".to_string(), vector("P", ["R", "G", "B"], &s.position)),
        ("Z".to_string(), vec![channel("Z", depth)]),
        ("crypto_object".to_string(), crypto_rank("crypto_object", object)),
        ("crypto_material".to_string(), crypto_rank("crypto_material", material)),
    ];
    (groups, attributes)
}

fn write_layers(path: &Path, layers: Vec<Layer<AnyChannels<FlatSamples>>>) {
    let bounds = IntegerBounds::from_dimensions((WIDTH, HEIGHT));
    Image::from_layers(ImageAttributes::new(bounds), layers).write().to_file(path).unwrap();
}

fn layer(
    name: Option<&str>,
    attributes: LayerAttributes,
    channels: Vec<AnyChannel<FlatSamples>>,
) -> Layer<AnyChannels<FlatSamples>> {
    let attributes = LayerAttributes { layer_name: name.map(Text::from), ..attributes };
    Layer::new((WIDTH, HEIGHT), attributes, Encoding::SMALL_LOSSLESS, AnyChannels::sort(channels.into()))
}

/// The same scene in lookdev's own format, with V toward the eye (the reversed ray, which for
/// a covered pixel is also toward the eye from its position).
fn lookdev_file(s: &Scene, path: &Path) {
    let pixels = WIDTH * HEIGHT;
    let view: Vec<Vec3> =
        (0..pixels).map(|p| if s.object[p] > 0 { (EYE - s.position[p]).normalize() } else { -s.ray[p] }).collect();
    let mut channels = vector("N", ["X", "Y", "Z"], &s.normal);
    channels.extend(vector("V", ["X", "Y", "Z"], &view));
    channels.push(channel("A", s.object.iter().map(|&o| if o > 0 { 1.0 } else { 0.0 }).collect()));
    channels
        .push(AnyChannel::new(Text::from("objectId"), FlatSamples::U32(s.object.iter().map(|&o| o as u32).collect())));
    channels.push(channel("mask.Red_Paint", s.object.iter().map(|&o| if o == 1 { 1.0 } else { 0.0 }).collect()));
    channels.push(channel("mask.Gold", s.object.iter().map(|&o| if o == 2 { 1.0 } else { 0.0 }).collect()));
    let mut attributes = LayerAttributes::default();
    for (i, name) in OBJECTS.iter().enumerate() {
        attributes
            .other
            .insert(Text::from(format!("objectName.{}", i + 1).as_str()), AttributeValue::Text(Text::from(*name)));
    }
    attributes.other.insert(Text::from("maskName.Red_Paint"), AttributeValue::Text(Text::from("Red Paint")));
    write_layers(path, vec![layer(None, attributes, channels)]);
}

fn read(path: &Path) -> lookdev::gbuffer::Read {
    GBuffer::read_with(path, &SourceOptions::default()).unwrap()
}

#[test]
fn arnold_files_single_and_multi_part_read_as_the_equivalent_lookdev_file() {
    let dir = tempfile::tempdir().unwrap();
    let s = scene();
    lookdev_file(&s, &dir.path().join("lookdev.exr"));
    let (groups, attributes) = arnold_channels(&s);
    let single = dir.path().join("single.exr");
    write_layers(&single, vec![layer(None, attributes.clone(), groups.iter().flat_map(|(_, c)| c.clone()).collect())]);
    // Multi-part, an AOV a part, each part's channels without the layer prefix where they have
    // none of their own (Cryptomatte's ranks keep their names).
    let multi = dir.path().join("multi.exr");
    let parts = groups
        .iter()
        .map(|(name, channels)| {
            let channels = channels
                .iter()
                .map(|c| {
                    let full = c.name.to_string();
                    let short = match full.strip_prefix(&format!("{name}.")) {
                        Some(component) if !name.starts_with("crypto") => component.to_string(),
                        _ => full,
                    };
                    AnyChannel::new(Text::from(short.as_str()), c.sample_data.clone())
                })
                .collect();
            layer(Some(name), attributes.clone(), channels)
        })
        .collect();
    write_layers(&multi, parts);

    let expected = read(&dir.path().join("lookdev.exr")).gbuffer;
    for path in [&single, &multi] {
        let read = read(path);
        assert_eq!(read.detected.source, lookdev::gbuffer::source::Source::Arnold, "{}", path.display());
        let g = read.gbuffer;
        let covered: Vec<usize> = (0..WIDTH * HEIGHT).filter(|&p| s.object[p] > 0).collect();
        assert!(covered.len() > 300);
        let first_difference = |a: &[[f32; 3]], b: &[[f32; 3]]| (0..a.len()).find(|&p| a[p] != b[p]);
        assert_eq!(first_difference(&g.normal, &expected.normal), None, "N, bit for bit");
        assert!(g.coverage == expected.coverage, "A, bit for bit");
        assert!(g.object_id == expected.object_id, "ids, bit for bit");
        assert!(g.masks == expected.masks, "mattes, bit for bit");
        assert_eq!(g.object_names, expected.object_names);
        assert_eq!(g.mask_names, expected.mask_names);
        for p in 0..WIDTH * HEIGHT {
            let (ours, theirs) = (Vec3::from(g.view[p]), Vec3::from(expected.view[p]));
            // Covered pixels from P and the camera; the background from the fitted pinhole.
            let tolerance = if s.object[p] > 0 { 1e-6 } else { 1e-4 };
            assert!(ours.distance(theirs) < tolerance, "V at pixel {p}: {ours} against {theirs}");
        }
    }
}

#[test]
fn ambiguous_and_broken_sources_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = scene();
    let path = |name: &str| d.join(name).to_string_lossy().into_owned();
    let render = |gbuffer: &str, extra: &[&str]| {
        let out = path("x.png");
        let mut args = vec!["render", "--gbuffer", gbuffer, "--out", &out, "--spp", "1"];
        args.extend_from_slice(extra);
        lookdev(&args)
    };
    // Two Blender view layers.
    let mut channels = vector("Left.Normal", ["X", "Y", "Z"], &s.normal);
    channels.extend(vector("Right.Normal", ["X", "Y", "Z"], &s.normal));
    write_layers(&d.join("layers.exr"), vec![layer(None, LayerAttributes::default(), channels)]);
    assert_bad_input(
        &render(&path("layers.exr"), &[]),
        &["layers.exr", "several Blender view layers (Left, Right)", "--gbuffer-layer"],
    );
    assert_bad_input(
        &render(&path("layers.exr"), &["--gbuffer-layer", "Middle"]),
        &["--gbuffer-layer Middle: no such view layer (the file has Left, Right)"],
    );
    // The normals here are Y-up, which a Blender file is not: the trap names the flag.
    assert_bad_input(
        &render(&path("layers.exr"), &["--gbuffer-layer", "Right"]),
        &["layers.exr", "the normals look Y-up", "pass --up y"],
    );
    let right = render(&path("layers.exr"), &["--gbuffer-layer", "Right", "--up", "y", "--quiet"]);
    assert!(right.status.success(), "{}", common::cli::stderr(&right));

    // lookdev's normals beside a Blender layer.
    let mut channels = vector("N", ["X", "Y", "Z"], &s.normal);
    channels.push(channel("A", vec![1.0; WIDTH * HEIGHT]));
    channels.extend(vector("ViewLayer.Normal", ["X", "Y", "Z"], &s.normal));
    write_layers(&d.join("both.exr"), vec![layer(None, LayerAttributes::default(), channels)]);
    assert_bad_input(
        &render(&path("both.exr"), &[]),
        &["both.exr", "could be read several ways", "--gbuffer-channel normal=NAME"],
    );

    // A broken manifest.
    let (groups, mut attributes) = arnold_channels(&s);
    let key = &format!("{:08x}", murmur3_32(b"crypto_object"))[..7];
    attributes.other.insert(
        Text::from(format!("cryptomatte/{key}/manifest").as_str()),
        AttributeValue::Text(Text::from("{\"ball\": 7")),
    );
    write_layers(
        &d.join("manifest.exr"),
        vec![layer(None, attributes, groups.into_iter().flat_map(|(_, c)| c).collect())],
    );
    assert_bad_input(
        &render(&path("manifest.exr"), &[]),
        &["manifest.exr", "Cryptomatte layer crypto_object", "manifest is not valid JSON"],
    );

    // Any other renderer, through an explicit mapping.
    let mut channels = vector("Nworld", ["x", "y", "z"], &s.normal);
    channels.push(channel("alpha", s.object.iter().map(|&o| if o > 0 { 1.0 } else { 0.0 }).collect()));
    write_layers(&d.join("other.exr"), vec![layer(None, LayerAttributes::default(), channels)]);
    assert_bad_input(
        &render(&path("other.exr"), &[]),
        &[
            "other.exr",
            "missing normal channels",
            "Nworld.x, Nworld.y, Nworld.z, alpha",
            "--gbuffer-channel normal=NAME",
        ],
    );
    let options = SourceOptions::default();
    let mut mapped = options.clone();
    mapped.channels.set("normal", "Nworld").unwrap();
    mapped.channels.set("coverage", "alpha").unwrap();
    let read = GBuffer::read_with(&d.join("other.exr"), &mapped).unwrap();
    assert_eq!(
        read.gbuffer.coverage.iter().filter(|&&a| a == 1.0).count(),
        s.object.iter().filter(|&&o| o > 0).count()
    );
    // In words a reader parses ("no the camera" once read there).
    let views = "no view vectors, and no positions to make them from (no P or Position layer)";
    assert!(read.warnings.iter().any(|w| w.contains(views)), "{:?}", read.warnings);
    let out = render(
        &path("other.exr"),
        &["--gbuffer-channel", "normal=Nworld", "--gbuffer-channel", "coverage=alpha", "--quiet"],
    );
    assert!(out.status.success(), "{}", common::cli::stderr(&out));
    assert_bad_input(
        &render(&path("other.exr"), &["--gbuffer-channel", "normals=Nworld"]),
        &["unknown g-buffer role 'normals'", "did you mean 'normal'?"],
    );
}

#[test]
fn stacks_by_name_resolve_and_lint_reports_two_stacks_claiming_one_object() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = scene();
    let (groups, attributes) = arnold_channels(&s);
    write_layers(&d.join("aovs.exr"), vec![layer(None, attributes, groups.into_iter().flat_map(|(_, c)| c).collect())]);
    let gbuffer = d.join("aovs.exr").to_string_lossy().into_owned();
    let look = d.join("look.toml");
    std::fs::write(&look, "[[object]]\nname = \"moon\"\n[[object.layer]]\npreset = \"gold\"\n\n[[object]]\nid = 2\n[[object.layer]]\npreset = \"chrome\"\n").unwrap();
    let look = look.to_string_lossy().into_owned();
    let lint = lookdev(&["lint", &look, "--gbuffer", &gbuffer]);
    let stdout = String::from_utf8_lossy(&lint.stdout);
    assert_eq!(lint.status.code(), Some(1), "{stdout}{}", common::cli::stderr(&lint));
    assert!(
        stdout.contains("look.toml:6: this stack claims object 2 'moon', which the stack at line 1 claims too"),
        "{stdout}"
    );

    // Rendered, the named stack shades the moon: gold, not chrome (the later claim is warned of).
    let out = d.join("x.exr").to_string_lossy().into_owned();
    let render = lookdev(&["render", "--gbuffer", &gbuffer, "--look", &look, "--out", &out, "--spp", "4", "--quiet"]);
    assert!(render.status.success(), "{}", common::cli::stderr(&render));
    assert!(common::cli::stderr(&render).contains("claims object 2 'moon'"));
    let image = read_all_flat_layers_from_file(&out).unwrap();
    let channel = |name: &str| {
        image.layer_data[0]
            .channel_data
            .list
            .iter()
            .find(|c| c.name.to_string() == name)
            .unwrap()
            .sample_data
            .values_as_f32()
            .collect::<Vec<f32>>()
    };
    let (r, b) = (channel("R"), channel("B"));
    let moon: Vec<usize> = (0..WIDTH * HEIGHT).filter(|&p| s.object[p] == 2).collect();
    let warm = moon.iter().filter(|&&p| r[p] > b[p] * 1.3).count();
    assert!(warm * 10 > moon.len() * 9, "the moon is gold at {warm} of {} pixels", moon.len());
}

/// Blender names a copied view layer `ViewLayer.002`, and its Cryptomatte
/// `ViewLayer.002.CryptoObject`: reading `ViewLayer` takes `ViewLayer.CryptoObject` alone,
/// whichever comes first in the file.
#[test]
fn a_view_layer_reads_its_own_cryptomatte_and_not_a_copys() {
    let dir = tempfile::tempdir().unwrap();
    let s = scene();
    let mut attributes = LayerAttributes::default();
    let copies = ["ball.copy", "moon.copy"];
    manifest_attributes(&mut attributes, "ViewLayer.CryptoObject", &OBJECTS);
    manifest_attributes(&mut attributes, "ViewLayer.002.CryptoObject", &copies);
    let mut channels = Vec::new();
    for (layer, names) in [("ViewLayer", OBJECTS), ("ViewLayer.002", copies)] {
        channels.extend(vector(&format!("{layer}.Normal"), ["X", "Y", "Z"], &s.normal));
        let object = |p: usize| (s.object[p] > 0).then(|| names[s.object[p] - 1]);
        channels.extend(crypto_rank(&format!("{layer}.CryptoObject"), object));
    }
    let path = dir.path().join("copied.exr");
    write_layers(&path, vec![layer(None, attributes, channels)]);
    for (layer, names) in [("ViewLayer", OBJECTS), ("ViewLayer.002", copies)] {
        let options =
            SourceOptions { layer: Some(layer.into()), up: Some(lookdev::gbuffer::Up::Y), ..Default::default() };
        let read = GBuffer::read_with(&path, &options).unwrap();
        let got: Vec<&str> = read.gbuffer.object_names.values().map(String::as_str).collect();
        assert_eq!(got, names, "{layer}");
        assert_eq!(
            read.gbuffer.coverage.iter().filter(|&&a| a == 1.0).count(),
            s.object.iter().filter(|&&o| o > 0).count()
        );
    }
}

/// A manifest may name far more entries than the image shows: 100,000 names over a small
/// image are read in memory that follows the pixels, not the manifest (each entry once took a
/// whole matte: 6.5 GB at 128×128).
#[test]
fn a_huge_cryptomatte_manifest_costs_what_its_pixels_use() {
    let dir = tempfile::tempdir().unwrap();
    let s = scene();
    let names: Vec<String> = (0..100_000).map(|i| format!("object{i}")).collect();
    let mut listed: Vec<&str> = names.iter().map(String::as_str).collect();
    // The two objects the pixels show are the last in the manifest.
    listed.extend(OBJECTS);
    let mut attributes = LayerAttributes::default();
    manifest_attributes(&mut attributes, "ViewLayer.CryptoObject", &listed);
    manifest_attributes(&mut attributes, "ViewLayer.CryptoMaterial", &listed);
    let mut channels = vector("ViewLayer.Normal", ["X", "Y", "Z"], &s.normal);
    let object = |p: usize| (s.object[p] > 0).then(|| OBJECTS[s.object[p] - 1]);
    channels.extend(crypto_rank("ViewLayer.CryptoObject", object));
    channels.extend(crypto_rank("ViewLayer.CryptoMaterial", object));
    write_layers(&dir.path().join("manifest.exr"), vec![layer(None, attributes, channels)]);
    let args =
        ["render", "--gbuffer", "manifest.exr", "--up", "y", "--spp", "1", "--out", "x.exr", "--aov", "objectId"];
    let run = common::cli::lookdev_measured(dir.path(), &args, 120.0, Some(2048));
    assert!(run.output.status.success(), "{}", common::cli::stderr(&run.output));
    // Two mattes of 48×36 pixels, not 100,002 of each layer; the rest is the renderer's own.
    // Measured: 159 MiB; 817 MiB with a matte per manifest entry.
    assert!(run.peak_mib < 400.0, "peak {:.0} MiB", run.peak_mib);
    let read = GBuffer::read_with(
        &dir.path().join("manifest.exr"),
        &SourceOptions { up: Some(lookdev::gbuffer::Up::Y), ..Default::default() },
    )
    .unwrap();
    assert_eq!(read.gbuffer.masks.len(), 2, "{:?}", read.gbuffer.masks.keys().collect::<Vec<_>>());
    let ids: std::collections::BTreeSet<u32> = read.gbuffer.object_id.iter().copied().collect();
    assert_eq!(ids, [0, 100_001, 100_002].into_iter().collect());
}
