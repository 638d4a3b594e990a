//! Turning decoded channels into a [`GBuffer`]: the checks and fix-ups of the file format.
//!
//! Every check counts its offending pixels and reports the first one, so a user can find the
//! problem in a compositing package rather than guess from "invalid normal".

use std::collections::BTreeMap;
use std::path::Path;

use glam::Vec3;

use super::frame::{orthogonalize, stable_tangent};
use super::source::raw::Samples;
use super::{
    GBuffer, COLOR_MAP_CHANNELS, COVERAGE_CHANNEL, DEFAULT_VIEW, MAP_PREFIX, MASK_PREFIX, NORMAL_CHANNELS,
    OBJECT_ID_CHANNEL, OBJECT_NAME_PREFIX, PLACEHOLDER_NORMAL, TANGENT_CHANNELS, VIEW_CHANNELS, VISIBILITY_PREFIX,
};
use crate::visibility::{self, Grid, Visibility};
use crate::{Error, Result};

/// A decoded EXR part, before any of its contents are checked.
pub(crate) struct RawImage {
    pub width: usize,
    pub height: usize,
    /// Channel name (decoded as UTF-8) to samples, row-major, row 0 at the top.
    pub channels: BTreeMap<String, Samples>,
    /// Header attributes named `objectName.*`, with their value where it is text.
    pub object_name_attributes: Vec<(String, Option<String>)>,
    /// Header text attributes named `maskName.<mask>`, by mask name.
    pub mask_names: BTreeMap<String, String>,
    /// What the file offers for tracing visibility; validation leaves it to the reader.
    pub surfaces: super::source::Surfaces,
    /// The supersampling factor the file declares, as written, and where.
    pub supersample: Option<(String, &'static str)>,
    /// The normals are a renderer's filtered pass: averaged over each pixel's surfaces, which
    /// at an edge, a crease or a thin part seen edge-on can all but cancel.
    pub filtered_normals: bool,
}

/// A normal shorter than this is "clearly empty": it marks background in files without `A`, and
/// is an error where `A` says the pixel is covered.
const MIN_NORMAL_LENGTH: f32 = 0.5;
/// Normals whose length is off by more than this are reported (they are renormalised anyway).
const NORMAL_LENGTH_TOLERANCE: f32 = 0.01;
/// A view vector shorter than this has no direction.
const MIN_VIEW_LENGTH: f32 = 1e-6;

/// Checks `raw` and builds the g-buffer, returning the fix-up warnings (one line each, naming
/// `path`) alongside it.
pub(crate) fn build(path: &Path, raw: RawImage) -> Result<(GBuffer, Vec<String>)> {
    let check = Checker { path, width: raw.width, warnings: Vec::new() };
    let size = check.size(&raw)?;
    check.sample_counts(&raw)?;
    check.run(raw, size)
}

/// The file being checked, and the warnings so far.
struct Checker<'a> {
    path: &'a Path,
    width: usize,
    warnings: Vec<String>,
}

impl Checker<'_> {
    fn run(mut self, raw: RawImage, (width, height): (u32, u32)) -> Result<(GBuffer, Vec<String>)> {
        let raw_normal = self.required_triple(&raw, NORMAL_CHANNELS, "normal")?;
        let raw_view = self.optional_triple(&raw, VIEW_CHANNELS, "view")?;
        let raw_tangent = self.optional_triple(&raw, TANGENT_CHANNELS, "tangent")?;

        let explicit_coverage = match raw.channels.get(COVERAGE_CHANNEL) {
            Some(samples) => Some(self.unit_interval(COVERAGE_CHANNEL, samples)?),
            None => None,
        };
        let has_explicit_coverage = explicit_coverage.is_some();
        let coverage = explicit_coverage.unwrap_or_else(|| raw_normal.iter().map(|&n| default_coverage(n)).collect());

        let object_id = match raw.channels.get(OBJECT_ID_CHANNEL) {
            Some(samples) => self.object_ids(samples)?,
            None => vec![0; raw_normal.len()],
        };
        let normal = self.normals(&raw_normal, &coverage, has_explicit_coverage, &object_id, raw.filtered_normals)?;
        let view = match &raw_view {
            Some(raw_view) => self.views(raw_view)?,
            None => vec![Vec3::from(DEFAULT_VIEW); normal.len()],
        };
        self.facing(&normal, &view, &coverage, raw_view.is_some())?;
        let tangent = match &raw_tangent {
            Some(raw_tangent) => self.tangents(&normal, raw_tangent, &coverage),
            None => normal.iter().map(|n| stable_tangent(n.to_array())).collect(),
        };
        let masks = self.prefixed(&raw.channels, MASK_PREFIX)?;
        let mut maps = self.prefixed(&raw.channels, MAP_PREFIX)?;
        // A map no look could name is left out, rather than offered and then refused.
        maps.retain(|channel, _| {
            let colour_map = channel.rsplit_once('.').filter(|(_, c)| COLOR_MAP_CHANNELS.contains(c));
            let name = colour_map.map_or(channel.as_str(), |(name, _)| name);
            match super::check_map_name(name) {
                Ok(()) => true,
                Err(problem) => {
                    let path = self.path.display();
                    self.warnings.push(format!("{path}: ignored channel {MAP_PREFIX}{channel}: {problem}"));
                    false
                }
            }
        });
        let object_names = self.object_names(&raw.object_name_attributes);

        let gbuffer = GBuffer {
            width,
            height,
            normal: normal.iter().map(|n| n.to_array()).collect(),
            view: view.iter().map(|v| v.to_array()).collect(),
            tangent,
            coverage,
            object_id,
            masks,
            maps,
            object_names,
            mask_names: raw.mask_names,
            visibility: self.visibility(&raw.channels)?,
            has_view: raw_view.is_some(),
            has_tangent: raw_tangent.is_some(),
            supersample: match &raw.supersample {
                Some((text, from)) => {
                    let factor =
                        text.parse::<u32>().map_err(|_| self.error(format!("{from} {text} is not a whole number")))?;
                    super::check_supersample(factor, width, height)
                        .map_err(|problem| self.error(format!("{from}: {problem}")))?;
                    factor
                }
                None => 1,
            },
        };
        Ok((gbuffer, self.warnings))
    }

    fn error(&self, problem: impl std::fmt::Display) -> Error {
        Error::input_file(self.path, problem)
    }

    fn warn(&mut self, problem: impl std::fmt::Display) {
        self.warnings.push(format!("{}: {problem}", self.path.display()));
    }

    /// The image size as (width, height), which must be non-zero.
    fn size(&self, raw: &RawImage) -> Result<(u32, u32)> {
        if raw.width == 0 || raw.height == 0 {
            return Err(self.error(format!("empty image ({}x{} pixels)", raw.width, raw.height)));
        }
        match (u32::try_from(raw.width), u32::try_from(raw.height)) {
            (Ok(width), Ok(height)) => Ok((width, height)),
            _ => Err(self.error(format!("image too large ({}x{} pixels)", raw.width, raw.height))),
        }
    }

    /// Every channel the g-buffer uses must hold one sample per pixel; subsampled (chroma)
    /// channels do not, and are only accepted among the ignored ones.
    fn sample_counts(&self, raw: &RawImage) -> Result<()> {
        let pixels = raw.width * raw.height;
        let wrong_count = |(name, samples): &(&String, &Samples)| is_gbuffer_channel(name) && samples.len() != pixels;
        match raw.channels.iter().find(wrong_count) {
            Some((name, samples)) => Err(self.error(format!(
                "channel {name} has {} samples for {}x{} pixels; subsampled channels are not supported",
                samples.len(),
                raw.width,
                raw.height
            ))),
            None => Ok(()),
        }
    }

    /// The `N.*` triple, or an error listing what is missing and what the file has.
    fn required_triple(&self, raw: &RawImage, names: [&str; 3], what: &str) -> Result<Vec<Vec3>> {
        let missing: Vec<&str> = names.into_iter().filter(|n| !raw.channels.contains_key(*n)).collect();
        if missing.is_empty() {
            return Ok(triple(raw, names));
        }
        let found: Vec<&str> = raw.channels.keys().map(String::as_str).collect();
        let found = if found.is_empty() { "none".to_string() } else { found.join(", ") };
        Err(self.error(format!(
            "missing {what} channel{} {} ({} are required); channels found: {found}",
            if missing.len() == 1 { "" } else { "s" },
            missing.join(", "),
            names.join(" "),
        )))
    }

    /// An optional triple: all three channels, none, or an error for a partial set.
    fn optional_triple(&self, raw: &RawImage, names: [&str; 3], what: &str) -> Result<Option<Vec<Vec3>>> {
        let (present, missing): (Vec<&str>, Vec<&str>) = names.into_iter().partition(|n| raw.channels.contains_key(*n));
        match present.len() {
            0 => Ok(None),
            3 => Ok(Some(triple(raw, names))),
            _ => Err(self.error(format!(
                "incomplete {what} channels: has {} but not {}",
                present.join(", "),
                missing.join(", ")
            ))),
        }
    }

    /// A scalar channel that must be finite, clamped into \[0,1\] with a warning.
    fn unit_interval(&mut self, name: &str, samples: &Samples) -> Result<Vec<f32>> {
        let mut values = to_f32(samples);
        let mut non_finite = Offenders::default();
        let mut clamped = 0usize;
        for (i, value) in values.iter_mut().enumerate() {
            if !value.is_finite() {
                non_finite.add(i);
            } else if !(0.0..=1.0).contains(value) {
                clamped += 1;
                *value = value.clamp(0.0, 1.0);
            }
        }
        if non_finite.count > 0 {
            return Err(self.error(format!(
                "channel {name} has {} ({})",
                counted(non_finite.count, "NaN/Inf value"),
                non_finite.first_at(self.width)
            )));
        }
        if clamped > 0 {
            let values = counted(clamped, "value");
            self.warn(format!("clamped {values} of channel {name} into [0,1]"));
        }
        Ok(values)
    }

    /// Unit normals. Covered pixels must have a usable normal; uncovered ones keep theirs where
    /// it is usable and get the placeholder otherwise. A covered pixel's normal shorter than
    /// [`MIN_NORMAL_LENGTH`] is an error, but where the pixel borders another object, or
    /// anywhere in a renderer's `filtered` pass: a filtered normal averages the pixel's
    /// surfaces, whose normals can all but cancel where objects meet, at a crease or on a thin
    /// part seen edge-on. Such a pixel takes the normal of a neighbour of its own object (of any
    /// covered neighbour if it has none), with a warning.
    fn normals(
        &mut self,
        raw: &[Vec3],
        coverage: &[f32],
        explicit_coverage: bool,
        ids: &[u32],
        filtered: bool,
    ) -> Result<Vec<Vec3>> {
        let mut non_finite = Offenders::default();
        let mut too_short = Offenders::default();
        let mut filled = 0usize;
        let mut renormalised = 0usize;
        let mut normals = Vec::with_capacity(raw.len());
        let usable = |n: Vec3| n.is_finite() && n.length() > MIN_NORMAL_LENGTH;
        for (i, (&n, &a)) in raw.iter().zip(coverage).enumerate() {
            let length = n.length();
            let mut normal = if usable(n) { n / length } else { Vec3::from(PLACEHOLDER_NORMAL) };
            if a > 0.0 {
                if !n.is_finite() {
                    non_finite.add(i);
                } else if !usable(n) {
                    match self.edge_normal(i, raw, coverage, ids, filtered) {
                        Some(borrowed) => {
                            normal = borrowed;
                            filled += 1;
                        }
                        None => too_short.add(i),
                    }
                } else if (length - 1.0).abs() > NORMAL_LENGTH_TOLERANCE {
                    renormalised += 1;
                }
            }
            normals.push(normal);
        }
        if filled > 0 {
            let place = if filtered { "at edges, creases or thin parts" } else { "where objects meet" };
            self.warn(format!(
                "{} shorter than {MIN_NORMAL_LENGTH} {place} (a filtered normal pass averages the surfaces' \
                 normals there) took a neighbour's normal",
                counted(filled, "normal")
            ));
        }
        if non_finite.count > 0 {
            let pixel = if explicit_coverage { "covered pixel" } else { "pixel" };
            return Err(self.error(format!(
                "NaN/Inf normals at {} ({})",
                counted(non_finite.count, pixel),
                non_finite.first_at(self.width)
            )));
        }
        if too_short.count > 0 {
            return Err(self.error(format!(
                "normals shorter than {MIN_NORMAL_LENGTH} where coverage A > 0, at {} ({})",
                counted(too_short.count, "pixel"),
                too_short.first_at(self.width)
            )));
        }
        if renormalised > 0 {
            self.warn(format!(
                "renormalised {} whose length was off by more than {}%",
                counted(renormalised, "normal"),
                NORMAL_LENGTH_TOLERANCE * 100.0
            ));
        }
        Ok(normals)
    }

    /// Where covered pixel `i` borders another object (anywhere, in a `filtered` pass), the unit
    /// normal of a neighbour of its own object, else of any covered neighbour, with a usable
    /// normal.
    fn edge_normal(&self, i: usize, raw: &[Vec3], coverage: &[f32], ids: &[u32], filtered: bool) -> Option<Vec3> {
        let covered: Vec<usize> = self.neighbours(i, raw.len()).filter(|&j| coverage[j] > 0.0).collect();
        if !filtered && covered.iter().all(|&j| ids[j] == ids[i]) {
            return None;
        }
        let usable = |&&j: &&usize| raw[j].is_finite() && raw[j].length() > MIN_NORMAL_LENGTH;
        let own = covered.iter().filter(usable).find(|&&j| ids[j] == ids[i]);
        own.or(covered.iter().find(usable)).map(|&j| raw[j].normalize())
    }

    /// The pixels around pixel `i` of an image of `pixels` pixels, up to eight, row by row.
    fn neighbours(&self, i: usize, pixels: usize) -> impl Iterator<Item = usize> {
        let width = self.width as isize;
        let height = (pixels / self.width) as isize;
        let (x, y) = ((i % self.width) as isize, (i / self.width) as isize);
        (-1..=1).flat_map(move |dy| (-1..=1).map(move |dx| (x + dx, y + dy))).filter_map(move |(nx, ny)| {
            let inside = (0..width).contains(&nx) && (0..height).contains(&ny) && (nx, ny) != (x, y);
            inside.then_some((ny * width + nx) as usize)
        })
    }

    /// Unit view vectors; every pixel needs one, background included, since the background shows
    /// the environment in the direction −V.
    fn views(&self, raw: &[Vec3]) -> Result<Vec<Vec3>> {
        let mut bad = Offenders::default();
        let views = raw
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                let length = v.length();
                if v.is_finite() && length >= MIN_VIEW_LENGTH {
                    v / length
                } else {
                    bad.add(i);
                    Vec3::from(DEFAULT_VIEW)
                }
            })
            .collect();
        if bad.count > 0 {
            return Err(self.error(format!(
                "NaN/Inf or zero-length view vectors V at {} ({})",
                counted(bad.count, "pixel"),
                bad.first_at(self.width)
            )));
        }
        Ok(views)
    }

    /// Covered pixels whose normal faces away from their view vector shade black (the BRDF is
    /// zero there). A few are normal (bump and normal maps produce them) and get a warning; most
    /// of the image facing away means V points from the eye to the surface instead of from the
    /// surface to the eye, which is an error rather than a silently black render.
    fn facing(&mut self, normals: &[Vec3], views: &[Vec3], coverage: &[f32], view_given: bool) -> Result<()> {
        let mut away = Offenders::default();
        let mut covered = 0usize;
        for (i, ((n, v), &a)) in normals.iter().zip(views).zip(coverage).enumerate() {
            if a > 0.0 {
                covered += 1;
                if n.dot(*v) <= 0.0 {
                    away.add(i);
                }
            }
        }
        if away.count == 0 {
            return Ok(());
        }
        let summary = format!(
            "the normal faces away from the view vector V at {} of {covered} covered pixels ({})",
            counted(away.count, "pixel"),
            away.first_at(self.width)
        );
        // A quarter facing away is no grazing edge: the file is wrong, and a half-black render
        // must not pass. Say what would fix it.
        if away.count * 4 > covered {
            let share_away = |turn: &dyn Fn(Vec3, Vec3) -> (Vec3, Vec3)| {
                let turned = normals.iter().zip(views).zip(coverage).filter(|(_, &a)| a > 0.0);
                turned.filter(|((&n, &v), _)| turn(n, v).0.dot(turn(n, v).1) <= 0.0).count() as f32 / covered as f32
            };
            let z_up = |n: Vec3, v: Vec3| (Vec3::new(n.x, n.z, -n.y), v);
            let y_up = |n: Vec3, v: Vec3| (Vec3::new(n.x, -n.z, n.y), v);
            let fixed = |share: f32| format!("turned, {:.0}% would", share * 100.0);
            let hint = if !view_given && share_away(&z_up) < 0.05 {
                format!("the normals look Z-up ({} face away): pass --up z", fixed(share_away(&z_up)))
            } else if !view_given && share_away(&y_up) < 0.05 {
                format!("the normals look Y-up ({} face away): pass --up y", fixed(share_away(&y_up)))
            } else {
                "V must point from the surface toward the eye; is it the camera ray reversed?".to_string()
            };
            return Err(self.error(format!("{summary}: {hint}")));
        }
        self.warn(format!("{summary}; they shade black"));
        Ok(())
    }

    /// Stored tangents made orthogonal to N; degenerate ones take the stable frame. Only covered
    /// pixels are counted, since background tangents are commonly left at zero.
    fn tangents(&mut self, normals: &[Vec3], raw: &[Vec3], coverage: &[f32]) -> Vec<[f32; 3]> {
        let mut replaced = 0usize;
        let tangents = normals
            .iter()
            .zip(raw)
            .zip(coverage)
            .map(|((&n, &t), &a)| match orthogonalize(n, t) {
                Some(t) => t.to_array(),
                None => {
                    replaced += usize::from(a > 0.0);
                    stable_tangent(n.to_array())
                }
            })
            .collect();
        if replaced > 0 {
            self.warn(format!(
                "replaced {} (zero, NaN/Inf or parallel to N) with the stable frame",
                counted(replaced, "tangent")
            ));
        }
        tangents
    }

    /// Object IDs: uint samples as they are; half/float samples must hold non-negative integers.
    fn object_ids(&self, samples: &Samples) -> Result<Vec<u32>> {
        if let Samples::U32(ids) = samples {
            return Ok(ids.clone());
        }
        let mut bad = Offenders::default();
        let ids = to_f32(samples)
            .into_iter()
            .enumerate()
            .map(|(i, value)| {
                // An integral float in range converts exactly.
                if value >= 0.0 && value.fract() == 0.0 && f64::from(value) <= f64::from(u32::MAX) {
                    value as u32
                } else {
                    bad.add(i);
                    0
                }
            })
            .collect();
        if bad.count > 0 {
            return Err(self.error(format!(
                "channel {OBJECT_ID_CHANNEL} holds {} other than non-negative integers ({})",
                counted(bad.count, "value"),
                bad.first_at(self.width)
            )));
        }
        Ok(ids)
    }

    /// Every `<prefix><name>` channel (masks, maps), keyed by `<name>`, each in \[0,1\].
    fn prefixed(&mut self, channels: &BTreeMap<String, Samples>, prefix: &str) -> Result<BTreeMap<String, Vec<f32>>> {
        let mut found = BTreeMap::new();
        for (channel, samples) in channels {
            let Some(name) = channel.strip_prefix(prefix).filter(|name| !name.is_empty()) else {
                continue;
            };
            found.insert(name.to_string(), self.unit_interval(channel, samples)?);
        }
        Ok(found)
    }

    /// The `visibility.<word>` channels: none, or uint words 0 to K − 1 for a grid of K words a
    /// pixel (docs/formats.md#visibility).
    fn visibility(&self, channels: &BTreeMap<String, Samples>) -> Result<Option<Visibility>> {
        let mut words: BTreeMap<usize, &[u32]> = BTreeMap::new();
        for (channel, samples) in channels {
            let Some(index) = channel.strip_prefix(VISIBILITY_PREFIX) else {
                continue;
            };
            let index = index.parse::<usize>().ok().filter(|i| i.to_string() == index).ok_or_else(|| {
                self.error(format!(
                    "channel {channel}: a visibility channel is named by its word's index, as {VISIBILITY_PREFIX}0"
                ))
            })?;
            let Samples::U32(values) = samples else {
                return Err(self.error(format!(
                    "channel {channel} is not uint: visibility words hold 32 bits, which half and float samples cannot"
                )));
            };
            words.insert(index, values);
        }
        if words.is_empty() {
            return Ok(None);
        }
        let count = words.len();
        let grid = Grid::from_words(count).filter(|_| words.keys().copied().eq(0..count)).ok_or_else(|| {
            let sides = visibility::SIDES.map(|side| Grid::new(side).expect("a listed side").words().to_string());
            self.error(format!(
                "visibility channels {VISIBILITY_PREFIX}0 to {VISIBILITY_PREFIX}K-1 with K = {} are needed \
                     (grids {} cells a side); found {count} with indices {}",
                sides.join(", "),
                visibility::side_list(),
                words.keys().map(usize::to_string).collect::<Vec<_>>().join(", ")
            ))
        })?;
        let pixels = words[&0].len();
        let mut bits = vec![0u32; pixels * count];
        for (word, values) in words.values().enumerate() {
            for (pixel, &value) in values.iter().enumerate() {
                bits[pixel * count + word] = value;
            }
        }
        Ok(Some(Visibility { grid, words: bits }))
    }

    /// Object names from `objectName.<ID>` text attributes; malformed ones are skipped.
    fn object_names(&mut self, attributes: &[(String, Option<String>)]) -> BTreeMap<u32, String> {
        let mut names = BTreeMap::new();
        for (attribute, value) in attributes {
            let id = attribute.strip_prefix(OBJECT_NAME_PREFIX).and_then(|id| id.parse::<u32>().ok());
            let problem = match (id, value) {
                (Some(id), Some(name)) => {
                    names.insert(id, name.clone());
                    continue;
                }
                (None, _) => "the text after objectName. is not a non-negative integer ID",
                (Some(_), None) => "it is not a text attribute",
            };
            self.warn(format!("ignored header attribute {attribute}: {problem}"));
        }
        names
    }
}

/// Coverage for a file without `A`: 1 unless the normal is clearly empty. A NaN normal is not
/// clearly empty, so it counts as covered and is then reported rather than silently dropped.
fn default_coverage(n: Vec3) -> f32 {
    if n.length() <= MIN_NORMAL_LENGTH {
        0.0
    } else {
        1.0
    }
}

/// "1 pixel", "2 pixels".
fn counted(count: usize, noun: &str) -> String {
    if count == 1 {
        format!("1 {noun}")
    } else {
        format!("{count} {noun}s")
    }
}

/// The pixels that failed one check: how many, and the first in row-major order.
#[derive(Default)]
struct Offenders {
    count: usize,
    first: Option<usize>,
}

impl Offenders {
    fn add(&mut self, index: usize) {
        self.count += 1;
        self.first.get_or_insert(index);
    }

    fn first_at(&self, width: usize) -> String {
        match self.first {
            Some(i) => format!("first at x={}, y={}", i % width, i / width),
            None => "none".to_string(),
        }
    }
}

/// Three channels known to exist, zipped into vectors.
fn triple(raw: &RawImage, names: [&str; 3]) -> Vec<Vec3> {
    let [x, y, z] = names.map(|name| raw.channels.get(name).map(to_f32).unwrap_or_default());
    x.into_iter().zip(y).zip(z).map(|((x, y), z)| Vec3::new(x, y, z)).collect()
}

fn to_f32(samples: &Samples) -> Vec<f32> {
    samples.to_f32()
}

/// Whether the g-buffer reads this channel (the rest are ignored).
fn is_gbuffer_channel(name: &str) -> bool {
    [NORMAL_CHANNELS, VIEW_CHANNELS, TANGENT_CHANNELS].iter().any(|triple| triple.contains(&name))
        || name == COVERAGE_CHANNEL
        || name == OBJECT_ID_CHANNEL
        || name.starts_with(MASK_PREFIX)
        || name.starts_with(MAP_PREFIX)
        || name.starts_with(VISIBILITY_PREFIX)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raw(width: usize, height: usize, channels: Vec<(&str, Samples)>) -> RawImage {
        RawImage {
            width,
            height,
            channels: channels.into_iter().map(|(name, samples)| (name.to_string(), samples)).collect(),
            object_name_attributes: Vec::new(),
            mask_names: BTreeMap::new(),
            surfaces: Default::default(),
            supersample: None,
            filtered_normals: false,
        }
    }

    fn normals(pixels: usize) -> Vec<(&'static str, Samples)> {
        vec![
            ("N.X", Samples::F32(vec![0.0; pixels])),
            ("N.Y", Samples::F32(vec![0.0; pixels])),
            ("N.Z", Samples::F32(vec![1.0; pixels])),
        ]
    }

    fn error_of(raw: RawImage) -> String {
        match build(Path::new("g.exr"), raw) {
            Ok(_) => panic!("accepted"),
            Err(e) => e.to_string(),
        }
    }

    // The exr crate never hands over an empty layer (it swaps inverted window corners), so the
    // check is exercised here directly.
    #[test]
    fn empty_images_are_refused() {
        assert_eq!(error_of(raw(0, 4, normals(0))), "g.exr: empty image (0x4 pixels)");
    }

    #[test]
    fn subsampled_gbuffer_channels_are_refused_and_others_ignored() {
        let mut channels = normals(4);
        channels.push(("mask.a", Samples::F32(vec![0.0; 1])));
        let message = error_of(raw(2, 2, channels));
        assert!(message.contains("channel mask.a has 1 samples for 2x2 pixels"), "{message}");

        let mut channels = normals(4);
        channels.push(("map.rough", Samples::F32(vec![0.0; 2])));
        let message = error_of(raw(2, 2, channels));
        assert!(message.contains("channel map.rough has 2 samples for 2x2 pixels"), "{message}");

        let mut channels = normals(4);
        channels.push(("RY", Samples::F32(vec![0.0; 1])));
        assert!(build(Path::new("g.exr"), raw(2, 2, channels)).is_ok());
    }

    /// Three pixels in a row, all covered, the middle one's normal all but cancelled.
    fn short_middle_normal(ids: [u32; 3]) -> RawImage {
        raw(
            3,
            1,
            vec![
                ("N.X", Samples::F32(vec![0.6, 0.0, 0.0])),
                ("N.Y", Samples::F32(vec![0.0, 0.0, 0.6])),
                ("N.Z", Samples::F32(vec![0.8, 0.1, 0.8])),
                ("A", Samples::F32(vec![1.0; 3])),
                ("objectId", Samples::U32(ids.to_vec())),
            ],
        )
    }

    #[test]
    fn short_normals_where_objects_meet_take_their_own_objects_neighbours() {
        let (g, warnings) = build(Path::new("g.exr"), short_middle_normal([1, 2, 2])).unwrap();
        assert_eq!(g.normal[1], [0.0, 0.6, 0.8], "the neighbour of its own object, object 2");
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        assert!(warnings[0].contains("1 normal shorter than 0.5 where objects meet"), "{}", warnings[0]);
        let (g, _) = build(Path::new("g.exr"), short_middle_normal([1, 3, 2])).unwrap();
        assert_eq!(g.normal[1], [0.6, 0.0, 0.8], "no neighbour of its own object: the first covered one");
    }

    #[test]
    fn short_normals_inside_one_object_stay_errors() {
        let message = error_of(short_middle_normal([2, 2, 2]));
        assert!(
            message.contains("normals shorter than 0.5 where coverage A > 0, at 1 pixel (first at x=1, y=0)"),
            "{message}"
        );
    }

    /// A renderer's filtered pass averages a crease's or a thin part's two sides inside one
    /// object (DamagedHelmet rendered by Blender at 320×240 has two such pixels): they take a
    /// neighbour's normal too; a pixel with no usable neighbour stays an error.
    #[test]
    fn short_normals_of_a_filtered_pass_take_a_neighbours_inside_one_object_too() {
        let mut raw = short_middle_normal([2, 2, 2]);
        raw.filtered_normals = true;
        let (g, warnings) = build(Path::new("g.exr"), raw).unwrap();
        assert_eq!(g.normal[1], [0.6, 0.0, 0.8]);
        assert!(warnings[0].contains("1 normal shorter than 0.5 at edges, creases or thin parts"), "{}", warnings[0]);
        let mut raw = short_middle_normal([2, 2, 2]);
        raw.filtered_normals = true;
        for axis in ["N.X", "N.Y", "N.Z"] {
            raw.channels.insert(axis.into(), Samples::F32(vec![0.0, 0.0, 0.1]));
        }
        assert!(error_of(raw).contains("normals shorter than 0.5 where coverage A > 0, at 3 pixels"));
    }

    #[test]
    fn object_ids_beyond_u32_are_refused() {
        let mut channels = normals(2);
        channels.push(("objectId", Samples::F32(vec![7.0, 5e9])));
        let message = error_of(raw(2, 1, channels));
        assert!(message.contains("objectId holds 1 value other than non-negative integers"), "{message}");
        assert!(message.contains("first at x=1, y=0"), "{message}");
    }

    #[test]
    fn counts_are_worded_for_one_and_many() {
        assert_eq!(counted(1, "pixel"), "1 pixel");
        assert_eq!(counted(0, "pixel"), "0 pixels");
        assert_eq!(counted(3, "covered pixel"), "3 covered pixels");
    }
}
