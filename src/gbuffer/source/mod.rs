//! G-buffer sources: lookdev's own files, Blender/Cycles multilayer EXRs, Arnold-style AOV EXRs
//! (single- or multi-part) and, through an explicit mapping, any other renderer's. Each is
//! translated into lookdev's channels (docs/formats.md#g-buffers) before validation, so
//! validation knows one format only:
//!
//! 1. the file's parts are merged into one set of named channels ([`raw`]);
//! 2. the source is detected from the channel names, unless the options name the normals;
//! 3. vectors are converted from a Z-up world to lookdev's Y-up one: (x, y, z) ↦ (x, z, −y);
//! 4. ids, coverage, names and mattes come from Cryptomatte ([`cryptomatte`]);
//! 5. view vectors come from a V channel, else from positions and the camera ([`camera`]),
//!    else they default to (0, 0, 1), with a warning.

pub mod camera;
pub mod cryptomatte;
pub mod occluders;
pub mod raw;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glam::Vec3;

use self::camera::Camera;
use self::cryptomatte::Role;
use self::raw::{RawFile, Samples};
use super::validate::RawImage;
use super::{COVERAGE_CHANNEL, MAP_PREFIX, MASK_PREFIX, NORMAL_CHANNELS, OBJECT_ID_CHANNEL, OBJECT_NAME_PREFIX};
use super::{TANGENT_CHANNELS, VIEW_CHANNELS};
use crate::{Error, Result};

/// The most the mattes of one Cryptomatte layer may take as mask channels (as much as a
/// g-buffer's channels may take decoded).
const MAX_MATTE_BYTES: u64 = 4 << 30;

/// The world's up axis in a file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Up {
    /// lookdev's, Maya's, Houdini's, Arnold's and Karma's: no conversion.
    #[default]
    Y,
    /// Blender's, 3ds Max's and Unreal's: (x, y, z) becomes (x, z, −y), a rotation of −90°
    /// about X, so Blender's front view (looking along +Y) looks down lookdev's −Z.
    Z,
}

impl Up {
    pub fn parse(text: &str) -> std::result::Result<Up, String> {
        match text.trim().to_ascii_lowercase().as_str() {
            "y" => Ok(Up::Y),
            "z" => Ok(Up::Z),
            other => Err(format!("up = '{other}': expected \"y\" or \"z\"")),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Up::Y => "y",
            Up::Z => "z",
        }
    }

    /// A vector (or point) of this world in lookdev's.
    pub fn to_lookdev(self, v: Vec3) -> Vec3 {
        match self {
            Up::Y => v,
            Up::Z => Vec3::new(v.x, v.z, -v.y),
        }
    }
}

/// Where lookdev's channels come from in a file of another renderer, by layer name (a vector's
/// components are found as `.X .Y .Z`, `.x .y .z`, `.R .G .B` or `.r .g .b`) or, for scalars,
/// by channel name. What is not named is found as the source's convention has it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Channels {
    pub normal: Option<String>,
    pub position: Option<String>,
    pub view: Option<String>,
    pub tangent: Option<String>,
    pub coverage: Option<String>,
    pub id: Option<String>,
    /// Channels to read as masks, each becoming `mask.<channel>` (its name made safe).
    pub masks: Vec<String>,
}

impl Channels {
    /// The roles and their names, for `--gbuffer-channel ROLE=NAME` and the look's `[gbuffer]`.
    pub const ROLES: [&'static str; 7] = ["normal", "position", "view", "tangent", "coverage", "id", "mask"];

    /// Sets a role to a name; `mask` adds one.
    pub fn set(&mut self, role: &str, name: &str) -> std::result::Result<(), String> {
        let name = name.trim();
        if name.is_empty() {
            return Err(format!("{role}: the channel name is empty"));
        }
        let slot = match role {
            "normal" => &mut self.normal,
            "position" => &mut self.position,
            "view" => &mut self.view,
            "tangent" => &mut self.tangent,
            "coverage" => &mut self.coverage,
            "id" => &mut self.id,
            "mask" => {
                self.masks.push(name.to_string());
                return Ok(());
            }
            other => return Err(crate::suggest::unknown("g-buffer role", other, "", &Channels::ROLES)),
        };
        *slot = Some(name.to_string());
        Ok(())
    }
}

/// How to read a g-buffer file: the look's `[gbuffer]` table under the command-line flags.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SourceOptions {
    /// A Blender view layer, or a part of a multi-part file (`--gbuffer-layer`).
    pub layer: Option<String>,
    /// The file's up axis (`--up`); by default, the source's convention.
    pub up: Option<Up>,
    /// The camera, in the file's own coordinates (`--camera-position`), for view vectors from
    /// positions when the header does not record it.
    pub camera_position: Option<Vec3>,
    pub channels: Channels,
    /// The scene's triangles (a glTF file), to trace the visibility through from the file's
    /// positions (`--occluders`); by default, the file the header's note names.
    pub occluders: Option<PathBuf>,
    /// Reads no visibility and traces none (`--no-visibility`).
    pub no_visibility: bool,
}

impl SourceOptions {
    /// These options over `base`: what is set here wins.
    pub fn over(&self, base: &SourceOptions) -> SourceOptions {
        let c = &self.channels;
        let b = &base.channels;
        SourceOptions {
            layer: self.layer.clone().or_else(|| base.layer.clone()),
            up: self.up.or(base.up),
            camera_position: self.camera_position.or(base.camera_position),
            channels: Channels {
                normal: c.normal.clone().or_else(|| b.normal.clone()),
                position: c.position.clone().or_else(|| b.position.clone()),
                view: c.view.clone().or_else(|| b.view.clone()),
                tangent: c.tangent.clone().or_else(|| b.tangent.clone()),
                coverage: c.coverage.clone().or_else(|| b.coverage.clone()),
                id: c.id.clone().or_else(|| b.id.clone()),
                masks: if c.masks.is_empty() { b.masks.clone() } else { c.masks.clone() },
            },
            occluders: self.occluders.clone().or_else(|| base.occluders.clone()),
            no_visibility: self.no_visibility || base.no_visibility,
        }
    }
}

/// The renderer a file came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    Lookdev,
    Blender,
    Arnold,
    /// Any other, through an explicit mapping.
    Mapped,
}

impl Source {
    pub fn name(self) -> &'static str {
        match self {
            Source::Lookdev => "lookdev",
            Source::Blender => "Blender/Cycles",
            Source::Arnold => "Arnold-style AOVs",
            Source::Mapped => "explicit mapping",
        }
    }
}

/// What was detected and where each channel comes from, for the line printed unless `--quiet`.
#[derive(Clone, Debug, PartialEq)]
pub struct Detected {
    pub source: Source,
    /// The view layer or part read, if the file has several.
    pub layer: Option<String>,
    pub up: Up,
    /// lookdev's channel (or channels) and where it comes from.
    pub from: Vec<(String, String)>,
}

impl Detected {
    /// One line: `G.exr: Blender/Cycles, view layer ViewLayer, Z up: N from ViewLayer.Normal, …`.
    pub fn summary(&self, path: &Path) -> String {
        let layer = self.layer.as_ref().map(|l| format!(", layer {l}")).unwrap_or_default();
        let from: Vec<String> = self.from.iter().map(|(what, from)| format!("{what} from {from}")).collect();
        format!(
            "{}: {}{layer}, {} up: {}",
            path.display(),
            self.source.name(),
            self.up.name().to_uppercase(),
            from.join("; ")
        )
    }
}

/// What a production render offers for tracing its visibility when it is read
/// ([`crate::visibility::occluders`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Surfaces {
    /// World positions in lookdev's frame, coverage divided out, where the file has them.
    pub positions: Option<Vec<Vec3>>,
    /// The occluders its header names.
    pub occluders: Option<occluders::Occluders>,
}

/// The channels of a file merged from its parts, with its header's attributes.
struct Merged {
    width: usize,
    height: usize,
    channels: BTreeMap<String, Samples>,
    text: BTreeMap<String, String>,
    matrices: BTreeMap<String, [[f32; 4]; 4]>,
    /// Names of the other attributes (neither text nor matrices).
    other_attributes: Vec<String>,
    /// The part chosen by `--gbuffer-layer`, if the layer named a part.
    part: Option<String>,
}

/// Translates a decoded file into lookdev's channels. Returns them with what was detected and
/// any warnings (one line each, naming the file).
pub(crate) fn translate(
    file: RawFile,
    options: &SourceOptions,
    path: &Path,
) -> Result<(RawImage, Detected, Vec<String>)> {
    let bad = |problem: String| Error::input_file(path, problem);
    let merged = merge(file, options.layer.as_deref()).map_err(bad)?;
    let crypto = cryptomatte::declared(&merged.text).map_err(bad)?;
    let source = detect(&merged, &crypto, options).map_err(bad)?;
    let mut warnings = Vec::new();
    match source {
        (Source::Lookdev, _) => Ok(lookdev(merged, options)),
        (source, layer) => other(merged, &crypto, options, source, layer, path, &mut warnings)
            .map(|(raw, detected)| (raw, detected, warnings)),
    }
}

/// One set of channels from the file's parts: a single part as it is; several parts (as
/// Arnold and Karma write them, an AOV a part) merged, a part's channels without a layer
/// prefix getting the part's name as one. `layer` naming a part reads that part alone.
fn merge(file: RawFile, layer: Option<&str>) -> std::result::Result<Merged, String> {
    let mut parts = file.parts;
    let names: Vec<String> = parts.iter().filter_map(|p| p.name.clone()).collect();
    let mut chosen = None;
    if let (Some(layer), true) = (layer, parts.len() > 1) {
        // Else the layer is a Blender view layer inside the parts, or an error later.
        if let Some(i) = parts.iter().position(|p| p.name.as_deref() == Some(layer)) {
            parts = vec![parts.swap_remove(i)];
            chosen = Some(layer.to_string());
        }
    }
    let Some(first) = parts.first() else { return Err("the file has no parts".into()) };
    let (width, height) = (first.width, first.height);
    let mut merged = Merged {
        width,
        height,
        channels: BTreeMap::new(),
        text: BTreeMap::new(),
        matrices: BTreeMap::new(),
        other_attributes: Vec::new(),
        part: chosen,
    };
    let several = parts.len() > 1;
    for part in parts {
        if (part.width, part.height) != (width, height) {
            return Err(format!(
                "its parts differ in size ({}: {}x{}, the first {width}x{height}); choose one with --gbuffer-layer (parts: {})",
                part.name.as_deref().unwrap_or("unnamed"),
                part.width,
                part.height,
                names.join(", ")
            ));
        }
        for (name, samples) in part.channels {
            let name = match (&part.name, several) {
                (Some(prefix), true) if !name.contains('.') => format!("{prefix}.{name}"),
                _ => name,
            };
            if merged.channels.insert(name.clone(), samples).is_some() {
                return Err(format!(
                    "several parts have the channel {name}, so the file holds more than one image; choose a part with --gbuffer-layer (parts: {})",
                    names.join(", ")
                ));
            }
        }
        merged.other_attributes.extend(part.other_attributes);
        for (key, value) in part.text {
            merged.text.entry(key).or_insert(value);
        }
        for (key, value) in part.matrices {
            merged.matrices.entry(key).or_insert(value);
        }
    }
    Ok(merged)
}

/// The component suffixes a vector layer's channels may have, in the order they are tried.
const COMPONENTS: [[&str; 3]; 4] = [["X", "Y", "Z"], ["x", "y", "z"], ["R", "G", "B"], ["r", "g", "b"]];

/// The three channels of the vector layer `layer`, if the file has them.
fn vector(channels: &BTreeMap<String, Samples>, layer: &str) -> Option<[String; 3]> {
    COMPONENTS.iter().find_map(|suffixes| {
        let names = suffixes.map(|s| format!("{layer}.{s}"));
        names.iter().all(|n| channels.contains_key(n)).then_some(names)
    })
}

/// The Blender view layers of a file: every `L` with `L.Normal.X`, `.Y` and `.Z`.
fn blender_layers(channels: &BTreeMap<String, Samples>) -> Vec<String> {
    channels
        .keys()
        .filter_map(|name| name.strip_suffix(".Normal.X"))
        .filter(|layer| vector(channels, &format!("{layer}.Normal")).is_some())
        .map(str::to_string)
        .collect()
}

/// Which source a file is, and its view layer: from the options' normal channel, else the
/// channel names. More than one candidate is an error that lists them and the flag to settle it.
fn detect(
    merged: &Merged,
    crypto: &[cryptomatte::Declared],
    options: &SourceOptions,
) -> std::result::Result<(Source, Option<String>), String> {
    let channels = &merged.channels;
    if options.channels.normal.is_some() {
        return Ok((Source::Mapped, merged.part.clone()));
    }
    let present: Vec<&str> = NORMAL_CHANNELS.iter().copied().filter(|c| channels.contains_key(*c)).collect();
    if !present.is_empty() && present.len() < 3 {
        let missing: Vec<&str> = NORMAL_CHANNELS.iter().copied().filter(|c| !present.contains(c)).collect();
        return Err(format!(
            "missing normal channel{} {} (N.X N.Y N.Z are required); channels found: {}",
            if missing.len() == 1 { "" } else { "s" },
            missing.join(", "),
            channels.keys().map(String::as_str).collect::<Vec<_>>().join(", ")
        ));
    }
    let lookdev_markers = channels.keys().any(|n| {
        n == COVERAGE_CHANNEL
            || n == OBJECT_ID_CHANNEL
            || VIEW_CHANNELS.contains(&n.as_str())
            || n.starts_with(MASK_PREFIX)
            || n.starts_with(MAP_PREFIX)
    });
    let has_lookdev_normals = NORMAL_CHANNELS.iter().all(|c| channels.contains_key(*c));
    let aov_layers = vector(channels, "P").is_some() || !crypto.is_empty();
    let lookdev = has_lookdev_normals && (lookdev_markers || !aov_layers);
    let arnold = !lookdev && vector(channels, "N").is_some();
    let blender = blender_layers(channels);
    let mut found = Vec::new();
    if lookdev {
        found.push("lookdev's N.X/N.Y/N.Z".to_string());
    }
    if arnold {
        found.push("Arnold-style N and P".to_string());
    }
    if !blender.is_empty() {
        found.push(format!("Blender view layers {}", blender.join(", ")));
    }
    match (lookdev, arnold, blender.len()) {
        (true, false, 0) | (false, true, 0) => {
            if let (Some(layer), None) = (&options.layer, &merged.part) {
                return Err(format!("--gbuffer-layer {layer}: the file has no view layer or part of that name"));
            }
            Ok((if lookdev { Source::Lookdev } else { Source::Arnold }, merged.part.clone()))
        }
        (false, false, n) if n > 0 => match &options.layer {
            Some(layer) if blender.contains(layer) => Ok((Source::Blender, Some(layer.clone()))),
            Some(layer) => {
                Err(format!("--gbuffer-layer {layer}: no such view layer (the file has {})", blender.join(", ")))
            }
            None if n == 1 => Ok((Source::Blender, Some(blender[0].clone()))),
            None => Err(format!(
                "the file has several Blender view layers ({}); choose one with --gbuffer-layer",
                blender.join(", ")
            )),
        },
        (false, false, _) => {
            let listed: Vec<&str> = channels.keys().map(String::as_str).take(24).collect();
            Err(format!(
                "missing normal channels N.X, N.Y, N.Z (lookdev's own files; Blender's <view layer>.Normal and \
                 Arnold's N are read too); channels found: {}{}; --gbuffer-channel normal=NAME names others",
                if listed.is_empty() { "none".to_string() } else { listed.join(", ") },
                if channels.len() > listed.len() { ", …" } else { "" }
            ))
        }
        _ => Err(format!(
            "the file could be read several ways ({}); --gbuffer-channel normal=NAME{} settles it",
            found.join("; "),
            if blender.is_empty() { "" } else { " or --gbuffer-layer NAME" }
        )),
    }
}

/// lookdev's own format: its channels as they are, vectors turned when `--up z` says so.
fn lookdev(merged: Merged, options: &SourceOptions) -> (RawImage, Detected, Vec<String>) {
    let up = options.up.unwrap_or(Up::Y);
    let mut channels = merged.channels;
    if up == Up::Z {
        for names in [NORMAL_CHANNELS, VIEW_CHANNELS, TANGENT_CHANNELS] {
            let names = names.map(String::from);
            if let Some(vectors) = read_vector(&channels, &names) {
                write_vector(&mut channels, &names, vectors.into_iter().map(|v| up.to_lookdev(v)).collect());
            }
        }
    }
    let text = merged.text.iter().map(|(name, value)| (name.clone(), Some(value.clone())));
    let other = merged.other_attributes.iter().map(|name| (name.clone(), None));
    let object_name_attributes = text.chain(other).filter(|(name, _)| name.starts_with(OBJECT_NAME_PREFIX)).collect();
    let mask_names = merged
        .text
        .iter()
        .filter_map(|(name, value)| Some((name.strip_prefix(super::MASK_NAME_PREFIX)?.to_string(), value.clone())))
        .collect();
    let supersample = merged.text.get(super::SUPERSAMPLE_ATTRIBUTE).map(|t| (t.clone(), "the header's supersample"));
    let raw = RawImage {
        width: merged.width,
        height: merged.height,
        channels,
        object_name_attributes,
        mask_names,
        surfaces: Surfaces::default(),
        supersample,
        filtered_normals: false,
    };
    let detected = Detected { source: Source::Lookdev, layer: merged.part, up, from: Vec::new() };
    (raw, detected, Vec::new())
}

fn read_vector(channels: &BTreeMap<String, Samples>, names: &[String; 3]) -> Option<Vec<Vec3>> {
    let [x, y, z] = [0, 1, 2].map(|k| channels.get(&names[k]).map(Samples::to_f32));
    let (x, y, z) = (x?, y?, z?);
    Some(x.into_iter().zip(y).zip(z).map(|((x, y), z)| Vec3::new(x, y, z)).collect())
}

fn write_vector(channels: &mut BTreeMap<String, Samples>, names: &[String; 3], vectors: Vec<Vec3>) {
    for (k, name) in names.iter().enumerate() {
        channels.insert(name.clone(), Samples::F32(vectors.iter().map(|v| v[k]).collect()));
    }
}

/// A renderer's AOVs in lookdev's channels.
fn other(
    merged: Merged,
    crypto: &[cryptomatte::Declared],
    options: &SourceOptions,
    source: Source,
    layer: Option<String>,
    path: &Path,
    warnings: &mut Vec<String>,
) -> Result<(RawImage, Detected)> {
    let bad = |problem: String| Error::input_file(path, problem);
    let named = &options.channels;
    let up = options.up.unwrap_or(if source == Source::Blender { Up::Z } else { Up::Y });
    // Blender's passes live under the view layer's name.
    let prefix = match (source, &layer) {
        (Source::Blender, Some(layer)) => format!("{layer}."),
        _ => String::new(),
    };
    let convention = |blender: &str, arnold: &str| match source {
        Source::Blender => Some(format!("{prefix}{blender}")),
        Source::Arnold => Some(arnold.to_string()),
        _ => None,
    };
    let channels = &merged.channels;
    let find =
        |given: &Option<String>, blender: &str, arnold: &str, what: &str| -> Result<Option<(String, [String; 3])>> {
            let Some(name) = given.clone().or_else(|| convention(blender, arnold)) else { return Ok(None) };
            match vector(channels, &name) {
                Some(names) => Ok(Some((name, names))),
                None if given.is_some() => Err(bad(format!(
                    "the {what} layer {name} is not in the file (as {name}.X/.Y/.Z, .x/.y/.z, .R/.G/.B or .r/.g/.b)"
                ))),
                None => Ok(None),
            }
        };
    let (normal_layer, normal_names) = find(&named.normal, "Normal", "N", "normal")?.expect("detected by its normals");
    let position = find(&named.position, "Position", "P", "position")?;
    let view = find(&named.view, "View", "V", "view")?;
    let tangent = find(&named.tangent, "Tangent", "T", "tangent")?;
    let pixels = merged.width * merged.height;
    let converted = |names: &[String; 3]| -> Vec<Vec3> {
        read_vector(channels, names).expect("found").into_iter().map(|v| up.to_lookdev(v)).collect()
    };
    let normals = converted(&normal_names);
    let mut out: BTreeMap<String, Samples> = BTreeMap::new();
    let mut from = vec![("N".to_string(), describe_vector(&normal_layer, up))];
    if let Some((layer, names)) = &tangent {
        write_vector(&mut out, &TANGENT_CHANNELS.map(String::from), converted(names));
        from.push(("T".into(), describe_vector(layer, up)));
    }

    // Ids, coverage and names from the object Cryptomatte; mattes from the others.
    let mut object_names = Vec::new();
    let mut mask_names = BTreeMap::new();
    let mut coverage: Option<Vec<f32>> = None;
    let mut taken: Vec<String> = Vec::new();
    // A view layer's own Cryptomatte: `ViewLayer.CryptoObject` is `ViewLayer`'s, not
    // `ViewLayer.002`'s `ViewLayer.002.CryptoObject`.
    let in_layer = |d: &&cryptomatte::Declared| {
        prefix.is_empty() || d.name.strip_prefix(&prefix).is_some_and(|rest| !rest.contains('.'))
    };
    for declared in crypto.iter().filter(in_layer) {
        let decoded = {
            let refs: BTreeMap<String, &Samples> = channels.iter().map(|(k, v)| (k.clone(), v)).collect();
            let ranks = cryptomatte::ranks(&refs, &declared.name);
            if ranks.is_empty() {
                warnings.push(format!(
                    "{}: Cryptomatte layer {} has no rank channels; it is ignored",
                    path.display(),
                    declared.name
                ));
                continue;
            }
            cryptomatte::decode(declared, &ranks, pixels)
        };
        let mismatched = declared.mismatched_hashes();
        if !mismatched.is_empty() {
            warnings.push(format!(
                "{}: Cryptomatte layer {}: the manifest's hashes of {} are not MurmurHash3_32 of the names; they are read by the manifest's hashes",
                path.display(),
                declared.name,
                listed(&mismatched, 5)
            ));
        }
        match declared.role() {
            Role::Object if named.id.is_none() && coverage.is_none() => {
                let (ids, sum) = dominant(&decoded.mattes, pixels);
                object_names = declared
                    .manifest
                    .iter()
                    .enumerate()
                    .map(|(i, (name, _))| (format!("{OBJECT_NAME_PREFIX}{}", i + 1), Some(name.clone())))
                    .collect();
                out.insert(OBJECT_ID_CHANNEL.into(), Samples::U32(ids));
                from.push(("objectId, A".into(), format!("{} ({} objects)", declared.name, declared.manifest.len())));
                coverage = Some(sum);
            }
            Role::Object => {}
            _ => {
                let bytes = (decoded.mattes.len() * pixels * std::mem::size_of::<f32>()) as u64;
                if bytes > MAX_MATTE_BYTES {
                    return Err(bad(format!(
                        "Cryptomatte layer {} covers its pixels with {} names, whose mattes would take {:.1} GiB, \
                         more than the {} GiB lookdev allows",
                        declared.name,
                        decoded.mattes.len(),
                        bytes as f64 / (1u64 << 30) as f64,
                        MAX_MATTE_BYTES >> 30
                    )));
                }
                for (entry, pairs) in &decoded.mattes {
                    let name = &declared.manifest[*entry].0;
                    let mask = crate::asset::names::unique(crate::asset::channel_name(name), &mut taken, |a, b| a == b);
                    if &mask != name {
                        mask_names.insert(mask.clone(), name.clone());
                    }
                    let matte = cryptomatte::Decoded::dense(pairs, pixels);
                    out.insert(
                        format!("{MASK_PREFIX}{mask}"),
                        Samples::F32(matte.into_iter().map(|c| c.min(1.0)).collect()),
                    );
                }
                from.push(("masks".into(), format!("{} ({} mattes)", declared.name, decoded.mattes.len())));
            }
        }
    }
    if let Some(name) = &named.coverage {
        let samples =
            channels.get(name).ok_or_else(|| bad(format!("the coverage channel {name} is not in the file")))?;
        coverage = Some(samples.to_f32());
        from.push(("A".into(), name.clone()));
    }
    if let Some(name) = &named.id {
        let samples = channels.get(name).ok_or_else(|| bad(format!("the id channel {name} is not in the file")))?;
        out.insert(OBJECT_ID_CHANNEL.into(), samples.clone());
        from.push(("objectId".into(), name.clone()));
    } else if !out.contains_key(OBJECT_ID_CHANNEL) {
        // Blender's object index pass, where there is no Cryptomatte.
        if let Some(index) = channels.get(&format!("{prefix}IndexOB.X")).filter(|_| source == Source::Blender) {
            out.insert(OBJECT_ID_CHANNEL.into(), index.clone());
            from.push(("objectId".into(), format!("{prefix}IndexOB")));
        }
    }
    // Renderers filter their passes over the pixel, background included, so at an edge the
    // normal and the position are the covered part's times its coverage: divide it out. With
    // no coverage from the file, the normal's length is the best estimate of it.
    let coverage: Vec<f32> = match coverage {
        Some(coverage) => coverage.iter().map(|c| c.clamp(0.0, 1.0)).collect(),
        None => {
            from.push(("A".into(), format!("the length of {normal_layer}")));
            normals.iter().map(|n| if n.length() > 0.02 { n.length().min(1.0) } else { 0.0 }).collect()
        }
    };
    // Validation renormalises every normal; here only the filtered ones need it, to count.
    let normals: Vec<Vec3> = normals
        .iter()
        .zip(&coverage)
        .map(|(n, &a)| if a < 1.0 { n.try_normalize().unwrap_or(*n) } else { *n })
        .collect();
    write_vector(&mut out, &NORMAL_CHANNELS.map(String::from), normals.clone());
    let unfiltered = |points: Vec<Vec3>| -> Vec<Vec3> {
        points.into_iter().zip(&coverage).map(|(p, &a)| if a > 0.0 { p / a } else { p }).collect()
    };
    out.insert(COVERAGE_CHANNEL.into(), Samples::F32(coverage.clone()));
    // Masks named in the options, and the shader AOVs lookdev's Blender script writes.
    let mut masks: Vec<(String, String)> = Vec::new();
    for name in &named.masks {
        let channel = if channels.contains_key(name) { name.clone() } else { format!("{name}.X") };
        if !channels.contains_key(&channel) {
            return Err(bad(format!("the mask channel {name} is not in the file")));
        }
        masks.push((name.rsplit('.').next().unwrap_or(name).to_string(), channel));
    }
    if source == Source::Blender {
        for channel in channels.keys().filter(|c| c.starts_with(&format!("{prefix}mask_")) && c.ends_with(".X")) {
            let name = &channel[prefix.len() + "mask_".len()..channel.len() - 2];
            masks.push((name.to_string(), channel.clone()));
        }
    }
    for (name, channel) in masks {
        let mask = crate::asset::names::unique(crate::asset::channel_name(&name), &mut taken, |a, b| a == b);
        if mask != name {
            mask_names.insert(mask.clone(), name.clone());
        }
        out.insert(format!("{MASK_PREFIX}{mask}"), channels[&channel].clone());
        from.push((format!("mask.{mask}"), channel));
    }

    // View vectors: given, else from positions and the camera, else the default.
    if let Some((layer, names)) = &view {
        write_vector(&mut out, &VIEW_CHANNELS.map(String::from), converted(names));
        from.push(("V".into(), describe_vector(layer, up)));
    } else {
        let camera = match options.camera_position {
            Some(position) => Some(Camera {
                position,
                forward: None,
                projection: camera::Projection::Perspective,
                from: "--camera-position".into(),
            }),
            None => camera::from_header(&merged.text, &merged.matrices).map_err(bad)?,
        };
        match (&position, camera) {
            (Some((layer, names)), Some(camera)) => {
                let camera = Camera {
                    position: up.to_lookdev(camera.position),
                    forward: camera.forward.map(|f| up.to_lookdev(f)),
                    ..camera
                };
                let views = camera::view_vectors(
                    &camera,
                    &unfiltered(converted(names)),
                    &coverage,
                    merged.width,
                    merged.height,
                );
                write_vector(&mut out, &VIEW_CHANNELS.map(String::from), views);
                let how = match camera.projection {
                    camera::Projection::Perspective => format!("{layer} and the camera of {}", camera.from),
                    camera::Projection::Orthographic => format!("the orthographic camera of {}", camera.from),
                };
                from.push(("V".into(), how));
            }
            (None, Some(camera))
                if camera.projection == camera::Projection::Orthographic && camera.forward.is_some() =>
            {
                let forward = up.to_lookdev(camera.forward.expect("checked"));
                write_vector(&mut out, &VIEW_CHANNELS.map(String::from), vec![-forward; pixels]);
                from.push(("V".into(), format!("the orthographic camera of {}", camera.from)));
            }
            (position, _) => {
                let missing = if position.is_some() {
                    "no camera to make them from (the header records none; --camera-position X,Y,Z gives it)"
                } else {
                    "no positions to make them from (no P or Position layer)"
                };
                warnings.push(format!(
                    "{}: no view vectors, and {missing}: V defaults to (0, 0, 1), an orthographic camera looking down -Z",
                    path.display()
                ));
            }
        }
    }
    let folder = path.parent().unwrap_or(Path::new(""));
    let surfaces = Surfaces {
        positions: position.as_ref().map(|(_, names)| unfiltered(converted(names))),
        occluders: occluders::from_note(&merged.text, folder).map_err(bad)?,
    };
    let supersample =
        camera::note_field(&merged.text, "supersample").map(|t| (t.to_string(), "the note's supersample="));
    let raw = RawImage {
        width: merged.width,
        height: merged.height,
        channels: out,
        object_name_attributes: object_names,
        mask_names,
        surfaces,
        supersample,
        filtered_normals: true,
    };
    Ok((raw, Detected { source, layer, up, from }))
}

/// Per pixel, the manifest entry with the most coverage (numbered from 1 in manifest order, 0
/// where none covers it), and the coverage of all entries together.
fn dominant(mattes: &[(usize, Vec<(u32, f32)>)], pixels: usize) -> (Vec<u32>, Vec<f32>) {
    let mut ids = vec![0u32; pixels];
    let mut sum = vec![0.0f32; pixels];
    let mut best = vec![0.0f32; pixels];
    for (entry, pairs) in mattes {
        for &(p, coverage) in pairs {
            let p = p as usize;
            sum[p] += coverage;
            if coverage > best[p] {
                best[p] = coverage;
                ids[p] = *entry as u32 + 1;
            }
        }
    }
    (ids, sum)
}

/// The first `most` names, and how many more there are.
fn listed(names: &[&str], most: usize) -> String {
    match names.len().checked_sub(most) {
        Some(more) if more > 0 => format!("{} and {more} more", names[..most].join(", ")),
        _ => names.join(", "),
    }
}

fn describe_vector(layer: &str, up: Up) -> String {
    match up {
        Up::Y => layer.to_string(),
        Up::Z => format!("{layer}, turned from Z up"),
    }
}
