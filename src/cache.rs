//! Files lookdev keeps between runs to start faster (docs/formats.md#caches): in
//! `$XDG_CACHE_HOME/lookdev/` (else `~/.cache/lookdev/`), each made again from its inputs
//! whenever it is missing, stale or damaged, so a cache can always be deleted.
//!
//! Every cache file is one entry in the same frame: a fixed header, a key, then the payload.
//!
//! | bytes | what                                                                   |
//! |-------|------------------------------------------------------------------------|
//! | 8     | `LDCACHE\0`                                                            |
//! | 8     | the entry's kind, ASCII, padded with NULs (`pipeline`, `envtable`, …)  |
//! | 4     | the kind's format version (little-endian u32)                          |
//! | 4     | the key's length k (u32, at most [`MAX_KEY`])                          |
//! | 8     | the payload's length n (u64)                                           |
//! | 16    | [`hash128`] of the payload                                             |
//! | k     | the key: everything the payload was made from                          |
//! | n     | the payload                                                            |
//!
//! A file is used only if every field matches what the reader expects, its length is exactly
//! the header's, and the payload's hash is right: anything else (another version, a truncated or
//! corrupted file, one written by another build) is treated as missing. Reading a cache file
//! never fails a command, and neither does writing one: a folder that cannot be written only
//! leaves the cache empty.

use crate::input::{self, Kind};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

const MAGIC: &[u8; 8] = b"LDCACHE\0";
const HEADER: usize = 8 + 8 + 4 + 4 + 8 + 16;

/// The longest key an entry may have.
pub const MAX_KEY: usize = 4096;

/// The folder of one kind of cache, `$XDG_CACHE_HOME/lookdev/<name>` (else
/// `~/.cache/lookdev/<name>`); `None` when neither variable is set. Not created here.
pub fn folder(name: &str) -> Option<PathBuf> {
    folder_with(name, |var| std::env::var_os(var))
}

/// [`folder`], with the environment's variables read through `var`.
pub fn folder_with(name: &str, var: impl Fn(&str) -> Option<std::ffi::OsString>) -> Option<PathBuf> {
    let base = var("XDG_CACHE_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| var("HOME").filter(|v| !v.is_empty()).map(|home| Path::new(&home).join(".cache")))?;
    Some(base.join("lookdev").join(name))
}

/// A 128-bit hash of `bytes`: two independent multiply-xorshift lanes over 8-byte words. Fast
/// enough to key megabytes of texels on every run, and stable across versions and platforms
/// (words are read little-endian). Not cryptographic: it guards against accidents (another map,
/// a damaged file), not against someone crafting a collision in their own cache.
pub fn hash128(bytes: &[u8]) -> [u8; 16] {
    const K: [u64; 2] = [0x9e37_79b9_7f4a_7c15, 0xc2b2_ae3d_27d4_eb4f];
    let mut lanes = [0x243f_6a88_85a3_08d3u64 ^ bytes.len() as u64, 0x1319_8a2e_0370_7344];
    let mix = |lanes: &mut [u64; 2], word: u64| {
        for (lane, k) in lanes.iter_mut().zip(K) {
            *lane = (*lane ^ word).wrapping_mul(k);
            *lane ^= *lane >> 31;
        }
    };
    let mut words = bytes.chunks_exact(8);
    for word in &mut words {
        mix(&mut lanes, u64::from_le_bytes(word.try_into().expect("8 bytes")));
    }
    let mut tail = [0u8; 8];
    tail[..words.remainder().len()].copy_from_slice(words.remainder());
    mix(&mut lanes, u64::from_le_bytes(tail));
    // A final avalanche, so that every input bit reaches every output bit.
    let finish = |mut h: u64| {
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
        h ^ (h >> 33)
    };
    let (a, b) = (finish(lanes[0] ^ lanes[1].rotate_left(17)), finish(lanes[1] ^ lanes[0].rotate_left(41)));
    let mut out = [0u8; 16];
    out[..8].copy_from_slice(&a.to_le_bytes());
    out[8..].copy_from_slice(&b.to_le_bytes());
    out
}

/// Lowercase hexadecimal, for file names made from hashes.
pub fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// What an entry is: its kind (at most 8 ASCII bytes) and format version.
#[derive(Clone, Copy, Debug)]
pub struct Entry {
    pub kind: &'static str,
    pub version: u32,
    /// The largest payload read back, checked before anything is allocated for it.
    pub max_payload: u64,
}

impl Entry {
    fn kind_bytes(&self) -> [u8; 8] {
        let mut out = [0u8; 8];
        out[..self.kind.len()].copy_from_slice(self.kind.as_bytes());
        out
    }

    /// The payload stored at `path` under `key`. `None` when there is no file, or when it holds
    /// another key (the inputs changed); a file that is damaged or not a cache entry at all is
    /// reported once with a warning and treated as missing, to be written again.
    pub fn load(&self, path: &Path, key: &[u8]) -> Option<Vec<u8>> {
        if !path.is_file() {
            return None;
        }
        // The file's size is checked against the cap before reading, and the header's lengths
        // against the file's, so a hostile file cannot make this allocate more than the cap.
        let cap = (HEADER + MAX_KEY) as u64 + self.max_payload;
        let bytes = match input::read_bytes_at_most(path, Kind::Cache, cap) {
            Ok(bytes) => bytes,
            Err(problem) => {
                damaged(path, &problem);
                return None;
            }
        };
        match self.parse(&bytes, key) {
            // The payload is moved to the front of the file's buffer rather than copied out.
            Ok(Some(start)) => Some({
                let mut bytes = bytes;
                bytes.drain(..start);
                bytes
            }),
            Ok(None) => None,
            Err(problem) => {
                damaged(path, problem);
                None
            }
        }
    }

    /// Where the payload of `bytes` starts: Ok(None) for a sound entry of another version or
    /// key, an error for a damaged one.
    fn parse(&self, bytes: &[u8], key: &[u8]) -> Result<Option<usize>, &'static str> {
        if bytes.len() < HEADER || &bytes[..8] != MAGIC {
            return Err("it is not a lookdev cache file");
        }
        let u32_at = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
        let (version, key_len) = (u32_at(16), u32_at(20) as usize);
        let payload_len = u64::from_le_bytes(bytes[24..32].try_into().expect("8 bytes"));
        if bytes[8..16] != self.kind_bytes() {
            return Err("it holds another kind of entry");
        }
        if key_len > MAX_KEY || payload_len > self.max_payload {
            return Err("its header gives impossible sizes");
        }
        if bytes.len() as u64 != (HEADER + key_len) as u64 + payload_len {
            return Err("it is truncated or has bytes past its end");
        }
        let payload = &bytes[HEADER + key_len..];
        if hash128(payload) != bytes[32..48] {
            return Err("its contents are corrupted");
        }
        if version != self.version || &bytes[HEADER..HEADER + key_len] != key {
            return Ok(None);
        }
        Ok(Some(HEADER + key_len))
    }

    /// The whole file of an entry.
    pub fn encode(&self, key: &[u8], payload: &[u8]) -> Vec<u8> {
        assert!(key.len() <= MAX_KEY, "a cache key of {} bytes", key.len());
        let mut out = Vec::with_capacity(HEADER + key.len() + payload.len());
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&self.kind_bytes());
        out.extend_from_slice(&self.version.to_le_bytes());
        out.extend_from_slice(&(key.len() as u32).to_le_bytes());
        out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
        out.extend_from_slice(&hash128(payload));
        out.extend_from_slice(key);
        out.extend_from_slice(payload);
        out
    }

    /// Writes the entry to `path` atomically (unsynced: a file damaged by a crash is detected
    /// and made again), creating its folder. A failure (a read-only
    /// folder, a full disk) leaves the cache without it and is otherwise ignored: it is shown
    /// only with `LOOKDEV_TIMINGS=1`.
    pub fn store(&self, path: &Path, key: &[u8], payload: &[u8]) {
        if payload.len() as u64 > self.max_payload {
            return;
        }
        let written = path.parent().map_or(Ok(()), std::fs::create_dir_all).map_err(|e| e.to_string()).and_then(|()| {
            crate::atomic_file::write_unsynced(path, &self.encode(key, payload)).map_err(|e| e.to_string())
        });
        match written {
            Ok(()) => crate::timings::note(|| format!("cache: wrote {}", path.display())),
            Err(e) => crate::timings::note(|| format!("cache: cannot write {} ({e})", path.display())),
        }
    }
}

/// Marks an entry as just used, for [`prune`]. Best effort.
pub fn touch(path: Option<&Path>) {
    if let Some(file) = path.and_then(|p| std::fs::File::options().append(true).open(p).ok()) {
        let _ = file.set_modified(std::time::SystemTime::now());
    }
}

/// Keeps the folder of `written` within `budget` bytes, removing the least recently used
/// entries other than `written`. Best effort: what cannot be read or removed stays.
pub fn prune(written: &Path, budget: u64) {
    let Some(Ok(entries)) = written.parent().map(std::fs::read_dir) else { return };
    let mut files: Vec<(std::time::SystemTime, u64, PathBuf)> = entries
        .flatten()
        .filter_map(|e| {
            let meta = e.metadata().ok().filter(|m| m.is_file())?;
            Some((meta.modified().ok()?, meta.len(), e.path()))
        })
        .collect();
    let mut total: u64 = files.iter().map(|f| f.1).sum();
    files.sort();
    for (_, len, path) in files {
        if total <= budget {
            break;
        }
        if path != written && std::fs::remove_file(&path).is_ok() {
            total -= len;
        }
    }
}

/// Warns once per process about a damaged cache file, which is then made again.
fn damaged(path: &Path, problem: &str) {
    static WARNED: AtomicBool = AtomicBool::new(false);
    if !WARNED.swap(true, Ordering::Relaxed) {
        crate::warn(format!("ignoring the cache file {}: {problem}; it is made again", path.display()));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ENTRY: Entry = Entry { kind: "test", version: 3, max_payload: 100 };

    #[test]
    fn an_entry_reads_back_only_whole_and_under_its_own_key_and_version() {
        let file = ENTRY.encode(b"key", b"payload");
        assert_eq!(ENTRY.parse(&file, b"key"), Ok(Some(file.len() - 7)));
        assert_eq!(&file[file.len() - 7..], b"payload");
        assert_eq!(ENTRY.parse(&file, b"other key"), Ok(None));
        assert_eq!(Entry { version: 4, ..ENTRY }.parse(&file, b"key"), Ok(None));
        assert!(Entry { kind: "other", ..ENTRY }.parse(&file, b"key").is_err());
        for cut in 0..file.len() {
            assert!(ENTRY.parse(&file[..cut], b"key").is_err(), "cut at {cut}");
        }
        for flip in 0..file.len() {
            let mut damaged = file.clone();
            damaged[flip] ^= 0x10;
            let sound = ENTRY.parse(&damaged, b"key") == Ok(Some(file.len() - 7)) && damaged.ends_with(b"payload");
            assert!(!sound, "byte {flip}");
        }
        let mut longer = file.clone();
        longer.push(0);
        assert!(ENTRY.parse(&longer, b"key").is_err());
        let big = ENTRY.encode(b"key", &[0; 101]);
        assert!(ENTRY.parse(&big, b"key").is_err(), "a payload over the cap is refused");
    }

    #[test]
    fn the_hash_sees_every_byte_and_the_length() {
        let base = vec![7u8; 37];
        let h = hash128(&base);
        for i in 0..base.len() {
            let mut other = base.clone();
            other[i] ^= 1;
            assert_ne!(hash128(&other), h, "byte {i}");
        }
        assert_ne!(hash128(&base[..36]), h);
        assert_ne!(hash128(&[0; 8]), hash128(&[0; 9]));
        // Stable across platforms and versions: cache files written elsewhere stay readable.
        assert_eq!(hex(&hash128(b"lookdev")), "62ac93ae41547bd3939af277b67fb146");
    }
}
