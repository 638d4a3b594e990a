//! Environments' sampling tables and the decoded built-in maps, kept in
//! `$XDG_CACHE_HOME/lookdev/environments/` (docs/formats.md#caches), so that a map's tables are
//! built once per content and the built-ins are decoded once per build.
//!
//! Tables are keyed by the map's content hash ([`Environment::content_hash`]: of its file, whose
//! texels it determines, or of the texels of a map made in memory), the map's size, the build's
//! parameters (the device's image limit, [`MAX_CELLS`]), [`TABLES_VERSION`] and a hash of the
//! source that builds them, so any change in how tables are built makes old entries unused
//! rather than wrong.
//! The tables are written and read field by field by [`encode_tables`] and [`decode_tables`],
//! which check every size before allocating; a file that fails any check is built again.

use super::distribution::{Distribution, Table, MAX_CELLS};
use super::{Environment, MAX_TEXEL};
use crate::cache::{self, Entry};
use std::path::PathBuf;

/// The version of the tables' file format *and* of how they are built: bump it whenever
/// [`Distribution`] gains a field (and [`encode_tables`] / [`decode_tables`] with it) or builds
/// different tables from the same map. (A change to distribution.rs also changes the key by
/// itself, through [`SOURCES`], but the bump says so on purpose.)
pub const TABLES_VERSION: u32 = 1;

/// The version of the decoded built-ins' format and decoding.
pub const BUILTIN_VERSION: u32 = 1;

/// The source files whose change must invalidate cached entries: what builds the tables, and
/// what decodes the built-ins (with the locked dependency versions, for the EXR decoder).
const SOURCES: [&str; 5] = [
    include_str!("distribution.rs"),
    include_str!("../shading/common.rs"),
    include_str!("load.rs"),
    include_str!("builtin.rs"),
    include_str!("../../Cargo.lock"),
];

const TABLES: Entry = Entry { kind: "envtable", version: TABLES_VERSION, max_payload: 512 << 20 };
const BUILTIN: Entry = Entry { kind: "envmap", version: BUILTIN_VERSION, max_payload: 64 << 20 };

/// The cache folder keeps at most this many bytes; the least recently used entries go first.
const FOLDER_BUDGET: u64 = 1 << 30;

fn folder() -> Option<PathBuf> {
    cache::folder("environments")
}

/// A hash of the sources in [`SOURCES`].
fn sources_hash() -> [u8; 16] {
    let hashes: Vec<u8> = SOURCES.iter().flat_map(|s| cache::hash128(s.as_bytes())).collect();
    cache::hash128(&hashes)
}

/// The sampling tables of `environment` for a device whose images are at most `max_image_side`
/// texels a side, MIS-compensated or not ([`Distribution::compensated_for_device`],
/// [`Distribution::for_device`]): from the cache when it holds them, else built and stored.
pub fn distribution(environment: &Environment, max_image_side: u32, compensated: bool) -> Distribution {
    let _timing = crate::timings::phase("environment tables");
    let mut key = Vec::new();
    // The content hash, not a hash of the texels: hashing 6 MB of a 1K map's texels took
    // 5-7 ms of every start-up, and the file's hash is known already.
    key.extend_from_slice(&environment.content_hash.to_le_bytes());
    for value in [environment.width, environment.height, max_image_side, MAX_CELLS] {
        key.extend_from_slice(&value.to_le_bytes());
    }
    key.push(compensated as u8);
    key.extend_from_slice(&sources_hash());
    let path = folder().map(|f| f.join(format!("{}.tables", cache::hex(&cache::hash128(&key)))));
    let cached = path.as_deref().and_then(|path| TABLES.load(path, &key)).and_then(|payload| {
        let decoded = decode_tables(&payload, environment.width, environment.height);
        if decoded.is_none() {
            crate::warn(format!(
                "ignoring the cache file {}: its tables are damaged or do not fit the map; they are made again",
                path_text(&path)
            ));
        }
        decoded
    });
    if let Some(distribution) = cached {
        crate::timings::note(|| format!("environment tables: loaded from {}", path_text(&path)));
        cache::touch(path.as_deref());
        return distribution;
    }
    let distribution = if compensated {
        Distribution::compensated_for_device(environment, max_image_side)
    } else {
        Distribution::for_device(environment, max_image_side)
    };
    if let Some(path) = &path {
        TABLES.store(path, &key, &encode_tables(&distribution));
        cache::prune(path, FOLDER_BUDGET);
    }
    distribution
}

fn path_text(path: &Option<PathBuf>) -> String {
    path.as_deref().map(|p| p.display().to_string()).unwrap_or_default()
}

/// A built-in environment named `name` whose embedded file hashes to `content_hash`, from the
/// cache when it holds it, else decoded by `decode` and stored. Cached texels are checked as a
/// file's are.
pub fn builtin(name: &str, content_hash: u64, decode: impl FnOnce() -> Environment) -> Environment {
    let _timing = crate::timings::phase("environment decode");
    let mut key = name.as_bytes().to_vec();
    key.extend_from_slice(&content_hash.to_le_bytes());
    key.extend_from_slice(&sources_hash());
    let path = folder().map(|f| f.join(format!("builtin-{name}-{}.texels", cache::hex(&cache::hash128(&key)))));
    let source = format!("built-in {name}");
    let cached = path.as_deref().and_then(|path| BUILTIN.load(path, &key)).and_then(|payload| {
        let (width, height, texels) = decode_texels(&payload)?;
        // What load::validate accepts without change, checked in one pass.
        let valid = width == 2 * height && texels.iter().flatten().all(|v| (0.0..=MAX_TEXEL).contains(v));
        valid.then(|| Environment { width, height, texels, source: source.clone(), content_hash })
    });
    if let Some(environment) = cached {
        crate::timings::note(|| format!("environment: {source} loaded from {}", path_text(&path)));
        cache::touch(path.as_deref());
        return environment;
    }
    let environment = decode();
    if let Some(path) = &path {
        BUILTIN.store(path, &key, &encode_texels(&environment));
        cache::prune(path, FOLDER_BUDGET);
    }
    environment
}

/// Little-endian words, read with every length checked against what is left.
struct Reader<'a> {
    bytes: &'a [u8],
}

impl Reader<'_> {
    fn u32(&mut self) -> Option<u32> {
        let (word, rest) = self.bytes.split_first_chunk::<4>()?;
        self.bytes = rest;
        Some(u32::from_le_bytes(*word))
    }

    /// `n` words, refused before allocating when fewer are left.
    fn words(&mut self, n: usize) -> Option<Vec<u32>> {
        if n > self.bytes.len() / 4 {
            return None;
        }
        let (words, rest) = self.bytes.split_at(4 * n);
        self.bytes = rest;
        Some(words.chunks_exact(4).map(|w| u32::from_le_bytes(w.try_into().expect("4 bytes"))).collect())
    }

    fn floats(&mut self, n: usize) -> Option<Vec<f32>> {
        Some(self.words(n)?.into_iter().map(f32::from_bits).collect())
    }
}

fn put(out: &mut Vec<u8>, words: impl IntoIterator<Item = u32>) {
    for word in words {
        out.extend_from_slice(&word.to_le_bytes());
    }
}

fn put_table(out: &mut Vec<u8>, table: &Table) {
    put(out, [table.len() as u32]);
    put(out, table.cdf.iter().map(|c| c.to_bits()));
    put(out, table.guide.iter().copied());
}

/// The tables as bytes: the sizes, the marginal table, each row's conditional table, the cell
/// pdfs. [`decode_tables`] reads exactly this back.
pub fn encode_tables(d: &Distribution) -> Vec<u8> {
    let mut out = Vec::new();
    put(&mut out, [d.width, d.height, d.block_x, d.block_y, d.columns, d.rows]);
    put_table(&mut out, &d.marginal);
    for table in &d.conditional {
        put_table(&mut out, table);
    }
    put(&mut out, d.cell_pdf.iter().map(|p| p.to_bits()));
    out
}

/// A table of `n` intervals, checked as strictly as one built from a map: a CDF from exactly 0
/// to exactly 1 that never decreases, and the very guides that CDF gives.
fn read_table(reader: &mut Reader, n: u32) -> Option<Table> {
    if reader.u32()? != n {
        return None;
    }
    let cdf = reader.floats(n as usize + 1)?;
    let guide = reader.words(n as usize + 1)?;
    Table::from_cdf(cdf).filter(|table| table.guide == guide)
}

/// The tables [`encode_tables`] wrote, if they are whole and fit a map of `width`×`height`.
pub fn decode_tables(bytes: &[u8], width: u32, height: u32) -> Option<Distribution> {
    let mut reader = Reader { bytes };
    let [w, h, block_x, block_y, columns, rows] = [(); 6].map(|()| reader.u32());
    let (w, h, block_x, block_y, columns, rows) = (w?, h?, block_x?, block_y?, columns?, rows?);
    let fits = w == width
        && h == height
        && block_x > 0
        && block_y > 0
        && columns == width.div_ceil(block_x)
        && rows == height.div_ceil(block_y)
        && columns.max(rows) <= MAX_CELLS;
    if !fits {
        return None;
    }
    let marginal = read_table(&mut reader, rows)?;
    let conditional = (0..rows).map(|_| read_table(&mut reader, columns)).collect::<Option<Vec<_>>>()?;
    let cell_pdf = reader.floats((rows * columns) as usize)?;
    if !cell_pdf.iter().all(|p| p.is_finite() && *p >= 0.0) {
        return None;
    }
    reader.bytes.is_empty().then_some(Distribution {
        width,
        height,
        block_x,
        block_y,
        columns,
        rows,
        marginal,
        conditional,
        cell_pdf,
    })
}

/// A decoded map as bytes: its size, then its RGB texels.
fn encode_texels(environment: &Environment) -> Vec<u8> {
    let mut out = Vec::with_capacity(8 + 12 * environment.texels.len());
    put(&mut out, [environment.width, environment.height]);
    if cfg!(target_endian = "little") {
        out.extend_from_slice(bytemuck::cast_slice(&environment.texels));
    } else {
        put(&mut out, environment.texels.iter().flatten().map(|v| v.to_bits()));
    }
    out
}

fn decode_texels(bytes: &[u8]) -> Option<(u32, u32, Vec<[f32; 3]>)> {
    let mut reader = Reader { bytes };
    let (width, height) = (reader.u32()?, reader.u32()?);
    let count = (width as usize).checked_mul(height as usize)?;
    let texels = reader.bytes;
    if texels.len() != count.checked_mul(12)? {
        return None;
    }
    // The file's floats are little-endian: on such a machine, one copy puts them in place.
    if cfg!(target_endian = "little") {
        return Some((width, height, bytemuck::pod_collect_to_vec(texels)));
    }
    let float = |c: &[u8]| f32::from_le_bytes(c.try_into().expect("4 bytes"));
    Some((width, height, texels.chunks_exact(12).map(|c| [float(&c[..4]), float(&c[4..8]), float(&c[8..])]).collect()))
}

const FILE_TEXELS: Entry = Entry { kind: "envfile", version: 1, max_payload: 128 << 20 };

/// The texels of an environment file whose bytes are `bytes`, as `decode` reads them, before
/// any check (the checks, and their warnings, run on them as on freshly decoded ones): from the
/// cache when it holds them for these bytes, else decoded and stored. Reading them back costs
/// less than decoding an EXR (docs/formats.md#caches); maps above 4096×2048 are not kept.
pub fn file_texels(
    bytes: &[u8],
    name: &str,
    decode: impl FnOnce() -> crate::Result<(u32, u32, Vec<[f32; 3]>)>,
) -> crate::Result<(u32, u32, Vec<[f32; 3]>)> {
    let _timing = crate::timings::phase("environment decode");
    let mut key = cache::hash128(bytes).to_vec();
    key.extend_from_slice(&sources_hash());
    let path = folder().map(|f| f.join(format!("file-{}.texels", cache::hex(&cache::hash128(&key)))));
    // Texels that are not finite or beyond the bound are never cached (see below), so such an
    // entry is damaged: the file is decoded again, and only its own problems are reported.
    let cached = path.as_deref().and_then(|path| FILE_TEXELS.load(path, &key)).and_then(|p| decode_texels(&p));
    if let Some(texels) = cached.filter(|(_, _, texels)| storable(texels)) {
        crate::timings::note(|| format!("environment: {name} loaded from {}", path_text(&path)));
        cache::touch(path.as_deref());
        return Ok(texels);
    }
    let (width, height, texels) = decode()?;
    if let Some(path) = path.as_ref().filter(|_| storable(&texels)) {
        let mut payload = Vec::with_capacity(8 + 12 * texels.len());
        put(&mut payload, [width, height]);
        put(&mut payload, texels.iter().flatten().map(|v| v.to_bits()));
        FILE_TEXELS.store(path, &key, &payload);
        cache::prune(path, FOLDER_BUDGET);
    }
    Ok((width, height, texels))
}

/// Whether decoded texels may be kept: all finite and within the documented bound. A file
/// with others is refused or warned about on every load, so nothing is lost by decoding it
/// again, and a cached entry with others can only be damaged.
fn storable(texels: &[[f32; 3]]) -> bool {
    texels.iter().flatten().all(|v| v.is_finite() && v.abs() <= MAX_TEXEL)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map() -> Environment {
        Environment::new(64, 32, (0..64 * 32).map(|i| [(i % 13) as f32, 0.5, (i % 5) as f32]).collect(), "test")
    }

    #[test]
    fn tables_read_back_exactly() {
        for max_side in [8193, 17] {
            let d = Distribution::for_device(&map(), max_side);
            let back = decode_tables(&encode_tables(&d), 64, 32).expect("decodes");
            assert_eq!(encode_tables(&back), encode_tables(&d));
            assert_eq!((back.marginal.clone(), back.cell_pdf.clone()), (d.marginal.clone(), d.cell_pdf.clone()));
        }
    }

    #[test]
    fn damaged_tables_are_refused_not_trusted() {
        let bytes = encode_tables(&Distribution::build(&map()));
        assert!(decode_tables(&bytes, 64, 32).is_some());
        assert!(decode_tables(&bytes, 32, 16).is_none(), "another map's size");
        for cut in [0, 3, 24, bytes.len() / 2, bytes.len() - 1] {
            assert!(decode_tables(&bytes[..cut], 64, 32).is_none(), "cut at {cut}");
        }
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(decode_tables(&longer, 64, 32).is_none());
        // A guide out of range would send the GPU's search outside its table.
        let mut bad_guide = bytes.clone();
        let guide_at = 24 + 4 + 4 * 33;
        bad_guide[guide_at..guide_at + 4].copy_from_slice(&1000u32.to_le_bytes());
        assert!(decode_tables(&bad_guide, 64, 32).is_none());
        // Values no map builds: NaN, a CDF that falls, a negative pdf.
        let cdf_at = 24 + 4 + 4 * 5;
        for value in [f32::NAN, -0.5, 2.0] {
            let mut bad_cdf = bytes.clone();
            bad_cdf[cdf_at..cdf_at + 4].copy_from_slice(&value.to_le_bytes());
            assert!(decode_tables(&bad_cdf, 64, 32).is_none(), "cdf {value}");
        }
        let mut bad_pdf = bytes.clone();
        let pdf_at = bytes.len() - 4;
        bad_pdf[pdf_at..].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(decode_tables(&bad_pdf, 64, 32).is_none());
        // A huge declared count is refused without allocating it.
        let mut huge = bytes;
        huge[24..28].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(decode_tables(&huge, 64, 32).is_none());
    }

    #[test]
    fn texels_read_back_exactly() {
        let env = map();
        let (w, h, texels) = decode_texels(&encode_texels(&env)).expect("decodes");
        assert_eq!((w, h), (64, 32));
        assert_eq!(bytemuck::cast_slice::<_, u8>(&texels), bytemuck::cast_slice::<_, u8>(&env.texels));
        let bytes = encode_texels(&env);
        assert!(decode_texels(&bytes[..bytes.len() - 4]).is_none());
        let mut huge = bytes;
        huge[..8].copy_from_slice(&[0xff; 8]);
        assert!(decode_texels(&huge).is_none());
    }
}
