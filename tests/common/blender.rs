//! Running Blender (Debian's `blender`, which CI installs) and reading what it writes.

use super::cli::stderr;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Blender, if installed; without it, the caller's tests say so and pass, except in CI (`CI`
/// set), where that fails.
pub fn blender() -> Option<PathBuf> {
    match Command::new("blender").arg("--version").output() {
        Ok(output) if output.status.success() => Some(PathBuf::from("blender")),
        _ => {
            assert!(
                std::env::var_os("CI").is_none(),
                "Blender is needed for these tests in CI (apt-get install blender)"
            );
            eprintln!("Blender is not installed (apt-get install blender): test skipped");
            None
        }
    }
}

/// Runs Blender in the background on `args`; any Python error fails the test.
pub fn run_blender(blender: &Path, args: &[&str]) {
    // Without --python-exit-code, Blender exits 0 whatever the script raised.
    let output = Command::new(blender).args(["-b", "--python-exit-code", "2"]).args(args).output().unwrap();
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success() && !text.contains("Error:"),
        "blender {}: {text}{}",
        args.join(" "),
        stderr(&output)
    );
}

/// Every channel of an EXR's first part as floats, with its text attributes.
pub fn read_channels(path: &str) -> (BTreeMap<String, Vec<f32>>, BTreeMap<String, String>) {
    use exr::prelude::*;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .unwrap();
    let channels = image
        .layer_data
        .channel_data
        .list
        .iter()
        .map(|c| (c.name.to_string(), c.sample_data.values_as_f32().collect()))
        .collect();
    let text = image
        .attributes
        .other
        .iter()
        .chain(image.layer_data.attributes.other.iter())
        .filter_map(|(k, v)| match v {
            AttributeValue::Text(t) => Some((k.to_string(), t.to_string())),
            _ => None,
        })
        .collect();
    (channels, text)
}

/// A Cryptomatte layer decoded from the specification: per manifest name, per pixel, its
/// coverage (rank pairs whose id is the name's hash, stored as float bits with the exponent
/// kept in 1..=254).
pub fn cryptomatte(
    channels: &BTreeMap<String, Vec<f32>>,
    text: &BTreeMap<String, String>,
    layer: &str,
    pixels: usize,
) -> Vec<(String, Vec<f32>)> {
    let key = text
        .iter()
        .find(|(k, v)| k.ends_with("/name") && *v == layer)
        .map(|(k, _)| k.trim_end_matches("/name").to_string())
        .unwrap();
    let manifest: serde_json::Map<String, serde_json::Value> =
        serde_json::from_str(&text[&format!("{key}/manifest")]).unwrap();
    manifest
        .iter()
        .map(|(name, hex)| {
            let hash = u32::from_str_radix(hex.as_str().unwrap(), 16).unwrap();
            let exponent = ((hash >> 23) & 0xff).clamp(1, 254);
            let id = (hash & 0x807f_ffff) | (exponent << 23);
            let mut coverage = vec![0.0f32; pixels];
            for rank in 0.. {
                let channel = |c: &str| channels.get(&format!("{layer}{rank:02}.{c}"));
                let (Some(r), Some(g), Some(b), Some(a)) = (channel("r"), channel("g"), channel("b"), channel("a"))
                else {
                    break;
                };
                for p in 0..pixels {
                    for (ids, covs) in [(r, g), (b, a)] {
                        if ids[p].to_bits() == id {
                            coverage[p] += covs[p];
                        }
                    }
                }
            }
            (name.clone(), coverage)
        })
        .collect()
}

/// Mean RGB of `image` over `pixels`.
pub fn mean(image: &BTreeMap<String, Vec<f32>>, prefix: &str, pixels: &[usize]) -> [f64; 3] {
    let mut sum = [0.0f64; 3];
    for (k, c) in ["R", "G", "B"].iter().enumerate() {
        let values = &image[&format!("{prefix}{c}")];
        sum[k] = pixels.iter().map(|&p| values[p] as f64).sum::<f64>() / pixels.len() as f64;
    }
    sum
}

/// A test scene's Blender script: `body` (its objects and camera) between the common start,
/// `tests/data/blender/start.py` (the arguments mode, output and environment; an empty Cycles
/// scene at 160×120 on the CPU; the materials `red` and `gold`, and `material(name, colour,
/// metallic, roughness)` for more) and the common end, `end.py`: the world lit by the
/// environment, and the modes `blend` (save the scene), `plain` (Blender's passes: Normal,
/// Position, Depth, Cryptomatte), `beauty` (Cycles' direct light, no bounces, 256 samples,
/// printing the render's seconds) and `catcher:NAME` (the same with the object NAME a shadow
/// catcher, and Cycles' Shadow Catcher pass, as multilayer EXR).
pub fn scene_script(body: &str) -> String {
    format!("{SCENE_START}{body}{SCENE_END}")
}

const SCENE_START: &str = include_str!("../data/blender/start.py");

const SCENE_END: &str = include_str!("../data/blender/end.py");

/// The scenes' materials as lookdev sets them: `red` and `gold` of [`scene_script`], and a grey.
pub const RED: &str = "base_color = [0.8, 0.1, 0.05]\nmetallic = 0.0\nroughness = 0.4\nspecular = 0.5\n";
pub const GOLD: &str = "base_color = [1.0, 0.766, 0.336]\nmetallic = 1.0\nroughness = 0.3\nspecular = 0.5\n";
pub const GREY: &str = "base_color = [0.5, 0.5, 0.5]\nmetallic = 0.0\nroughness = 0.6\nspecular = 0.5\n";

/// A look giving each named object one layer of its material.
pub fn look_by_names(objects: &[(&str, &str)]) -> String {
    objects
        .iter()
        .map(|(name, material)| {
            format!("[[object]]\nname = \"{name}\"\n[[object.layer]]\n[object.layer.set]\n{material}\n")
        })
        .collect()
}
