//! Reading a g-buffer file: OpenEXR decoding, then validation (in `validate`).

use std::collections::BTreeMap;
use std::path::Path;

use exr::prelude::{AttributeValue, FlatSamples, ReadChannels, ReadLayers, Text};

use super::validate::{self, RawImage};
use super::{GBuffer, MASK_NAME_PREFIX, OBJECT_NAME_PREFIX};
use crate::input::exr::Budget;
use crate::input::{self, Kind};
use crate::{Error, Result};

impl GBuffer {
    /// Reads and validates a g-buffer file, printing fix-up warnings to stderr.
    /// See the module documentation for the format, the errors and the fix-ups.
    pub fn read(path: &Path) -> Result<GBuffer> {
        let (gbuffer, warnings) = GBuffer::read_with_warnings(path)?;
        for warning in warnings {
            crate::warn(warning);
        }
        Ok(gbuffer)
    }

    /// Like [`GBuffer::read`], but returns the warnings (one line each, naming the file) instead
    /// of printing them, for callers that show them elsewhere.
    pub fn read_with_warnings(path: &Path) -> Result<(GBuffer, Vec<String>)> {
        GBuffer::decode(&input::read(path, Kind::GBuffer)?, path)
    }

    /// Decodes and validates the bytes of a g-buffer file; `path` names it in messages. Needs
    /// no GPU and touches no file.
    pub fn decode(bytes: &[u8], path: &Path) -> Result<(GBuffer, Vec<String>)> {
        let raw = decode_exr(bytes, path)?;
        validate::build(path, raw)
    }
}

/// The most a g-buffer's channels may take decoded: a 4K frame with forty float channels.
const MAX_DECODED_BYTES: u64 = 4 << 30;

/// Decodes the single part of an EXR file into named channels, without judging their contents.
fn decode_exr(bytes: &[u8], path: &Path) -> Result<RawImage> {
    let budget = Budget { max_side: input::exr::MAX_SIDE, max_decoded_bytes: MAX_DECODED_BYTES };
    input::exr::check(bytes, &budget).map_err(|problem| Error::input_file(path, problem))?;
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| Error::input_file(path, format!("not a readable OpenEXR file ({e})")))?;

    let part_count = image.layer_data.len();
    let mut parts = image.layer_data.into_iter();
    let (Some(layer), None) = (parts.next(), parts.next()) else {
        return Err(Error::input_file(
            path,
            format!("the file has {part_count} parts; only single-part g-buffers are supported"),
        ));
    };

    let channels: BTreeMap<String, FlatSamples> = layer
        .channel_data
        .list
        .into_iter()
        .map(|channel| (text_to_string(&channel.name), channel.sample_data))
        .collect();

    // Unknown attributes may land in either set, depending on their type.
    let attributes: Vec<(String, Option<String>)> = layer
        .attributes
        .other
        .iter()
        .chain(image.attributes.other.iter())
        .map(|(name, value)| (text_to_string(name), attribute_text(value)))
        .collect();
    let object_name_attributes =
        attributes.iter().filter(|(name, _)| name.starts_with(OBJECT_NAME_PREFIX)).cloned().collect();
    let mask_names = attributes
        .into_iter()
        .filter_map(|(name, value)| Some((name.strip_prefix(MASK_NAME_PREFIX)?.to_string(), value?)))
        .collect();

    Ok(RawImage { width: layer.size.0, height: layer.size.1, channels, object_name_attributes, mask_names })
}

/// The value of a text attribute, or `None` for any other type.
fn attribute_text(value: &AttributeValue) -> Option<String> {
    match value {
        AttributeValue::Text(text) => Some(text_to_string(text)),
        _ => None,
    }
}

/// EXR text is a byte string; OpenEXR's own library treats it as UTF-8, and so do we (the `exr`
/// crate's `Display` would read it as Latin-1 and garble non-ASCII names).
pub(crate) fn text_to_string(text: &Text) -> String {
    String::from_utf8_lossy(text.bytes()).into_owned()
}
