//! Writing a g-buffer file, in the format that `read` accepts.

use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, AttributeValue, Blocks, Compression, Encoding, FlatSamples, Image, Layer, LayerAttributes,
    LineOrder, SmallVec, Text, WritableImage,
};
use half::f16;

use super::{
    GBuffer, COVERAGE_CHANNEL, MAP_PREFIX, MASK_NAME_PREFIX, MASK_PREFIX, NORMAL_CHANNELS, OBJECT_ID_CHANNEL,
    OBJECT_NAME_PREFIX, TANGENT_CHANNELS, VIEW_CHANNELS, VISIBILITY_PREFIX,
};
use crate::{Error, Result};

impl GBuffer {
    /// Writes the g-buffer as a single-part, ZIP-compressed EXR: `N.*` always, `V.*` if
    /// `has_view`, `T.*` if `has_tangent` (all float), `A`, masks and maps as half, `objectId` and
    /// the `visibility.<word>` channels as uint, and object names as `objectName.<ID>` attributes.
    ///
    /// The file appears atomically: it is written to a temporary file in the same folder, then
    /// renamed over `path`, so a reader never sees half a file.
    pub fn write(&self, path: &Path) -> Result<()> {
        crate::input::refuse_replacing_input(path)?;
        self.check_lengths(path)?;
        let image = Image::from_layer(self.to_layer());
        crate::atomic_file::write_with(path, true, |file| {
            image
                .write()
                .to_buffered(std::io::BufWriter::new(file))
                .map_err(|e| std::io::Error::other(format!("cannot encode the g-buffer ({e})")))
        })
    }

    /// The fields are public, so make sure they agree before the encoder indexes them.
    fn check_lengths(&self, path: &Path) -> Result<()> {
        let pixels = self.pixel_count();
        let mut lengths = vec![
            ("normal", self.normal.len()),
            ("view", self.view.len()),
            ("tangent", self.tangent.len()),
            ("coverage", self.coverage.len()),
            ("object_id", self.object_id.len()),
        ];
        lengths.extend(self.masks.iter().chain(&self.maps).map(|(name, values)| (name.as_str(), values.len())));
        if let Some(visibility) = &self.visibility {
            lengths.push(("visibility", visibility.words.len() / visibility.grid.words()));
        }
        if pixels == 0 {
            return Err(Error::io(path, "cannot write an empty g-buffer"));
        }
        match lengths.into_iter().find(|&(_, length)| length != pixels) {
            Some((name, length)) => Err(Error::io(
                path,
                format!(
                    "cannot write the g-buffer: {name} has {length} entries for {}x{} pixels",
                    self.width, self.height
                ),
            )),
            None => Ok(()),
        }
    }

    fn to_layer(&self) -> Layer<AnyChannels<FlatSamples>> {
        let mut channels: Vec<AnyChannel<FlatSamples>> = Vec::new();
        channels.extend(vector_channels(NORMAL_CHANNELS, &self.normal));
        if self.has_view {
            channels.extend(vector_channels(VIEW_CHANNELS, &self.view));
        }
        if self.has_tangent {
            channels.extend(vector_channels(TANGENT_CHANNELS, &self.tangent));
        }
        channels.push(half_channel(COVERAGE_CHANNEL, &self.coverage));
        channels.push(AnyChannel::new(text(OBJECT_ID_CHANNEL), FlatSamples::U32(self.object_id.clone())));
        for (name, mask) in &self.masks {
            channels.push(half_channel(&format!("{MASK_PREFIX}{name}"), mask));
        }
        for (name, map) in &self.maps {
            channels.push(half_channel(&format!("{MAP_PREFIX}{name}"), map));
        }
        if let Some(visibility) = &self.visibility {
            let words = visibility.grid.words();
            for word in 0..words {
                let samples = visibility.words.iter().skip(word).step_by(words).copied().collect();
                channels.push(AnyChannel::new(text(&format!("{VISIBILITY_PREFIX}{word}")), FlatSamples::U32(samples)));
            }
        }

        let mut attributes = LayerAttributes { software_name: Some(text("lookdev")), ..LayerAttributes::default() };
        for (id, name) in &self.object_names {
            attributes.other.insert(text(&format!("{OBJECT_NAME_PREFIX}{id}")), AttributeValue::Text(text(name)));
        }
        for (mask, name) in &self.mask_names {
            attributes.other.insert(text(&format!("{MASK_NAME_PREFIX}{mask}")), AttributeValue::Text(text(name)));
        }
        if self.supersample > 1 {
            let factor = AttributeValue::Text(text(&self.supersample.to_string()));
            attributes.other.insert(text(super::SUPERSAMPLE_ATTRIBUTE), factor);
        }

        let encoding =
            Encoding { compression: Compression::ZIP16, blocks: Blocks::ScanLines, line_order: LineOrder::Increasing };
        let size = (self.width as usize, self.height as usize);
        Layer::new(size, attributes, encoding, AnyChannels::sort(SmallVec::from_vec(channels)))
    }
}

/// Three float channels from a vector per pixel.
fn vector_channels(names: [&str; 3], vectors: &[[f32; 3]]) -> [AnyChannel<FlatSamples>; 3] {
    [0, 1, 2].map(|axis| {
        let samples = vectors.iter().map(|v| v[axis]).collect();
        AnyChannel::new(text(names[axis]), FlatSamples::F32(samples))
    })
}

/// A half-float channel: coverage, masks and maps (from 8-bit textures) need no more than 11 bits.
fn half_channel(name: &str, values: &[f32]) -> AnyChannel<FlatSamples> {
    AnyChannel::new(text(name), FlatSamples::F16(values.iter().map(|&v| f16::from_f32(v)).collect()))
}

/// EXR text from UTF-8, byte for byte (what `source::raw::text_to_string` decodes). The `exr` crate's
/// own conversion panics on characters outside Latin-1.
fn text(string: &str) -> Text {
    Text::from_slice_unchecked(string.as_bytes())
}
