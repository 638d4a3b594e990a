//! An OpenEXR file as named channels and header attributes, independent of the `exr` crate's
//! types, before any source is detected or any channel judged.

use std::collections::BTreeMap;
use std::path::Path;

use exr::prelude::{AttributeValue, FlatSamples, ReadChannels, ReadLayers, Text};

use crate::input::exr::Budget;
use crate::{Error, Result};

/// One channel's samples, row-major, row 0 at the top. Half floats are widened to float.
#[derive(Clone, Debug, PartialEq)]
pub enum Samples {
    F32(Vec<f32>),
    U32(Vec<u32>),
}

impl Samples {
    pub fn len(&self) -> usize {
        match self {
            Samples::F32(v) => v.len(),
            Samples::U32(v) => v.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The samples as floats (unsigned integers converted).
    pub fn to_f32(&self) -> Vec<f32> {
        match self {
            Samples::F32(v) => v.clone(),
            Samples::U32(v) => v.iter().map(|&x| x as f32).collect(),
        }
    }

    /// The samples as floats, borrowed where they already are.
    pub fn as_f32(&self) -> std::borrow::Cow<'_, [f32]> {
        match self {
            Samples::F32(v) => std::borrow::Cow::Borrowed(v),
            Samples::U32(_) => std::borrow::Cow::Owned(self.to_f32()),
        }
    }
}

impl From<FlatSamples> for Samples {
    fn from(samples: FlatSamples) -> Samples {
        match samples {
            FlatSamples::F16(v) => Samples::F32(v.iter().map(|h| h.to_f32()).collect()),
            FlatSamples::F32(v) => Samples::F32(v),
            FlatSamples::U32(v) => Samples::U32(v),
        }
    }
}

/// One part of an OpenEXR file.
#[derive(Clone, Debug, Default)]
pub struct RawPart {
    /// The part's `name` attribute (multi-part files), if any.
    pub name: Option<String>,
    pub width: usize,
    pub height: usize,
    /// Channel name (as UTF-8) to samples.
    pub channels: BTreeMap<String, Samples>,
    /// Text attributes of the part and of the file, by name.
    pub text: BTreeMap<String, String>,
    /// 4×4 matrix attributes (`worldToCamera`, `worldToNDC`), rows as stored: OpenEXR's
    /// row-vector convention, so that a point is `p · M`.
    pub matrices: BTreeMap<String, [[f32; 4]; 4]>,
    /// Names of attributes that are neither text nor matrices, for messages.
    pub other_attributes: Vec<String>,
}

/// Every part of an OpenEXR file.
#[derive(Clone, Debug, Default)]
pub struct RawFile {
    pub parts: Vec<RawPart>,
}

/// The most a g-buffer's channels may take decoded: a 4K frame with forty float channels.
const MAX_DECODED_BYTES: u64 = 4 << 30;

/// Decodes every part of an OpenEXR file, after its header has been checked against the file
/// ([`crate::input::exr::check`]).
pub fn decode(bytes: &[u8], path: &Path) -> Result<RawFile> {
    let budget = Budget { max_side: crate::input::exr::MAX_SIDE, max_decoded_bytes: MAX_DECODED_BYTES };
    crate::input::exr::check(bytes, &budget).map_err(|problem| Error::input_file(path, problem))?;
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| Error::input_file(path, format!("not a readable OpenEXR file ({e})")))?;
    let file_attributes: Vec<(String, AttributeValue)> =
        image.attributes.other.iter().map(|(name, value)| (text_to_string(name), value.clone())).collect();
    let parts = image
        .layer_data
        .into_iter()
        .map(|layer| {
            let mut part = RawPart {
                name: layer.attributes.layer_name.as_ref().map(text_to_string),
                width: layer.size.0,
                height: layer.size.1,
                channels: layer
                    .channel_data
                    .list
                    .into_iter()
                    .map(|channel| (text_to_string(&channel.name), Samples::from(channel.sample_data)))
                    .collect(),
                ..RawPart::default()
            };
            let attributes = layer.attributes.other.iter().map(|(n, v)| (text_to_string(n), v.clone()));
            for (name, value) in file_attributes.iter().cloned().chain(attributes) {
                match value {
                    AttributeValue::Text(text) => {
                        part.text.insert(name, text_to_string(&text));
                    }
                    AttributeValue::Matrix4x4(m) => {
                        part.matrices.insert(name, rows(&m));
                    }
                    _ => part.other_attributes.push(name),
                }
            }
            // OpenEXR's standard attributes the exr crate reads into fields of its own.
            if let Some(m) = &layer.attributes.world_to_camera {
                part.matrices.insert("worldToCamera".into(), rows(m));
            }
            if let Some(m) = &layer.attributes.world_to_normalized_device {
                part.matrices.insert("worldToNDC".into(), rows(m));
            }
            part
        })
        .collect();
    Ok(RawFile { parts })
}

/// A stored 4×4 matrix as its four rows.
fn rows(m: &[f32; 16]) -> [[f32; 4]; 4] {
    [0, 1, 2, 3].map(|r| [0, 1, 2, 3].map(|c| m[r * 4 + c]))
}

/// EXR text is a byte string; OpenEXR's own library treats it as UTF-8, and so do we (the `exr`
/// crate's `Display` would read it as Latin-1 and garble non-ASCII names).
pub(crate) fn text_to_string(text: &Text) -> String {
    String::from_utf8_lossy(text.bytes()).into_owned()
}
