//! Reading `.exr` and `.hdr` environments, with the checks of docs/formats.md.

use super::Environment;
use super::MAX_TEXEL;
use crate::input::exr::Budget;
use crate::input::{self, Kind};
use crate::{Error, Result};
use std::path::Path;

/// What to tolerate in an environment file.
#[derive(Clone, Copy, Debug, Default)]
pub struct LoadOptions {
    /// Accept a map that is not 2:1 (it is still read as equirectangular).
    pub any_aspect: bool,
    /// Replace NaN and negative texels with 0, +Inf with the largest valid value, and texels
    /// brighter than [`MAX_TEXEL`] with it, instead of refusing the file.
    pub clamp_invalid: bool,
}

/// Reads an environment, choosing the format by extension.
pub fn load(path: &Path, options: &LoadOptions) -> Result<Environment> {
    let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let name = path.display().to_string();
    match extension.as_deref() {
        Some("exr") => {
            // A file's decoded texels are cached by content, as its sampling tables are.
            let bytes = input::read(path, Kind::Environment)?;
            let texels = super::cache::file_texels(&bytes, &name, || read_exr_texels(&bytes, &name))?;
            exr_environment(&bytes, texels, &name, options)
        }
        Some("hdr") => from_hdr_bytes(&input::read(path, Kind::Environment)?, &name, options),
        _ => {
            input::check_regular(path)?;
            Err(Error::input_file(path, "unsupported environment format: use an equirectangular .exr or .hdr"))
        }
    }
}

/// The most an environment's pixels may take decoded: 16384×8192 RGB in half floats, with room
/// for an alpha channel.
const MAX_DECODED_BYTES: u64 = 2 << 30;

/// The size limits of an environment image, before decoding.
const BUDGET: Budget = Budget { max_side: input::exr::MAX_SIDE, max_decoded_bytes: MAX_DECODED_BYTES };

pub fn from_exr_bytes(bytes: &[u8], name: &str, options: &LoadOptions) -> Result<Environment> {
    exr_environment(bytes, read_exr_texels(bytes, name)?, name, options)
}

/// An EXR file's environment from its decoded texels.
fn exr_environment(
    bytes: &[u8],
    (width, height, texels): (u32, u32, Vec<[f32; 3]>),
    name: &str,
    options: &LoadOptions,
) -> Result<Environment> {
    validate(width, height, texels, name, options, super::content_hash(bytes))
}

/// The RGB texels of an EXR (a Y-only file is read as grey), before any checks.
pub fn read_exr_texels(bytes: &[u8], name: &str) -> Result<(u32, u32, Vec<[f32; 3]>)> {
    use exr::prelude::{read, ReadChannels, ReadLayers};
    input::exr::check(bytes, &BUDGET).map_err(|problem| Error::input_file(name, problem))?;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| Error::input_file(name, format!("not a readable OpenEXR file ({e})")))?;
    let layer = &image.layer_data;
    let (width, height) = (layer.size.width(), layer.size.height());
    let channels = &layer.channel_data.list;
    // A channel named exactly `R`, else the only one ending in `.R` (one layer of a multi-layer
    // file); several candidates are ambiguous and refused.
    let mut ambiguous = None;
    let mut find = |wanted: &str| {
        if let Some(exact) = channels.iter().find(|c| c.name.to_string() == wanted) {
            return Some(exact);
        }
        let suffixed: Vec<_> =
            channels.iter().filter(|c| c.name.to_string().ends_with(&format!(".{wanted}"))).collect();
        if suffixed.len() > 1 {
            ambiguous = Some(suffixed.iter().map(|c| c.name.to_string()).collect::<Vec<_>>().join(", "));
        }
        (suffixed.len() == 1).then(|| suffixed[0])
    };
    let (r, g, b, y) = (find("R"), find("G"), find("B"), find("Y"));
    if let Some(names) = ambiguous {
        return Err(Error::input_file(name, format!("several layers could be the radiance ({names}); keep one")));
    }
    let expected = width * height;
    if let Some(short) = channels.iter().find(|c| c.sample_data.len() != expected) {
        return Err(Error::input_file(name, format!("channel {} has the wrong number of samples", short.name)));
    }
    let planes: Vec<Vec<f32>> = match (r, g, b, y) {
        (Some(r), Some(g), Some(b), _) => [r, g, b].iter().map(|c| c.sample_data.values_as_f32().collect()).collect(),
        (_, _, _, Some(y)) => {
            let grey: Vec<f32> = y.sample_data.values_as_f32().collect();
            vec![grey.clone(), grey.clone(), grey]
        }
        _ => {
            let found: Vec<String> = channels.iter().map(|c| c.name.to_string()).collect();
            return Err(Error::input_file(
                name,
                format!("an environment needs R, G and B channels (or Y); found {}", found.join(", ")),
            ));
        }
    };
    let texels = (0..width * height).map(|i| [planes[0][i], planes[1][i], planes[2][i]]).collect();
    Ok((width as u32, height as u32, texels))
}

pub fn from_hdr_bytes(bytes: &[u8], name: &str, options: &LoadOptions) -> Result<Environment> {
    let unreadable = |e: image::ImageError| Error::input_file(name, format!("not a readable Radiance .hdr file ({e})"));
    let decoder = image::codecs::hdr::HdrDecoder::new(bytes).map_err(unreadable)?;
    check_hdr_size(image::ImageDecoder::dimensions(&decoder), bytes.len() as u64)
        .map_err(|problem| Error::input_file(name, problem))?;
    let decoded = image::DynamicImage::from_decoder(decoder).map_err(unreadable)?.into_rgb32f();
    let (width, height) = decoded.dimensions();
    let texels = decoded.pixels().map(|p| p.0).collect();
    validate(width, height, texels, name, options, super::content_hash(bytes))
}

/// Refuses a Radiance header whose size the file cannot hold, before the decoder allocates it.
/// Run-length encoded scan lines store at most 127 equal bytes in 2, so each 4-byte texel takes
/// at least 4·2/127 bytes of the file.
fn check_hdr_size((width, height): (u32, u32), file_bytes: u64) -> std::result::Result<(), String> {
    let side = BUDGET.max_side as u32;
    if width > side || height > side {
        return Err(format!(
            "the header declares {width}x{height} pixels, larger than the {side} pixels a side lookdev accepts"
        ));
    }
    let texels = width as u64 * height as u64;
    if texels * 4 * 2 / 127 > file_bytes {
        return Err(format!(
            "the header declares {width}x{height} pixels, more than a file of {} can hold: the file is truncated or its header is damaged",
            input::size_text(file_bytes)
        ));
    }
    Ok(())
}

/// Checks the shape and the texels, fixing them only when the options allow. `content_hash` is
/// the file's ([`super::content_hash`] of its bytes).
pub fn validate(
    width: u32,
    height: u32,
    mut texels: Vec<[f32; 3]>,
    name: &str,
    options: &LoadOptions,
    content_hash: u64,
) -> Result<Environment> {
    if width == 0 || height == 0 {
        return Err(Error::input_file(name, "the environment is empty"));
    }
    if width != 2 * height && !options.any_aspect {
        return Err(Error::input_file(
            name,
            format!("the environment is {width}x{height}, not 2:1 as an equirectangular map must be (--env-any-aspect reads it anyway)"),
        ));
    }
    let bad = |v: f32| !(0.0..=MAX_TEXEL).contains(&v);
    // One pass that counts the texels with a NaN, an infinite, a negative and a too bright
    // value, and finds the largest value that is none of those (what an infinity becomes):
    // start-up reads every texel of a map here, so one plain loop rather than five.
    let (mut nan, mut inf, mut negative, mut too_bright, mut largest) = (0, 0, 0, 0, 0.0f32);
    for texel in &texels {
        nan += texel.iter().any(|v| v.is_nan()) as usize;
        inf += texel.iter().any(|v| v.is_infinite()) as usize;
        negative += texel.iter().any(|&v| v < 0.0) as usize;
        too_bright += texel.iter().any(|&v| v.is_finite() && v > MAX_TEXEL) as usize;
        largest = texel.iter().copied().filter(|&v| !bad(v)).fold(largest, f32::max);
    }
    if nan + inf + negative + too_bright > 0 {
        let mut summary = format!("{nan} NaN, {inf} infinite and {negative} negative texels");
        if too_bright > 0 {
            summary.push_str(&format!(", and {too_bright} brighter than {MAX_TEXEL:e}, the most lookdev accepts"));
        }
        if !options.clamp_invalid {
            return Err(Error::input_file(name, format!("the environment has {summary} (--env-clamp replaces them)")));
        }
        for texel in &mut texels {
            for v in texel.iter_mut().filter(|v| bad(**v)) {
                *v = match *v {
                    v if v.is_nan() || v < 0.0 => 0.0,
                    f32::INFINITY => largest,
                    _ => MAX_TEXEL,
                };
            }
        }
        crate::warn(format!("{name}: clamped {summary}"));
    }
    Ok(Environment { width, height, texels, source: name.to_string(), content_hash })
}
