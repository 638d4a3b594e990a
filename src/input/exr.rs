//! OpenEXR headers, checked before any pixel is decoded.
//!
//! The decoder sizes its pixel buffers from the header's data window and channel list, so a
//! file of a few KiB can claim 100000×100000 pixels and have the allocation abort the process.
//! [`check`] reads only the header and refuses, before anything is allocated for pixels:
//!
//! - deep data, and images or tiles wider or taller than [`Budget::max_side`];
//! - pixel data larger than [`Budget::max_decoded_bytes`];
//! - pixel data that the file cannot hold: more than its size times the best ratio its
//!   compression can reach ([`max_ratio`]), or more chunks than the file has room for;
//! - DWAA and DWAB chunks whose own headers claim sections far larger than the chunk's pixels
//!   (the decoder sizes its buffers from those counters).

use exr::compression::Compression;
use exr::meta::attribute::{LevelMode, SampleType};
use exr::meta::{BlockDescription, MetaData};

/// Limits for one kind of image.
#[derive(Clone, Copy, Debug)]
pub struct Budget {
    /// The largest width or height. The GPU's own limit is checked again once the device is
    /// known; this bounds the arithmetic and the allocations before that.
    pub max_side: usize,
    /// The most bytes the decoded pixels of the channels read may take.
    pub max_decoded_bytes: u64,
}

/// The largest image side any Vulkan device lookdev runs on accepts (lavapipe and most GPUs
/// take 16384, some 32768).
pub const MAX_SIDE: usize = 32768;

/// The smallest a chunk can be: its offset-table entry, its y or tile coordinates, and its
/// data size.
const MIN_CHUNK_BYTES: u64 = 8 + 4 + 4;

/// What the header of an accepted file declares.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Declared {
    pub width: usize,
    pub height: usize,
    pub parts: usize,
    pub decoded_bytes: u64,
}

/// Checks the header of the OpenEXR file `bytes` against `budget` and against the file's own
/// size. Returns the problem, for the caller to prefix with the file's name.
pub fn check(bytes: &[u8], budget: &Budget) -> Result<Declared, String> {
    if let Some(code) = declared_compressions(bytes).into_iter().find(|&code| code > LAST_DECODED_COMPRESSION) {
        return Err(format!(
            "unsupported compression ({}): lookdev reads uncompressed, RLE, ZIPS, ZIP, PIZ, PXR24, B44, B44A, DWAA \
             and DWAB files; save it again with ZIP or PIZ",
            compression_name(code)
        ));
    }
    let meta = MetaData::read_from_buffered(bytes, false).map_err(|e| unreadable(&e))?;
    MetaData::validate(&meta.headers, false).map_err(|e| unreadable(&e))?;
    let file_bytes = bytes.len() as u64;
    let mut declared = Declared { width: 0, height: 0, parts: meta.headers.len(), decoded_bytes: 0 };
    let mut stored_bytes: u64 = 0;
    let mut chunks: u64 = 0;
    for header in &meta.headers {
        if header.deep {
            return Err("deep data is not supported".into());
        }
        let (width, height) = (header.layer_size.width(), header.layer_size.height());
        if width > budget.max_side || height > budget.max_side {
            return Err(format!(
                "the header declares {width}x{height} pixels, larger than the {} pixels a side lookdev accepts",
                budget.max_side
            ));
        }
        if let BlockDescription::Tiles(tiles) = header.blocks {
            let (tile_w, tile_h) = (tiles.tile_size.width(), tiles.tile_size.height());
            if tile_w == 0 || tile_h == 0 || tile_w > budget.max_side || tile_h > budget.max_side {
                return Err(format!("the header declares {tile_w}x{tile_h} tiles"));
            }
        }
        // Sides are bounded above, so none of these products can overflow.
        let bytes_per_pixel: u64 = header.channels.list.iter().map(|c| sample_bytes(c.sample_type)).sum();
        let largest_level = width as u64 * height as u64 * bytes_per_pixel;
        declared.width = declared.width.max(width);
        declared.height = declared.height.max(height);
        declared.decoded_bytes += largest_level;
        let all_levels = match header.blocks {
            BlockDescription::Tiles(tiles) if tiles.level_mode != LevelMode::Singular => {
                // Mip and rip levels at most double, respectively quadruple, the largest one.
                largest_level * if tiles.level_mode == LevelMode::MipMap { 2 } else { 4 }
            }
            _ => largest_level,
        };
        stored_bytes += all_levels.div_ceil(max_ratio(header.compression));
        chunks += header.chunk_count as u64;
    }
    if declared.decoded_bytes > budget.max_decoded_bytes {
        return Err(format!(
            "the header declares {} of pixel data ({}x{}), more than the {} lookdev decodes for one image",
            super::size_text(declared.decoded_bytes),
            declared.width,
            declared.height,
            super::size_text(budget.max_decoded_bytes)
        ));
    }
    if meta.headers.iter().any(|h| matches!(h.compression, Compression::DWAA(_) | Compression::DWAB(_))) {
        check_dwa_chunks(bytes)?;
    }
    if stored_bytes > file_bytes || chunks.saturating_mul(MIN_CHUNK_BYTES) > file_bytes {
        return Err(format!(
            "the header declares {} of pixel data ({}x{}) in {chunks} chunks, more than a file of {} can hold: \
             the file is truncated or its header is damaged",
            super::size_text(declared.decoded_bytes),
            declared.width,
            declared.height,
            super::size_text(file_bytes)
        ));
    }
    Ok(declared)
}

/// The counters at the start of a DWA chunk that size the decoder's buffers: the unknown,
/// AC, DC and RLE sections' byte sizes and coefficient counts (OpenEXR's DwaCompressor layout:
/// eleven little-endian u64, the version first and the AC coder last).
const DWA_SIZE_COUNTERS: std::ops::Range<usize> = 1..10;

/// How much larger than its block's decoded pixels a DWA section may claim to be: a block of
/// one 8×8 DCT block per two-byte sample, padded at the edges, is the worst real case (32).
const DWA_SECTION_RATIO: u64 = 64;

/// Reads every chunk of a DWA file and checks the counters in its header against the size of
/// the pixels it holds, before the decoder allocates from them.
fn check_dwa_chunks(bytes: &[u8]) -> Result<(), String> {
    use exr::block::chunk::CompressedBlock;
    let reader = exr::block::read(std::io::Cursor::new(bytes), false).map_err(|e| unreadable(&e))?;
    let headers = reader.headers().to_vec();
    for chunk in reader.all_chunks(false).map_err(|e| unreadable(&e))? {
        let chunk = chunk.map_err(|e| unreadable(&e))?;
        let header = headers.get(chunk.layer_index).ok_or("a chunk names a part the file does not have")?;
        if !matches!(header.compression, Compression::DWAA(_) | Compression::DWAB(_)) {
            continue;
        }
        let data = match &chunk.compressed_block {
            CompressedBlock::ScanLine(block) => &block.compressed_pixels_le,
            CompressedBlock::Tile(block) => &block.compressed_pixels_le,
            _ => continue,
        };
        let block = header
            .get_block_data_indices(&chunk.compressed_block)
            .and_then(|tile| header.get_absolute_block_pixel_coordinates(tile))
            .map_err(|e| unreadable(&e))?;
        let bytes_per_pixel: u64 = header.channels.list.iter().map(|c| sample_bytes(c.sample_type)).sum();
        let pixels = block.size.width() as u64 * block.size.height() as u64 * bytes_per_pixel;
        let limit = pixels * DWA_SECTION_RATIO + (64 << 10);
        // A chunk stored uncompressed (as small ones are) has no DWA header.
        if data.len() as u64 == pixels || data.len() < 88 {
            continue;
        }
        for counter in DWA_SIZE_COUNTERS {
            let value = u64::from_le_bytes(data[counter * 8..counter * 8 + 8].try_into().expect("8 bytes"));
            if value > limit {
                return Err(format!(
                    "a DWA chunk claims a section of {value} bytes for {} of pixels: the file is damaged",
                    super::size_text(pixels)
                ));
            }
        }
    }
    Ok(())
}

/// An upper bound on decoded bytes per stored byte for a compression: 1 for none, 64 for RLE
/// (a run of 128 bytes in 2), about 1032 for the zlib-based methods and PIZ's Huffman coder with
/// run-length codes, 11 for B44 (a flat 4×4 block of halves in 3 bytes). DWA and HTJ2K can in
/// principle reach more on constant images; 2048 is far beyond what real images reach (a
/// constant 4096×2048 image compresses about 135:1 with DWAB, real environments about 30:1).
pub fn max_ratio(compression: Compression) -> u64 {
    match compression {
        Compression::Uncompressed => 1,
        Compression::RLE => 64,
        Compression::B44 | Compression::B44A => 11,
        Compression::ZIP1 | Compression::ZIP16 | Compression::PIZ => 1100,
        // 32-bit floats are cut to 24 bits before zlib.
        Compression::PXR24 => 1500,
        Compression::DWAA(_) | Compression::DWAB(_) | Compression::HTJ2K32 | Compression::HTJ2K256 => 2048,
    }
}

fn sample_bytes(sample: SampleType) -> u64 {
    sample.bytes_per_sample() as u64
}

/// The highest OpenEXR compression code the reader decodes (DWAB).
const LAST_DECODED_COMPRESSION: u8 = 9;

/// The names OpenEXR gives the compression codes after the ones lookdev decodes.
fn compression_name(code: u8) -> String {
    match code {
        10 => "HTJ2K256".into(),
        11 => "HTJ2K32".into(),
        _ => format!("code {code}, newer than lookdev's reader knows, such as ZSTD"),
    }
}

/// The `compression` attribute of every header of the file, read straight from the bytes: the
/// decoder refuses a code it does not know with a message about a damaged attribute, when the
/// file is valid and only newer than the reader. Stops quietly at anything malformed, which the
/// decoder then reports.
fn declared_compressions(bytes: &[u8]) -> Vec<u8> {
    const MULTIPART: u8 = 0x10;
    let mut codes = Vec::new();
    let Some(version) = bytes.get(4..8) else { return codes };
    let multipart = version[1] & MULTIPART != 0;
    let mut at = 8;
    let text = |at: &mut usize| -> Option<&[u8]> {
        let rest = bytes.get(*at..)?;
        let end = rest.iter().take(256).position(|&b| b == 0)?;
        *at += end + 1;
        Some(&rest[..end])
    };
    loop {
        let Some(name) = text(&mut at) else { return codes };
        if name.is_empty() {
            // A header ends with an empty name; a multi-part file's header list with an empty header.
            if !multipart || bytes.get(at) == Some(&0) {
                return codes;
            }
            continue;
        }
        let Some(kind) = text(&mut at) else { return codes };
        let Some(size) = bytes.get(at..at + 4).map(|b| i32::from_le_bytes(b.try_into().expect("4 bytes"))) else {
            return codes;
        };
        let Ok(size) = usize::try_from(size) else { return codes };
        at += 4;
        if name == b"compression" && kind == b"compression" && size == 1 {
            let Some(&code) = bytes.get(at) else { return codes };
            codes.push(code);
        }
        at = at.saturating_add(size);
    }
}

fn unreadable(e: &exr::error::Error) -> String {
    format!("not a readable OpenEXR file ({e})")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A minimal uncompressed scan-line file of `width`×`height` half RGB, with `data_bytes`
    /// of pixel data after the header (a real file has 6·width·height plus the chunk headers).
    fn file(width: i32, height: i32, data_bytes: usize) -> Vec<u8> {
        fn attribute(name: &str, kind: &str, data: &[u8]) -> Vec<u8> {
            let mut out = [name.as_bytes(), b"\0", kind.as_bytes(), b"\0"].concat();
            out.extend((data.len() as i32).to_le_bytes());
            out.extend(data);
            out
        }
        let window: Vec<u8> = [0, 0, width - 1, height - 1].iter().flat_map(|v: &i32| v.to_le_bytes()).collect();
        let mut channels = Vec::new();
        for name in ["B", "G", "R"] {
            channels.extend(name.as_bytes());
            channels.extend([0, 1, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0]);
        }
        channels.push(0);
        let mut bytes = vec![0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0];
        bytes.extend(attribute("channels", "chlist", &channels));
        bytes.extend(attribute("compression", "compression", &[0]));
        bytes.extend(attribute("dataWindow", "box2i", &window));
        bytes.extend(attribute("displayWindow", "box2i", &window));
        bytes.extend(attribute("lineOrder", "lineOrder", &[0]));
        bytes.extend(attribute("pixelAspectRatio", "float", &1f32.to_le_bytes()));
        bytes.extend(attribute("screenWindowCenter", "v2f", &[0; 8]));
        bytes.extend(attribute("screenWindowWidth", "float", &1f32.to_le_bytes()));
        bytes.push(0);
        bytes.resize(bytes.len() + data_bytes, 0);
        bytes
    }

    const BUDGET: Budget = Budget { max_side: MAX_SIDE, max_decoded_bytes: 1 << 30 };

    #[test]
    fn a_compression_newer_than_the_reader_is_named_as_unsupported() {
        let mut bytes = file(4, 4, 4 * 4 * 6 + 4 * 16);
        let at = bytes.windows(12).position(|w| w == b"compression\0").unwrap() + 12 + 12 + 4;
        for (code, name) in [(10, "HTJ2K256"), (12, "code 12, newer")] {
            bytes[at] = code;
            let message = check(&bytes, &BUDGET).unwrap_err();
            assert!(message.starts_with(&format!("unsupported compression ({name}")), "{message}");
        }
        bytes[at] = 3;
        if let Err(message) = check(&bytes, &BUDGET) {
            assert!(!message.contains("unsupported"), "{message}");
        }
    }

    #[test]
    fn a_header_that_fits_its_file_is_accepted() {
        let declared = check(&file(64, 32, 64 * 32 * 6 + 32 * 16), &BUDGET).unwrap();
        assert_eq!((declared.width, declared.height, declared.decoded_bytes), (64, 32, 64 * 32 * 6));
    }

    #[test]
    fn headers_claiming_more_than_the_file_holds_are_refused() {
        let message = check(&file(100_000, 100_000, 7000), &BUDGET).unwrap_err();
        assert!(message.contains("100000x100000 pixels, larger than the 32768"), "{message}");
        let message = check(&file(20_000, 20_000, 7000), &BUDGET).unwrap_err();
        assert!(message.contains("more than the 1.0 GiB lookdev decodes"), "{message}");
        let message = check(&file(4000, 4000, 7000), &BUDGET).unwrap_err();
        assert!(message.contains("more than a file of 7."), "{message}");
    }
}
