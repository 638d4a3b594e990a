//! What an EXR records of how it was made (docs/formats.md#output): the look as rendered, with
//! every setting the flags changed written into it, and the few flags no look holds. Rendering
//! that look with those flags gives the same image, bit for bit, on the same driver.

use crate::environment::{Backdrop, EnvironmentRef};
use crate::material::look::{EnvironmentSettings, GBufferSettings, RenderSettings};
use crate::material::{Look, Param};
use crate::render::settings::Settings;
use std::path::{Path, PathBuf};

/// What a render reads beyond its look and its settings: the g-buffer, as a `[gbuffer]` table
/// (the built-in scene by its size),
/// the AOVs asked for, and the flags no look holds (`--supersample`,
/// `--no-visibility`, `--env-clamp`, `--env-any-aspect`, `--sampling`).
#[derive(Clone, Debug, Default)]
pub struct Recorded {
    pub gbuffer: GBufferSettings,
    pub aovs: Option<Vec<String>>,
    pub flags: Vec<String>,
}

/// `path` made absolute, so that the look reads it from wherever it is saved.
pub fn absolute(path: &Path) -> PathBuf {
    std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf())
}

/// `look` as rendered with `settings`: the environment, render settings and model it was
/// rendered with, the g-buffer it was read from, and every layer's parameters written out in
/// full, its preset file (if it names one by path) by its absolute path.
pub fn rendered_look(look: &Look, settings: &Settings, recorded: &Recorded) -> Look {
    let folder = look.file.as_deref().and_then(Path::parent).unwrap_or(Path::new(""));
    let mut look = look.clone();
    let source = match EnvironmentRef::or_default(settings.environment.as_ref()) {
        EnvironmentRef::File(path) => EnvironmentRef::File(absolute(&path)),
        builtin => builtin,
    };
    look.environment = EnvironmentSettings {
        source: Some(source),
        rotation: Some(settings.lighting.rotation_degrees),
        intensity: Some(settings.lighting.intensity),
        background: Some(settings.lighting.background),
        backdrop: match &settings.backdrop {
            Backdrop::Environment => None,
            Backdrop::Other(EnvironmentRef::File(path)) => Some(Backdrop::Other(EnvironmentRef::File(absolute(path)))),
            backdrop => Some(backdrop.clone()),
        },
    };
    look.render = RenderSettings {
        spp: Some(settings.spp),
        seed: Some(settings.seed),
        exposure: Some(settings.exposure),
        tonemap: Some(settings.tonemap),
        aovs: recorded.aovs.clone(),
        noise_threshold: settings.noise.map(|n| n.threshold),
        min_spp: settings.noise.map(|n| n.min_samples),
    };
    look.model = Some(settings.model);
    look.gbuffer = recorded.gbuffer.clone();
    for layer in look.objects.iter_mut().flat_map(|o| &mut o.layers) {
        layer.overrides = Param::ALL.to_vec();
        // A file it names, or a preset beside the look found by name, by its absolute path.
        if let Some(preset) = layer.preset.as_mut() {
            let file = match crate::material::library::looks_like_path(preset) {
                true => Some(folder.join(&*preset)),
                false => Some(folder.join(format!("{preset}.toml"))).filter(|f| f.is_file()),
            };
            if let Some(file) = file {
                *preset = absolute(&file).to_string_lossy().into_owned();
            }
        }
    }
    look.file = None;
    look
}
