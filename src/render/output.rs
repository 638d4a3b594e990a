//! Writing renders: EXR as linear radiance, PNG as display pixels (docs/formats.md: Output).

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
    use exr::prelude::{Encoding, Image, Layer, LayerAttributes, SpecificChannels, Vec2, WritableImage};
    check_finite(path, radiance)?;
    let pixel = |position: Vec2<usize>| {
        let p = radiance[position.y() * width as usize + position.x()];
        (p[0], p[1], p[2], if background { 1.0 } else { p[3] })
    };
    let channels = SpecificChannels::rgba(pixel);
    let layer =
        Layer::new((width as usize, height as usize), LayerAttributes::default(), Encoding::SMALL_LOSSLESS, channels);
    let mut bytes = std::io::Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .non_parallel()
        .to_buffered(&mut bytes)
        .map_err(|e| Error::io(path, format!("cannot encode the EXR ({e})")))?;
    atomic_file::write(path, bytes.get_ref())
}

/// Writes display pixels (RGBA8, sRGB-encoded) as a PNG: RGB when opaque, RGBA otherwise.
pub fn write_png(path: &Path, width: u32, height: u32, rgba: &[u8], with_alpha: bool) -> Result<()> {
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
    if OutputFormat::from_path(path)? != OutputFormat::Png {
        return Err(Error::input_file(path, "this output is a .png file"));
    }
    write_png(path, image.width(), image.height(), image.as_raw(), true)
}
