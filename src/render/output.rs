//! Writing renders: EXR as linear radiance, PNG as display pixels (docs/formats.md#output).

use crate::{atomic_file, Error, Result};
use std::path::Path;

/// The image formats `--out` accepts, by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputFormat {
    Exr,
    Png,
}

impl OutputFormat {
    pub fn from_path(path: &Path) -> Result<OutputFormat> {
        match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("exr") => Ok(OutputFormat::Exr),
            Some("png") => Ok(OutputFormat::Png),
            _ => Err(Error::input_file(path, "the output must be a .png or an .exr file")),
        }
    }
}

/// Refuses to write an image with pixels that are not finite. Inputs are bounded so that none
/// can arise; if one does, no file is better than a file that poisons a composite.
pub fn check_finite(path: &Path, radiance: &[[f32; 4]]) -> Result<()> {
    let bad = radiance.iter().filter(|p| !p.iter().all(|v| v.is_finite())).count();
    if bad == 0 {
        return Ok(());
    }
    Err(Error::gpu(format!(
        "{}: not written: {bad} of {} pixels are not finite (NaN or infinite); this is a defect of lookdev, please report it",
        path.display(),
        radiance.len()
    )))
}

/// Writes linear radiance as a float RGBA EXR. With a background, alpha is 1; without, it is the
/// coverage and the colour is premultiplied by it, as compositors expect.
pub fn write_exr(path: &Path, width: u32, height: u32, radiance: &[[f32; 4]], background: bool) -> Result<()> {
    write_exr_with(path, width, height, radiance, background, Vec::new(), &[])
}

/// [`write_exr`], with AOV layers beside the beauty (`<layer>.R .G .B` or `.Y`) and text
/// header attributes (the render's [`Metadata`]).
pub fn write_exr_with(
    path: &Path,
    width: u32,
    height: u32,
    radiance: &[[f32; 4]],
    background: bool,
    layers: Vec<crate::render::aov::Layer>,
    attributes: &[(String, String)],
) -> Result<()> {
    use exr::prelude::{
        AnyChannel, AnyChannels, AttributeValue, Encoding, FlatSamples, Image, Layer, LayerAttributes, Text,
        WritableImage,
    };
    crate::input::refuse_replacing_input(path)?;
    check_finite(path, radiance)?;
    for layer in &layers {
        for (channel, values) in &layer.channels {
            if let Some(bad) = values.iter().position(|v| !v.is_finite()) {
                return Err(Error::gpu(format!(
                    "{}: not written: the AOV {}.{channel} is not finite at pixel {bad}; this is a defect of lookdev, please report it",
                    path.display(),
                    layer.name
                )));
            }
        }
    }
    let text = |s: &str| Text::from_slice_unchecked(s.as_bytes());
    // Colour and value channels are not perceptually linear (a hint to lossy codecs); alpha is,
    // as OpenEXR's own writers mark it.
    let channel = |name: &str, values: Vec<f32>| AnyChannel {
        quantize_linearly: name == "A",
        ..AnyChannel::new(text(name), FlatSamples::F32(values))
    };
    let beauty = ["R", "G", "B", "A"].iter().enumerate().map(|(k, name)| {
        channel(name, radiance.iter().map(|p| if k == 3 && background { 1.0 } else { p[k] }).collect())
    });
    // Moved, not copied: an image with every AOV is several times the beauty.
    let aovs = layers.into_iter().flat_map(|layer| {
        let name = layer.name;
        layer.channels.into_iter().map(move |(channel_name, values)| channel(&format!("{name}.{channel_name}"), values))
    });
    let channels: Vec<AnyChannel<FlatSamples>> = beauty.chain(aovs).collect();
    let mut layer_attributes = LayerAttributes { software_name: Some(text("lookdev")), ..LayerAttributes::default() };
    for (name, value) in attributes {
        layer_attributes.other.insert(text(name), AttributeValue::Text(text(value)));
    }
    let layer = Layer::new(
        (width as usize, height as usize),
        layer_attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels.into()),
    );
    let mut bytes = std::io::Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .to_buffered(&mut bytes)
        .map_err(|e| Error::io(path, format!("cannot encode the EXR ({e})")))?;
    let mut bytes = bytes.into_inner();
    sort_header_attributes(&mut bytes);
    atomic_file::write(path, &bytes)
}

/// Puts a single-part EXR's header attributes in name order, as OpenEXR's own writer does. The
/// encoder keeps them in a hash map, whose order changes from run to run; sorted, the same
/// render is the same file. The header keeps its length, so the offsets after it stay right.
fn sort_header_attributes(bytes: &mut [u8]) {
    const MULTIPART: u8 = 0x10; // bit 12 of the version field
    if bytes.len() < 8 || bytes[5] & MULTIPART != 0 {
        return;
    }
    let mut attributes: Vec<&[u8]> = Vec::new();
    let mut at = 8;
    // name\0 type\0 size (i32, little-endian) value, until an empty name.
    while at < bytes.len() && bytes[at] != 0 {
        let start = at;
        let mut strings = 0;
        while strings < 2 {
            match bytes[at..].iter().position(|&b| b == 0) {
                Some(end) => at += end + 1,
                None => return,
            }
            strings += 1;
        }
        let Some(size) = bytes.get(at..at + 4).map(|s| i32::from_le_bytes([s[0], s[1], s[2], s[3]])) else {
            return;
        };
        at += 4 + size.max(0) as usize;
        if at > bytes.len() {
            return;
        }
        attributes.push(&bytes[start..at]);
    }
    let name = |attribute: &[u8]| attribute.split(|&b| b == 0).next().unwrap_or_default().to_vec();
    attributes.sort_by_key(|a| name(a));
    let sorted: Vec<u8> = attributes.concat();
    bytes[8..8 + sorted.len()].copy_from_slice(&sorted);
}

/// How a render was made, written into every EXR it produces as text attributes named
/// `lookdev/<key>` (docs/formats.md#output).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Metadata {
    pub entries: Vec<(String, String)>,
}

impl Metadata {
    /// lookdev's version, the look as rendered (its TOML text, see
    /// [`crate::render::provenance`]) and the flags no look holds, the BRDF model, the seed,
    /// the samples per pixel, and the environment's file name and the hash of its content.
    pub fn of_render(
        look: &crate::material::Look,
        settings: &crate::render::settings::Settings,
        environment: &crate::environment::Environment,
        recorded: &crate::render::provenance::Recorded,
    ) -> Metadata {
        let rendered = crate::render::provenance::rendered_look(look, settings, recorded);
        let entries = [
            ("version", env!("CARGO_PKG_VERSION").to_string()),
            ("look", rendered.to_toml()),
            ("flags", recorded.flags.join(" ")),
            ("model", settings.model.label()),
            ("seed", settings.seed.to_string()),
            ("spp", settings.spp.to_string()),
            ("environment", environment.source.clone()),
            ("environmentHash", format!("{:016x}", environment.content_hash)),
        ];
        Metadata { entries: entries.into_iter().map(|(k, v)| (format!("lookdev/{k}"), v)).collect() }
    }
}

/// Writes display pixels (RGBA8, sRGB-encoded) as a PNG: RGB when opaque, RGBA otherwise.
pub fn write_png(path: &Path, width: u32, height: u32, rgba: &[u8], with_alpha: bool) -> Result<()> {
    crate::input::refuse_replacing_input(path)?;
    let mut bytes = std::io::Cursor::new(Vec::new());
    let encoded = if with_alpha {
        image::RgbaImage::from_raw(width, height, rgba.to_vec())
            .expect("buffer size matches")
            .write_to(&mut bytes, image::ImageFormat::Png)
    } else {
        let rgb: Vec<u8> = rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
        image::RgbImage::from_raw(width, height, rgb)
            .expect("buffer size matches")
            .write_to(&mut bytes, image::ImageFormat::Png)
    };
    encoded.map_err(|e| Error::io(path, format!("cannot encode the PNG ({e})")))?;
    atomic_file::write(path, bytes.get_ref())
}

/// Writes an RGBA8 image (a contact sheet, a wedge) as a PNG, atomically.
pub fn write_png_image(path: &Path, image: &image::RgbaImage) -> Result<()> {
    require_png(path)?;
    write_png(path, image.width(), image.height(), image.as_raw(), true)
}

/// Refuses an output path for a PNG-only image (a contact sheet, a wedge) that is not a `.png`:
/// checked before the renders, so that a wrong name costs nothing.
pub fn require_png(path: &Path) -> Result<()> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("png") => Ok(()),
        _ => Err(Error::input_file(path, "this image is written only as PNG: name the output FILE.png")),
    }
}
