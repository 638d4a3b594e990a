//! The `masks` and `maps` AOVs: `render --aov masks --aov maps` writes every g-buffer mask as
//! `mask_<name>.Y` and every map as `map_<name>.R/G/B` or `.Y`, the values as read; the group
//! `inputs` asks for both, and `--aov-display` refuses them (they are several layers).

mod common;

use common::cli::{assert_bad_input, assert_success, lookdev};
use lookdev::gbuffer::GBuffer;
use lookdev::render::aov::Aov;
use std::collections::BTreeMap;
use std::path::Path;

/// Every channel of an EXR's first layer, by name.
fn channels(path: &Path) -> BTreeMap<String, Vec<f32>> {
    let image = exr::prelude::read_all_flat_layers_from_file(path).unwrap();
    image.layer_data[0]
        .channel_data
        .list
        .iter()
        .map(|c| (c.name.to_string(), c.sample_data.values_as_f32().collect()))
        .collect()
}

#[test]
fn masks_and_maps_are_written_as_read() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let mut gbuffer = GBuffer::shaderball(48, 48);
    let n = gbuffer.pixel_count();
    gbuffer.maps.insert("tex.R".into(), (0..n).map(|i| (i % 48) as f32 / 48.0).collect());
    gbuffer.maps.insert("tex.G".into(), (0..n).map(|i| (i / 48) as f32 / 48.0).collect());
    gbuffer.maps.insert("tex.B".into(), vec![0.25; n]);
    gbuffer.maps.insert("rough".into(), gbuffer.masks["grunge"].clone());
    gbuffer.write(Path::new(&path("g.exr"))).unwrap();
    let read = GBuffer::read(Path::new(&path("g.exr"))).unwrap();

    let out = path("inputs.exr");
    let args = ["render", "--gbuffer", &path("g.exr"), "--spp", "1", "--quiet", "--aov", "inputs", "--out", &out];
    assert_success(&lookdev(&args));
    let written = channels(Path::new(&out));
    assert!(!read.masks.is_empty());
    for (name, values) in &read.masks {
        assert_eq!(written.get(&format!("mask_{name}.Y")), Some(values), "mask {name}");
    }
    for (c, channel) in ["R", "G", "B"].iter().enumerate() {
        let key = ["tex.R", "tex.G", "tex.B"][c];
        assert_eq!(written.get(&format!("map_tex.{channel}")), Some(&read.maps[key]), "map tex.{channel}");
    }
    assert_eq!(written.get("map_rough.Y"), Some(&read.maps["rough"]));
    let extra: Vec<&String> = written
        .keys()
        .filter(|k| !["R", "G", "B", "A"].contains(&k.as_str()))
        .filter(|k| !k.starts_with("ma"))
        .collect();
    assert!(extra.is_empty(), "only masks and maps beside the beauty: {extra:?}");

    assert_eq!(Aov::parse("inputs").unwrap(), [Aov::Masks, Aov::Maps]);
    assert!(Aov::all().contains(&Aov::Masks) && Aov::all().contains(&Aov::Maps), "part of `all`");
    let png = path("masks.png");
    let output =
        lookdev(&["render", "--gbuffer", &path("g.exr"), "--spp", "1", "--aov-display", "masks", "--out", &png]);
    assert_bad_input(&output, &["--aov-display masks: name one AOV, not a group"]);
}
