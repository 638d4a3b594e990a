//! Looks: what to render. A look file sets the environment, the BRDF model, the render settings,
//! the g-buffer and one layer stack per object; its keys, the blending rule, map bindings and
//! how preset names resolve are specified in docs/formats.md#looks. Every error is one line,
//! `FILE:LINE: problem`, naming the key.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::library::Library;
use super::mask::MaskAdjust;
use super::params::{Param, Params, Value};
use super::toml_input::{self as input, Field, Source};
use crate::environment::backdrop::{self, Backdrop};
use crate::environment::EnvironmentRef;
use crate::gbuffer::source::{Channels, SourceOptions, Up};
use crate::shading::model::{Model, ModelValue};
use crate::shading::tonemap::{Tonemap, MAX_EXPOSURE};

/// What to render: environment, render settings and the layer stacks.
#[derive(Clone, Debug, PartialEq)]
pub struct Look {
    /// The file it was read from; `None` for the built-in look.
    pub file: Option<PathBuf>,
    /// From `[environment]`.
    pub environment: EnvironmentSettings,
    /// From `[render]`.
    pub render: RenderSettings,
    /// From `[model]`: the BRDF model, `None` when the look has no such table (the default).
    pub model: Option<Model>,
    /// From `[gbuffer]`: the g-buffer and how to read it; flags override it.
    pub gbuffer: GBufferSettings,
    /// From `[[object]]`, in file order.
    pub objects: Vec<ObjectStack>,
    /// Where some keys were written, for the errors found only once the look is used.
    pub lines: KeyLines,
}

/// The lines on which a look wrote the keys whose problems show only once it is used
/// (`"render.min_spp"`, `"environment.file"`). Not part of what the look means: any two compare
/// equal, as a layer's `line` does not count in its equality.
#[derive(Clone, Debug, Default)]
pub struct KeyLines(BTreeMap<&'static str, usize>);

impl PartialEq for KeyLines {
    fn eq(&self, _: &KeyLines) -> bool {
        true
    }
}

/// `[gbuffer]`: the g-buffer file (resolved against the look file's folder) and how to read
/// it (docs/formats.md#production-renders).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GBufferSettings {
    pub file: Option<PathBuf>,
    pub source: SourceOptions,
    /// `size = [W, H]`: the built-in shader ball's size, where no file is named.
    pub size: Option<(u32, u32)>,
}

/// `[environment]`. `None` means "not set here": the caller's default applies.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EnvironmentSettings {
    /// `builtin = "NAME"`, or `file`: the environment image, already resolved against the look
    /// file's folder.
    pub source: Option<EnvironmentRef>,
    /// Degrees about +Y.
    pub rotation: Option<f32>,
    /// Radiance scale, finite and ≥ 0.
    pub intensity: Option<f32>,
    /// Whether background pixels show a background (`background = false`: transparent).
    pub background: Option<bool>,
    /// What a shown background is (`background = "blur"` with `background_blur`, `[r, g, b]`,
    /// or `background_environment`); None: the lighting environment. Never set beside
    /// `background = false`.
    pub backdrop: Option<Backdrop>,
}

/// `[render]`. `None` means "not set here": command-line flags and defaults apply.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderSettings {
    /// Samples per pixel, ≥ 1.
    pub spp: Option<u32>,
    pub seed: Option<u32>,
    /// Exposure in stops.
    pub exposure: Option<f32>,
    pub tonemap: Option<Tonemap>,
    /// The AOVs renders write beside the beauty (docs/formats.md#aovs), as written.
    pub aovs: Option<Vec<String>>,
    /// Adaptive sampling's threshold (docs/shading.md#adaptive-sampling): `spp` is then the
    /// most a pixel takes. Within (0, 1000).
    pub noise_threshold: Option<f32>,
    /// The samples every pixel takes before it may stop, ≥ 2; only with `noise_threshold`.
    pub min_spp: Option<u32>,
}

/// One `[[object]]`: the layer stack for an object id, or the default stack.
#[derive(Clone, Debug)]
pub struct ObjectStack {
    /// The object's id: as written, or resolved from `name` once the g-buffer is read. `None`
    /// with no `name` is the default stack, used by every object without a stack of its own.
    pub id: Option<u32>,
    /// The object's name, as the g-buffer names it (`name = "Sphere.001"`), instead of `id`.
    pub name: Option<String>,
    /// Bottom layer first. Never empty.
    pub layers: Vec<Layer>,
    /// Whether the object catches shadows (`shadow_catcher = true`): its pixels show what is
    /// behind them darkened by the share of light the visibility blocks, not its own shading
    /// (docs/formats.md#shadow-catchers).
    pub shadow_catcher: bool,
    /// The 1-based line of this `[[object]]` in the file, for later error messages.
    pub line: usize,
}

impl PartialEq for ObjectStack {
    fn eq(&self, other: &ObjectStack) -> bool {
        self.id == other.id
            && self.name == other.name
            && self.layers == other.layers
            && self.shadow_catcher == other.shadow_catcher
    }
}

impl ObjectStack {
    /// A stack for an object id (`None`: the default stack).
    pub fn new(id: Option<u32>, layers: Vec<Layer>) -> ObjectStack {
        ObjectStack { id, name: None, layers, shadow_catcher: false, line: 0 }
    }

    /// Whether this is the default stack: neither an id nor a name.
    pub fn is_default(&self) -> bool {
        self.id.is_none() && self.name.is_none()
    }

    /// Whether this is the stack of `id`, or, for `None`, the default stack.
    pub fn is_for(&self, id: Option<u32>) -> bool {
        match id {
            Some(_) => self.id == id,
            None => self.is_default(),
        }
    }
}

/// One `[[object.layer]]`: a preset, overrides, and the mask that blends it over the layers
/// below.
#[derive(Clone, Debug)]
pub struct Layer {
    /// The layer's own name (`name`), which the viewer shows instead of the preset's.
    pub name: Option<String>,
    /// The `preset` value as written in the file.
    pub preset: Option<String>,
    /// The preset's values with `[object.layer.set]` applied on top.
    pub params: Params,
    /// Which parameters `[object.layer.set]` set, in [`Param::ALL`] order.
    pub overrides: Vec<Param>,
    /// `[object.layer.map]`: the parameters bound to a g-buffer map, each with the map as
    /// written (`name`, or `name.R`/`.G`/`.B` for one channel of a colour map). Checked against
    /// the g-buffer when the stacks are packed.
    pub maps: BTreeMap<Param, String>,
    /// The g-buffer channel `mask.<name>`; `None` is 1 everywhere.
    pub mask: Option<String>,
    /// The mask's blur and levels (`mask_blur`, `mask_black`, `mask_white`, `mask_gamma`),
    /// applied before `invert` and `opacity`.
    pub mask_adjust: MaskAdjust,
    pub invert: bool,
    /// In [0, 1].
    pub opacity: f32,
    /// `enabled = false` keeps the layer in the look but leaves it out of rendering, so an
    /// artist can compare with and without it.
    pub enabled: bool,
    /// The 1-based line of this `[[object.layer]]` in the file, for later error messages
    /// (such as a mask the g-buffer lacks).
    pub line: usize,
    /// Which layer this is, while the program runs: kept by clones (an undo step's copy of a
    /// stack holds the same layers), new for every layer made or duplicated. Not saved, and not
    /// part of what the layer means.
    pub id: LayerId,
}

/// A layer's identity while the program runs ([`Layer::id`]), so that a selection follows its
/// layer through edits, undo and redo however the stack's order changes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LayerId(u64);

impl LayerId {
    /// An identity no other layer has.
    pub fn new() -> LayerId {
        static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
        LayerId(NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed))
    }
}

impl Default for LayerId {
    fn default() -> LayerId {
        LayerId::new()
    }
}

impl Layer {
    /// A layer of these parameters with no preset, mask or overrides, at full opacity: what fills
    /// a stack on its own.
    pub fn filling(params: Params) -> Layer {
        Layer {
            name: None,
            preset: None,
            params,
            overrides: Vec::new(),
            maps: BTreeMap::new(),
            mask: None,
            mask_adjust: MaskAdjust::default(),
            invert: false,
            opacity: 1.0,
            enabled: true,
            line: 0,
            id: LayerId::new(),
        }
    }
}

/// Layers are equal when they mean the same. `line` records where one was written and `id`
/// which one it is, not what it means, so both are left out: that is what lets
/// `parse(to_toml(look)) == look` hold.
impl PartialEq for Layer {
    fn eq(&self, other: &Layer) -> bool {
        self.name == other.name
            && self.preset == other.preset
            && self.params == other.params
            && self.overrides == other.overrides
            && self.maps == other.maps
            && self.mask == other.mask
            && self.mask_adjust == other.mask_adjust
            && self.invert == other.invert
            && self.opacity == other.opacity
            && self.enabled == other.enabled
    }
}

/// The built-in look, shown when `lookdev render` is given none.
const DEFAULT_LOOK: &str = include_str!("default_look.toml");

impl Look {
    /// The built-in look's file, as written (comments included): what `lookdev look default`
    /// writes out.
    pub fn builtin_default_text() -> &'static str {
        DEFAULT_LOOK
    }

    /// The look with layer `solo` alone in its stack (every other layer of that stack hidden,
    /// so it fills its objects), as Painter's solo shows one layer; `None` when no layer of the
    /// look is `solo`. Other stacks are left alone.
    pub fn soloed(&self, solo: LayerId) -> Option<Look> {
        let stack = self.objects.iter().position(|o| o.layers.iter().any(|l| l.id == solo))?;
        let mut look = self.clone();
        for layer in &mut look.objects[stack].layers {
            layer.enabled = layer.id == solo;
        }
        Some(look)
    }

    /// Reads and parses a look file. A missing file is an error naming it.
    pub fn load(path: &Path) -> crate::Result<Look> {
        Look::parse(&input::read_text(path)?, path)
    }

    /// Parses a look file's text. `file` names it in errors, and its folder is where relative
    /// paths and preset files are looked for.
    pub fn parse(text: &str, file: &Path) -> crate::Result<Look> {
        let mut look = parse_with(Source { file, text }, &Library::for_look(file))?;
        look.file = Some(file.to_path_buf());
        Ok(look)
    }

    /// The built-in look: the shader ball (object 1, "ball") in blue rubber with gold through
    /// `stripes` and grime through `grunge`; the pedestal (object 2) in white ceramic turning
    /// to copper through `gradient`; red plastic for any other object; 256 samples per pixel.
    /// Its presets come from the built-ins only, whatever the current directory holds.
    pub fn builtin_default() -> Look {
        let src = Source { file: Path::new("<built-in default look>"), text: DEFAULT_LOOK };
        // The embedded text is checked by the test suite; failing here is a build defect.
        parse_with(src, &Library::builtin_only()).expect("the built-in default look parses (tested)")
    }

    /// Where `key` (`"render.min_spp"`) is written, for a message: `FILE:LINE`, or the file, or
    /// "the look" for a look that has no file.
    pub fn place(&self, key: &str) -> String {
        match (&self.file, self.lines.0.get(key)) {
            (Some(file), Some(line)) => format!("{}:{line}", file.display()),
            (Some(file), None) => file.display().to_string(),
            (None, _) => "the look".to_string(),
        }
    }

    /// The look used for a user g-buffer rendered without a look: every object in the default
    /// material (docs/formats.md#presets; defaults: grey 0.8 dielectric, roughness 0.5), default settings.
    pub fn default_material() -> Look {
        let mut look = Look {
            file: None,
            environment: EnvironmentSettings::default(),
            render: RenderSettings::default(),
            model: None,
            gbuffer: GBufferSettings::default(),
            objects: Vec::new(),
            lines: KeyLines::default(),
        };
        look.ensure_default_stack();
        look
    }

    /// Gives a look without a default stack one of a single default-material layer, so every
    /// object has a stack that `--set` can reach. Returns whether it added one.
    pub fn ensure_default_stack(&mut self) -> bool {
        if self.objects.iter().any(ObjectStack::is_default) {
            return false;
        }
        self.objects.push(ObjectStack::new(None, vec![Layer::filling(Params::default())]));
        true
    }

    /// The stack for an object id: its own, else the default stack, else `None`.
    pub fn stack_for(&self, id: u32) -> Option<&ObjectStack> {
        let own = self.objects.iter().find(|o| o.id == Some(id));
        own.or_else(|| self.objects.iter().find(|o| o.is_default()))
    }

    /// Gives each stack that names its object (`name = "..."`) that object's id, from the
    /// g-buffer's object names. An unknown name is an error at the stack's line, listing the
    /// names the g-buffer has. Returns a warning for each stack that claims an object an earlier
    /// one claims (the earlier one is used).
    pub fn resolve_object_names(
        &mut self,
        names: &BTreeMap<u32, String>,
        gbuffer: &Path,
    ) -> crate::Result<Vec<String>> {
        let file = self.file.clone().unwrap_or_else(|| PathBuf::from("<look>"));
        for stack in self.objects.iter_mut() {
            let Some(name) = &stack.name else { continue };
            let id = names.iter().find(|(_, n)| *n == name).map(|(&id, _)| id).ok_or_else(|| {
                let listed: Vec<String> = names.iter().map(|(id, n)| format!("{n} ({id})")).collect();
                let has = if listed.is_empty() { "no object names".to_string() } else { listed.join(", ") };
                crate::Error::input_file(
                    format!("{}:{}", file.display(), stack.line),
                    format!("no object named '{name}' in {} (it has {has})", gbuffer.display()),
                )
            })?;
            stack.id = Some(id);
        }
        Ok(self.claim_warnings(names))
    }

    /// A warning for each stack that claims an object an earlier stack claims, by id or name.
    pub fn claim_warnings(&self, names: &BTreeMap<u32, String>) -> Vec<String> {
        let file = self.file.as_deref().unwrap_or(Path::new("<look>")).display().to_string();
        let mut warnings = Vec::new();
        for (i, stack) in self.objects.iter().enumerate() {
            let Some(id) = stack.id else { continue };
            if let Some(first) = self.objects[..i].iter().find(|o| o.id == Some(id)) {
                let name = names.get(&id).map(|n| format!(" '{n}'")).unwrap_or_default();
                warnings.push(format!(
                    "{file}:{}: this stack claims object {id}{name}, which the stack at line {} claims too; that one is used",
                    stack.line, first.line
                ));
            }
        }
        warnings
    }

    /// Applies `--set NAME=VALUE` to every layer of every object, after the look's own values,
    /// and records it as an override so that [`Look::to_toml`] keeps it. A value of the wrong
    /// kind or out of range changes nothing and is the error.
    pub fn set_everywhere(&mut self, param: Param, value: Value) -> Result<(), String> {
        super::params::check(param, value)?;
        for layer in self.objects.iter_mut().flat_map(|o| o.layers.iter_mut()) {
            layer.params.set(param, value)?;
            if !layer.overrides.contains(&param) {
                layer.overrides.push(param);
                layer.overrides.sort();
            }
        }
        Ok(())
    }

    /// The look in the look format: presets by their written name, overrides by value, the
    /// environment file relative to the look file's folder. Parsing it back (from the same
    /// path) gives an equal look.
    pub fn to_toml(&self) -> String {
        let mut lines = Vec::new();
        self.write_environment(&mut lines);
        self.write_render(&mut lines);
        self.write_gbuffer(&mut lines);
        if let Some(model) = &self.model {
            let body = model.entries().into_iter().map(|(k, v)| format!("{k} = {v}")).collect();
            push_section(&mut lines, "[model]", body);
        }
        for object in &self.objects {
            object.write(&mut lines);
        }
        lines.join("\n")
    }

    fn write_environment(&self, lines: &mut Vec<String>) {
        let env = &self.environment;
        let mut body = Vec::new();
        match &env.source {
            Some(EnvironmentRef::File(file)) => {
                let folder = self.file.as_deref().and_then(Path::parent).unwrap_or(Path::new(""));
                let relative = file.strip_prefix(folder).unwrap_or(file);
                body.push(format!("file = {}", input::quoted(&relative.to_string_lossy())));
            }
            Some(EnvironmentRef::Builtin(name)) => body.push(format!("builtin = {}", input::quoted(name))),
            None => {}
        }
        push_float(&mut body, "rotation", env.rotation);
        push_float(&mut body, "intensity", env.intensity);
        write_background(&mut body, env, self.file.as_deref());
        push_section(lines, "[environment]", body);
    }

    fn write_gbuffer(&self, lines: &mut Vec<String>) {
        let settings = &self.gbuffer;
        let source = &settings.source;
        let mut body = Vec::new();
        if let Some(file) = &settings.file {
            let folder = self.file.as_deref().and_then(Path::parent).unwrap_or(Path::new(""));
            let relative = file.strip_prefix(folder).unwrap_or(file);
            body.push(format!("file = {}", input::quoted(&relative.to_string_lossy())));
        }
        if let Some((width, height)) = settings.size {
            body.push(format!("size = [{width}, {height}]"));
        }
        if let Some(layer) = &source.layer {
            body.push(format!("layer = {}", input::quoted(layer)));
        }
        if let Some(up) = source.up {
            body.push(format!("up = {}", input::quoted(up.name())));
        }
        if let Some(p) = source.camera_position {
            body.push(format!(
                "camera_position = [{}, {}, {}]",
                input::float(p.x),
                input::float(p.y),
                input::float(p.z)
            ));
        }
        if let Some(file) = &source.occluders {
            let folder = self.file.as_deref().and_then(Path::parent).unwrap_or(Path::new(""));
            let relative = file.strip_prefix(folder).unwrap_or(file);
            body.push(format!("occluders = {}", input::quoted(&relative.to_string_lossy())));
        }
        let c = &source.channels;
        for (key, value) in [
            ("normal", &c.normal),
            ("position", &c.position),
            ("view", &c.view),
            ("tangent", &c.tangent),
            ("coverage", &c.coverage),
            ("id", &c.id),
        ] {
            if let Some(value) = value {
                body.push(format!("{key} = {}", input::quoted(value)));
            }
        }
        if !c.masks.is_empty() {
            let masks: Vec<String> = c.masks.iter().map(|m| input::quoted(m)).collect();
            body.push(format!("masks = [{}]", masks.join(", ")));
        }
        push_section(lines, "[gbuffer]", body);
    }

    fn write_render(&self, lines: &mut Vec<String>) {
        let render = &self.render;
        let mut body = Vec::new();
        if let Some(spp) = render.spp {
            body.push(format!("spp = {spp}"));
        }
        if let Some(seed) = render.seed {
            body.push(format!("seed = {seed}"));
        }
        push_float(&mut body, "exposure", render.exposure);
        if let Some(tonemap) = render.tonemap {
            body.push(format!("tonemap = {}", input::quoted(tonemap.name())));
        }
        if let Some(aovs) = &render.aovs {
            let names: Vec<String> = aovs.iter().map(|a| input::quoted(a)).collect();
            body.push(format!("aovs = [{}]", names.join(", ")));
        }
        push_float(&mut body, "noise_threshold", render.noise_threshold);
        if let Some(min_spp) = render.min_spp {
            body.push(format!("min_spp = {min_spp}"));
        }
        push_section(lines, "[render]", body);
    }
}

impl ObjectStack {
    fn write(&self, lines: &mut Vec<String>) {
        lines.push("[[object]]".to_string());
        match (&self.name, self.id) {
            (Some(name), _) => lines.push(format!("name = {}", input::quoted(name))),
            (None, Some(id)) => lines.push(format!("id = {id}")),
            (None, None) => {}
        }
        if self.shadow_catcher {
            lines.push("shadow_catcher = true".to_string());
        }
        for layer in &self.layers {
            layer.write(lines);
        }
        lines.push(String::new());
    }
}

impl Layer {
    fn write(&self, lines: &mut Vec<String>) {
        lines.push("[[object.layer]]".to_string());
        if let Some(name) = &self.name {
            lines.push(format!("name = {}", input::quoted(name)));
        }
        if let Some(preset) = &self.preset {
            lines.push(format!("preset = {}", input::quoted(preset)));
        }
        if let Some(mask) = &self.mask {
            lines.push(format!("mask = {}", input::quoted(mask)));
        }
        let (adjust, identity) = (self.mask_adjust, MaskAdjust::default());
        for (key, value, default) in [
            ("mask_blur", adjust.blur, identity.blur),
            ("mask_black", adjust.black, identity.black),
            ("mask_white", adjust.white, identity.white),
            ("mask_gamma", adjust.gamma, identity.gamma),
        ] {
            if value != default {
                lines.push(format!("{key} = {}", input::float(value)));
            }
        }
        if self.invert {
            lines.push("invert = true".to_string());
        }
        if self.opacity != 1.0 {
            lines.push(format!("opacity = {}", input::float(self.opacity)));
        }
        if !self.enabled {
            lines.push("enabled = false".to_string());
        }
        if !self.overrides.is_empty() {
            lines.push("[object.layer.set]".to_string());
            for &param in &self.overrides {
                lines.push(format!("{param} = {}", input::value(self.params.get(param))));
            }
        }
        if !self.maps.is_empty() {
            lines.push("[object.layer.map]".to_string());
            for (param, map) in &self.maps {
                lines.push(format!("{param} = {}", input::quoted(map)));
            }
        }
    }
}

fn push_float(body: &mut Vec<String>, key: &str, value: Option<f32>) {
    if let Some(x) = value {
        body.push(format!("{key} = {}", input::float(x)));
    }
}

/// Writes a table only when it has something in it.
fn push_section(lines: &mut Vec<String>, header: &str, body: Vec<String>) {
    if !body.is_empty() {
        lines.push(header.to_string());
        lines.extend(body);
        lines.push(String::new());
    }
}

// ---- The file as written: structure only. Values are converted by `parse_with`. ----

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a look table")]
struct LookFile {
    environment: Option<EnvironmentFile>,
    render: Option<RenderFile>,
    /// Keys are checked by `Model::set`, which names the values each takes.
    model: Option<BTreeMap<Field<String>, Field>>,
    gbuffer: Option<GBufferFile>,
    #[serde(default)]
    object: Vec<Field<ObjectFile>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a [gbuffer] table")]
struct GBufferFile {
    file: Option<Field>,
    layer: Option<Field>,
    up: Option<Field>,
    camera_position: Option<Field>,
    occluders: Option<Field>,
    normal: Option<Field>,
    position: Option<Field>,
    view: Option<Field>,
    tangent: Option<Field>,
    coverage: Option<Field>,
    id: Option<Field>,
    masks: Option<Field>,
    size: Option<Field>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "an [environment] table")]
struct EnvironmentFile {
    file: Option<Field>,
    builtin: Option<Field>,
    rotation: Option<Field>,
    intensity: Option<Field>,
    background: Option<Field>,
    background_blur: Option<Field>,
    background_environment: Option<Field>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a [render] table")]
struct RenderFile {
    spp: Option<Field>,
    seed: Option<Field>,
    exposure: Option<Field>,
    tonemap: Option<Field>,
    aovs: Option<Field>,
    noise_threshold: Option<Field>,
    min_spp: Option<Field>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "an [[object]] table")]
struct ObjectFile {
    id: Option<Field>,
    name: Option<Field>,
    shadow_catcher: Option<Field>,
    #[serde(default)]
    layer: Vec<Field<LayerFile>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "an [[object.layer]] table")]
struct LayerFile {
    name: Option<Field>,
    preset: Option<Field>,
    mask: Option<Field>,
    mask_blur: Option<Field>,
    mask_black: Option<Field>,
    mask_white: Option<Field>,
    mask_gamma: Option<Field>,
    invert: Option<Field>,
    opacity: Option<Field>,
    enabled: Option<Field>,
    /// Parameter name to value; names are checked here rather than by serde so that an unknown
    /// one can be reported as a parameter, with the closest name.
    set: Option<BTreeMap<Field<String>, Field>>,
    /// Parameter name to map name, checked like `set`.
    map: Option<BTreeMap<Field<String>, Field>>,
}

fn parse_with(src: Source, library: &Library) -> crate::Result<Look> {
    let raw: LookFile = src.decode()?;
    let folder = src.file.parent().unwrap_or(Path::new(""));
    let mut lines = KeyLines::default();
    let mut note = |key: &'static str, field: Option<&Field>| {
        if let Some(field) = field {
            lines.0.insert(key, src.line(field.span().start));
        }
    };
    note("render.min_spp", raw.render.as_ref().and_then(|r| r.min_spp.as_ref()));
    note("render.noise_threshold", raw.render.as_ref().and_then(|r| r.noise_threshold.as_ref()));
    note("environment.file", raw.environment.as_ref().and_then(|e| e.file.as_ref()));
    note(
        "environment.background_environment",
        raw.environment.as_ref().and_then(|e| e.background_environment.as_ref()),
    );
    let look = Look {
        file: None,
        environment: environment(&src, raw.environment, folder)?,
        render: render(&src, raw.render)?,
        model: model(&src, raw.model.as_ref())?,
        gbuffer: gbuffer(&src, raw.gbuffer, folder)?,
        objects: objects(&src, &raw.object, library)?,
        lines,
    };
    warn_about_bottom_layers(&src, &look);
    Ok(look)
}

fn environment(src: &Source, raw: Option<EnvironmentFile>, folder: &Path) -> crate::Result<EnvironmentSettings> {
    let Some(raw) = raw else {
        return Ok(EnvironmentSettings::default());
    };
    let file = src.read("file", &raw.file, input::text)?.map(|f| EnvironmentRef::File(folder.join(f)));
    let (background, backdrop) = background(src, &raw, folder)?;
    let builtin = src.read("builtin", &raw.builtin, |key, value| {
        EnvironmentRef::builtin(&input::text(key, value)?).map_err(|e| format!("{key}: {e}"))
    })?;
    if let (Some(_), Some(field)) = (&file, &raw.builtin) {
        return Err(src.error(field.span(), "[environment] takes a file or a builtin, not both"));
    }
    Ok(EnvironmentSettings {
        source: file.or(builtin),
        rotation: src.read("rotation", &raw.rotation, input::number)?,
        intensity: src.read("intensity", &raw.intensity, intensity)?,
        background,
        backdrop,
    })
}

/// `background`, with `background_blur` and `background_environment`: whether a background is
/// shown, and what it is where that is not the lighting environment.
fn background(src: &Source, raw: &EnvironmentFile, folder: &Path) -> crate::Result<(Option<bool>, Option<Backdrop>)> {
    let blur = src.read("background_blur", &raw.background_blur, |key, value| {
        let degrees = input::number(key, value)?;
        backdrop::check_blur(degrees).map(|()| degrees).map_err(|e| e.replacen("background_blur", key, 1))
    })?;
    let other = src.read("background_environment", &raw.background_environment, |key, value| {
        let text = input::text(key, value)?;
        match text.strip_prefix("builtin:") {
            Some(name) => EnvironmentRef::builtin(name).map_err(|e| format!("{key}: {e}")),
            None => Ok(EnvironmentRef::File(folder.join(text))),
        }
    })?;
    let (shown, backdrop) = match src.read("background", &raw.background, background_value)? {
        None => (None, None),
        Some((shown, backdrop)) => (Some(shown), backdrop),
    };
    let backdrop = match (backdrop, blur) {
        (Some(Backdrop::Blurred(_)), Some(degrees)) => Some(Backdrop::Blurred(degrees)),
        (backdrop, None) => backdrop,
        (_, Some(_)) => {
            let field = raw.background_blur.as_ref().expect("read above");
            return Err(src.error(field.span(), "[environment] background_blur needs background = \"blur\""));
        }
    };
    match (other, &backdrop, shown) {
        (None, _, _) => Ok((shown, backdrop)),
        (Some(other), None, None | Some(true)) => Ok((shown, Some(Backdrop::Other(other)))),
        (Some(_), _, _) => {
            let field = raw.background_environment.as_ref().expect("read above");
            Err(src.error(
                field.span(),
                "[environment] background_environment takes the place of the lighting environment behind the \
                 objects: it needs background = true or no background, not another background",
            ))
        }
    }
}

/// A `background` value: true or false, "blur" (at the default blur until `background_blur`
/// says), or a linear colour [r, g, b].
fn background_value(key: &str, value: &toml::Value) -> Result<(bool, Option<Backdrop>), String> {
    match value {
        toml::Value::Boolean(shown) => Ok((*shown, None)),
        toml::Value::String(s) if s == "blur" => Ok((true, Some(Backdrop::Blurred(backdrop::DEFAULT_BLUR_DEGREES)))),
        toml::Value::Array(_) => {
            let rgb = input::color(key, value)?;
            backdrop::check_colour(rgb).map_err(|e| format!("{key}: {e}"))?;
            Ok((true, Some(Backdrop::Colour(rgb))))
        }
        _ => Err(format!(
            "{key} must be true, false, \"blur\" or a linear colour [r, g, b], not {}",
            input::describe(value)
        )),
    }
}

/// Writes `background` and the keys beside it as [`background`] reads them. A backdrop is left
/// out with `background = false`, which shows none.
fn write_background(body: &mut Vec<String>, env: &EnvironmentSettings, look_file: Option<&Path>) {
    let backdrop = env.backdrop.as_ref().filter(|_| env.background != Some(false));
    match backdrop {
        Some(Backdrop::Blurred(degrees)) => {
            body.push("background = \"blur\"".to_string());
            push_float(body, "background_blur", Some(*degrees));
        }
        Some(Backdrop::Colour(rgb)) => body.push(format!("background = {}", input::value(Value::Color(*rgb)))),
        _ => {
            if let Some(shown) = env.background {
                body.push(format!("background = {shown}"));
            }
        }
    }
    if let Some(Backdrop::Other(other)) = backdrop {
        let text = match other {
            EnvironmentRef::File(file) => {
                let folder = look_file.and_then(Path::parent).unwrap_or(Path::new(""));
                file.strip_prefix(folder).unwrap_or(file).to_string_lossy().into_owned()
            }
            builtin => builtin.to_string(),
        };
        body.push(format!("background_environment = {}", input::quoted(&text)));
    }
}

fn gbuffer(src: &Source, raw: Option<GBufferFile>, folder: &Path) -> crate::Result<GBufferSettings> {
    let Some(raw) = raw else {
        return Ok(GBufferSettings::default());
    };
    let text = |key: &str, field: &Option<Field>| src.read(key, field, input::text);
    let channels = Channels {
        normal: text("normal", &raw.normal)?,
        position: text("position", &raw.position)?,
        view: text("view", &raw.view)?,
        tangent: text("tangent", &raw.tangent)?,
        coverage: text("coverage", &raw.coverage)?,
        id: text("id", &raw.id)?,
        masks: src.read("masks", &raw.masks, input::text_list)?.unwrap_or_default(),
    };
    let camera_position = src.read("camera_position", &raw.camera_position, point)?;
    let file = text("file", &raw.file)?.map(|f| folder.join(f));
    let size = src.read("size", &raw.size, builtin_size)?;
    if let (Some(_), Some(_)) = (&file, size) {
        src.read("size", &raw.size, |_, _| -> Result<(), String> {
            Err("size = [W, H] sizes the built-in shader ball; a g-buffer file has its own size".into())
        })?;
    }
    Ok(GBufferSettings {
        file,
        size,
        source: SourceOptions {
            layer: text("layer", &raw.layer)?,
            up: src.read("up", &raw.up, |key, value| Up::parse(&input::text(key, value)?))?,
            camera_position,
            channels,
            occluders: text("occluders", &raw.occluders)?.map(|f| folder.join(f)),
            no_visibility: false,
        },
    })
}

/// `[W, H]`, each side 1 to [`crate::gbuffer::MAX_BUILTIN_SIDE`] pixels.
fn builtin_size(key: &str, value: &toml::Value) -> Result<(u32, u32), String> {
    let most = crate::gbuffer::MAX_BUILTIN_SIDE;
    let side = |item: &toml::Value| item.as_integer().filter(|n| (1..=most as i64).contains(n)).map(|n| n as u32);
    match value {
        toml::Value::Array(items) if items.len() == 2 => match (side(&items[0]), side(&items[1])) {
            (Some(width), Some(height)) => Ok((width, height)),
            _ => Err(format!("{key} = {value}: each side must be a whole number of pixels, 1 to {most}")),
        },
        _ => Err(format!("{key} must be [width, height] in pixels, not {}", input::describe(value))),
    }
}

/// Three finite numbers `[x, y, z]`.
fn point(key: &str, value: &toml::Value) -> Result<glam::Vec3, String> {
    match value {
        toml::Value::Array(items) if items.len() == 3 => {
            let mut xyz = [0.0; 3];
            for (i, item) in items.iter().enumerate() {
                xyz[i] = input::number(&format!("{key}[{i}]"), item)?;
            }
            Ok(glam::Vec3::from(xyz))
        }
        _ => Err(format!("{key} must be a point [x, y, z], not {}", input::describe(value))),
    }
}

fn render(src: &Source, raw: Option<RenderFile>) -> crate::Result<RenderSettings> {
    let Some(raw) = raw else {
        return Ok(RenderSettings::default());
    };
    Ok(RenderSettings {
        spp: src.read("spp", &raw.spp, |k, v| input::unsigned(k, v, 1))?,
        seed: src.read("seed", &raw.seed, |k, v| input::unsigned(k, v, 0))?,
        exposure: src.read("exposure", &raw.exposure, exposure)?,
        tonemap: src.read("tonemap", &raw.tonemap, tonemap)?,
        aovs: src.read("aovs", &raw.aovs, aov_names)?,
        noise_threshold: src.read("noise_threshold", &raw.noise_threshold, noise_threshold)?,
        min_spp: src.read("min_spp", &raw.min_spp, |k, v| input::unsigned(k, v, 2))?,
    })
}

fn model(src: &Source, raw: Option<&BTreeMap<Field<String>, Field>>) -> crate::Result<Option<Model>> {
    let Some(raw) = raw else {
        return Ok(None);
    };
    let mut model = Model::default();
    for (key, value) in raw {
        let parsed = match value.get_ref() {
            toml::Value::String(t) => ModelValue::Text(t),
            toml::Value::Float(x) => ModelValue::Number(*x),
            toml::Value::Integer(i) => ModelValue::Number(*i as f64),
            toml::Value::Boolean(b) => ModelValue::Bool(*b),
            other => {
                return Err(
                    src.error(value.span(), format!("{}: a {} is not a model value", key.get_ref(), other.type_str()))
                )
            }
        };
        let span =
            if crate::shading::model::KEYS.contains(&key.get_ref().as_str()) { value.span() } else { key.span() };
        model.set(key.get_ref(), parsed).map_err(|problem| src.error(span, problem))?;
    }
    Ok(Some(model))
}

/// Converts the `[[object]]` tables, checking that ids are unique and that there is at most one
/// default stack.
fn objects(src: &Source, raw: &[Field<ObjectFile>], library: &Library) -> crate::Result<Vec<ObjectStack>> {
    // The line of the first stack seen for each id (None: the default stack).
    let mut first_line: BTreeMap<Option<u32>, usize> = BTreeMap::new();
    let mut stacks = Vec::new();
    for object in raw {
        let line = src.line(object.span().start);
        let id = src.read("id", &object.get_ref().id, |k, v| input::unsigned(k, v, 0))?;
        let name = src.read("name", &object.get_ref().name, input::text)?;
        let shadow_catcher =
            src.read("shadow_catcher", &object.get_ref().shadow_catcher, input::boolean)?.unwrap_or(false);
        if let (Some(_), Some(field)) = (id, &object.get_ref().name) {
            return Err(src.error(field.span(), "an [[object]] has an id or a name, not both"));
        }
        if name.is_some() {
            let layers = &object.get_ref().layer;
            if layers.is_empty() {
                return Err(src.error(object.span(), "[[object]] has no layers; add at least one [[object.layer]]"));
            }
            let layers = layers.iter().map(|l| layer(src, l, library)).collect::<crate::Result<_>>()?;
            stacks.push(ObjectStack { id: None, name, layers, shadow_catcher, line });
            continue;
        }
        if let Some(first) = first_line.insert(id, line) {
            let problem = match id {
                Some(id) => format!("duplicate object id {id} (first at line {first})"),
                None => format!("a second default stack ([[object]] without id; the first is at line {first})"),
            };
            return Err(src.error(object.span(), problem));
        }
        let layers = &object.get_ref().layer;
        if layers.is_empty() {
            return Err(src.error(object.span(), "[[object]] has no layers; add at least one [[object.layer]]"));
        }
        let layers = layers.iter().map(|l| layer(src, l, library)).collect::<crate::Result<_>>()?;
        stacks.push(ObjectStack { id, name: None, layers, shadow_catcher, line });
    }
    Ok(stacks)
}

fn layer(src: &Source, raw: &Field<LayerFile>, library: &Library) -> crate::Result<Layer> {
    let fields = raw.get_ref();
    let preset = src.read("preset", &fields.preset, input::text)?;
    let mut params = Params::default();
    if let (Some(name), Some(field)) = (&preset, &fields.preset) {
        params = library.resolve(name).map_err(|problem| src.error(field.span(), problem))?.params;
    }
    let mut overrides = Vec::new();
    for (key, value) in fields.set.iter().flatten() {
        let param = Param::from_name(key.get_ref())
            .ok_or_else(|| src.error(key.span(), unknown_param(key.get_ref(), "[object.layer.set]")))?;
        input::set_param(&mut params, param, value.get_ref()).map_err(|problem| src.error(value.span(), problem))?;
        overrides.push(param);
    }
    overrides.sort();
    let mut maps = BTreeMap::new();
    for (key, value) in fields.map.iter().flatten() {
        let param = Param::from_name(key.get_ref())
            .ok_or_else(|| src.error(key.span(), unknown_param(key.get_ref(), "[object.layer.map]")))?;
        let map = map_name(param.name(), value.get_ref()).map_err(|problem| src.error(value.span(), problem))?;
        maps.insert(param, map);
    }
    let mask_adjust = mask_adjust(src, fields)?;
    Ok(Layer {
        name: src.read("name", &fields.name, input::text)?,
        preset,
        params,
        overrides,
        maps,
        mask: src.read("mask", &fields.mask, input::text)?,
        mask_adjust,
        invert: src.read("invert", &fields.invert, input::boolean)?.unwrap_or(false),
        opacity: src.read("opacity", &fields.opacity, unit_interval)?.unwrap_or(1.0),
        enabled: src.read("enabled", &fields.enabled, input::boolean)?.unwrap_or(true),
        line: src.line(raw.span().start),
        id: LayerId::new(),
    })
}

/// The layer's `mask_*` keys, each checked on its own and then together (black below white).
fn mask_adjust(src: &Source, fields: &LayerFile) -> crate::Result<MaskAdjust> {
    let identity = MaskAdjust::default();
    let adjust = MaskAdjust {
        blur: src.read("mask_blur", &fields.mask_blur, input::number)?.unwrap_or(identity.blur),
        black: src.read("mask_black", &fields.mask_black, input::number)?.unwrap_or(identity.black),
        white: src.read("mask_white", &fields.mask_white, input::number)?.unwrap_or(identity.white),
        gamma: src.read("mask_gamma", &fields.mask_gamma, input::number)?.unwrap_or(identity.gamma),
    };
    if let Err(problem) = adjust.check() {
        // The message starts with the key it is about.
        let keys = [
            ("mask_blur", &fields.mask_blur),
            ("mask_black", &fields.mask_black),
            ("mask_white", &fields.mask_white),
            ("mask_gamma", &fields.mask_gamma),
        ];
        let written = keys.iter().filter_map(|(key, field)| field.as_ref().map(|f| (key, f)));
        let mut written: Vec<_> = written.collect();
        written.sort_by_key(|(key, _)| !problem.starts_with(*key));
        let span = written.first().map_or(0..0, |(_, f)| f.span());
        return Err(src.error(span, problem));
    }
    Ok(adjust)
}

fn unknown_param(name: &str, table: &str) -> String {
    let names = Param::ALL.map(Param::name);
    crate::suggest::unknown("parameter", name, &format!("in {table}"), &names)
}

/// A map's name as a binding gives it: `name` or `name.R|G|B`, without the `map.` prefix.
fn map_name(key: &str, value: &toml::Value) -> Result<String, String> {
    let name = input::text(key, value)?;
    crate::gbuffer::check_map_name(&name).map_err(|problem| format!("{key} = {problem}"))?;
    Ok(name)
}

fn intensity(key: &str, value: &toml::Value) -> Result<f32, String> {
    let x = input::number(key, value)?;
    crate::environment::check_intensity(x).map(|()| x).map_err(|_| {
        format!("{key} = {} must be a number from 0 to {:e}", crate::number_text(x), crate::environment::MAX_INTENSITY)
    })
}

/// AOV names, each one lookdev writes (or a group of them).
fn aov_names(key: &str, value: &toml::Value) -> Result<Vec<String>, String> {
    let names = input::text_list(key, value)?;
    for name in &names {
        crate::render::aov::Aov::parse(name)?;
    }
    Ok(names)
}

fn exposure(key: &str, value: &toml::Value) -> Result<f32, String> {
    let x = input::number(key, value)?;
    if x.abs() <= MAX_EXPOSURE {
        Ok(x)
    } else {
        Err(format!("{key} = {} must be within ±{MAX_EXPOSURE} stops", crate::number_text(x)))
    }
}

fn noise_threshold(key: &str, value: &toml::Value) -> Result<f32, String> {
    let x = input::number(key, value)?;
    if x > 0.0 && x < 1e3 {
        Ok(x)
    } else {
        Err(format!("{key} = {} must be above 0 and below 1000", crate::number_text(x)))
    }
}

fn unit_interval(key: &str, value: &toml::Value) -> Result<f32, String> {
    let x = input::number(key, value)?;
    if (0.0..=1.0).contains(&x) {
        Ok(x)
    } else {
        Err(format!("{key} = {x} is out of range [0, 1]"))
    }
}

fn tonemap(key: &str, value: &toml::Value) -> Result<Tonemap, String> {
    Tonemap::parse(&input::text(key, value)?)
}

/// The bottom layer fills its object, so settings that only weight a layer do nothing there.
/// They are kept (and written back), but an artist who set them expected something: say so.
fn warn_about_bottom_layers(src: &Source, look: &Look) {
    for bottom in look.objects.iter().filter_map(|o| o.layers.first()) {
        if bottom.mask.is_some() || bottom.invert || bottom.opacity != 1.0 {
            crate::warn(format!(
                "{}:{}: the bottom layer fills its object; its mask, invert and opacity have no effect",
                src.file.display(),
                bottom.line
            ));
        }
    }
}
