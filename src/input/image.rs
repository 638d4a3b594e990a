//! PNG and JPEG textures, decoded only after their headers are checked against their size.
//!
//! A decoder allocates the whole image from the header's width and height before it reads a
//! pixel, so a 100-byte file can claim 16384×16384 and cost a gigabyte. [`decode`] reads the
//! dimensions first and refuses an image wider or taller than the limit, or one whose pixels
//! cannot fit in the file at the best ratio its compression reaches.

use image::{DynamicImage, ImageReader, Limits};
use std::io::Cursor;

/// Decoded bytes per stored byte that no real PNG (deflate: at most about 1032) or JPEG (a flat
/// 8×8 block in a few bits, with chroma subsampling) exceeds.
const MAX_RATIO: u64 = 2048;

/// Small images need no ratio: their headers and palettes outweigh their pixels.
const SMALL_IMAGE_BYTES: u64 = 1 << 20;

/// Decodes a PNG or JPEG (or another format the `image` crate reads) of at most `max_side`
/// pixels a side. The error is the problem, worded to follow the image's label.
pub fn decode(bytes: &[u8], max_side: u32) -> Result<DynamicImage, String> {
    let reader = || ImageReader::new(Cursor::new(bytes)).with_guessed_format().map_err(|e| e.to_string());
    let (width, height) = reader()?.into_dimensions().map_err(|e| format!("cannot be decoded ({e})"))?;
    if width > max_side || height > max_side {
        return Err(format!("is {width}x{height}, larger than the {max_side} pixels a side lookdev decodes"));
    }
    let decoded_bytes = width as u64 * height as u64 * 4;
    if decoded_bytes > SMALL_IMAGE_BYTES.max(bytes.len() as u64 * MAX_RATIO) {
        return Err(format!(
            "declares {width}x{height} pixels, more than its {} bytes can hold: the file is truncated or damaged",
            bytes.len()
        ));
    }
    let mut reader = reader()?;
    let mut limits = Limits::default();
    limits.max_image_width = Some(max_side);
    limits.max_image_height = Some(max_side);
    // Room for 16 bits a channel, and the conversion to RGBA8 after.
    limits.max_alloc = Some(decoded_bytes * 3 + SMALL_IMAGE_BYTES);
    reader.limits(limits);
    reader.decode().map_err(|e| format!("cannot be decoded ({e})"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn png(width: u32, height: u32) -> Vec<u8> {
        let mut bytes = Cursor::new(Vec::new());
        image::RgbaImage::new(width, height).write_to(&mut bytes, image::ImageFormat::Png).unwrap();
        bytes.into_inner()
    }

    /// Rewrites a PNG's IHDR width and height, with the chunk's CRC to match.
    fn claim(mut png: Vec<u8>, width: u32, height: u32) -> Vec<u8> {
        png[16..20].copy_from_slice(&width.to_be_bytes());
        png[20..24].copy_from_slice(&height.to_be_bytes());
        // CRC-32 (IEEE, reflected) over the chunk type and data: bytes 12..29.
        let crc = !png[12..29].iter().fold(!0u32, |crc, &byte| {
            (0..8).fold(crc ^ byte as u32, |c, _| if c & 1 == 1 { (c >> 1) ^ 0xedb8_8320 } else { c >> 1 })
        });
        png[29..33].copy_from_slice(&crc.to_be_bytes());
        png
    }

    #[test]
    fn images_decode_within_their_limits() {
        assert_eq!(decode(&png(8, 4), 16).unwrap().width(), 8);
        let message = decode(&png(32, 4), 16).unwrap_err();
        assert!(message.contains("is 32x4, larger than the 16 pixels"), "{message}");
    }

    #[test]
    fn a_header_claiming_more_than_the_file_holds_is_refused_before_decoding() {
        let message = decode(&claim(png(8, 8), 16000, 16000), 16384).unwrap_err();
        assert!(message.contains("declares 16000x16000 pixels, more than its"), "{message}");
    }
}
