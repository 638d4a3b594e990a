//! Reading input files as hostile data. Every file lookdev reads comes through [`read`] or
//! [`read_text`], so every reader refuses the same things in the same words:
//!
//! - anything that is not a regular file (a directory, a FIFO, a device such as `/dev/zero`, a
//!   socket), checked on the opened handle, and opened without blocking, so that a FIFO can
//!   never hang a command;
//! - a file larger than its kind's cap ([`Kind::cap`]), checked before reading and again while
//!   reading, since a file can grow meanwhile.
//!
//! What a file's own header declares (an image's size, a buffer's length) is checked by its
//! reader against what the file holds before any allocation is sized by it; [`exr`] does that
//! for OpenEXR headers.

pub mod exr;
pub mod image;
mod inputs;
pub mod readers;

pub use inputs::{refuse_replacing_input, track_inputs};

use crate::{Error, Result};
use std::fs::File;
use std::io::Read;
use std::path::Path;

const MIB: u64 = 1 << 20;

/// What a file is for, which sets how large it may be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A look or a preset (TOML).
    Toml,
    /// A viewer script.
    Script,
    /// A glTF asset: JSON or binary (`.glb`).
    Gltf,
    /// A glTF buffer or image file that an asset names.
    GltfResource,
    /// A g-buffer (OpenEXR).
    GBuffer,
    /// An environment map (OpenEXR or Radiance `.hdr`).
    Environment,
    /// A viewer snapshot's display image (PNG).
    SnapshotImage,
    /// A file of lookdev's own cache (src/cache.rs), which checks each kind's tighter limit.
    Cache,
}

impl Kind {
    /// The largest file of this kind lookdev reads, in bytes. Text files are written by hand
    /// or by tools, and a few MiB is far beyond any real one; binary files are capped near the
    /// formats' own limits (a `.glb` cannot exceed 4 GiB), and their decoded size is checked
    /// separately against their headers.
    pub const fn cap(self) -> u64 {
        match self {
            Kind::Toml | Kind::Script => 4 * MIB,
            Kind::Gltf | Kind::GltfResource => 2048 * MIB,
            Kind::GBuffer => 4096 * MIB,
            Kind::Environment => 2048 * MIB,
            Kind::SnapshotImage => 1024 * MIB,
            Kind::Cache => 512 * MIB,
        }
    }

    fn what(self) -> &'static str {
        match self {
            Kind::Toml => "a TOML file",
            Kind::Script => "a script",
            Kind::Gltf => "a glTF file",
            Kind::GltfResource => "a glTF buffer or image",
            Kind::GBuffer => "a g-buffer",
            Kind::Environment => "an environment",
            Kind::SnapshotImage => "a snapshot image",
            Kind::Cache => "a cache file",
        }
    }
}

/// Reads a whole file of `kind`. Errors name the file: `FILE: problem`.
pub fn read(path: &Path, kind: Kind) -> Result<Vec<u8>> {
    read_bytes(path, kind).map_err(|problem| Error::input_file(path, problem))
}

/// Checks that `path` is a regular file that can be opened, without reading it: for a caller
/// that refuses it on other grounds, so that a folder is called a folder first.
pub fn check_regular(path: &Path) -> Result<()> {
    let meta = open(path)
        .and_then(|file| file.metadata().map_err(|e| format!("cannot read the file ({e})")))
        .map_err(|problem| Error::input_file(path, problem))?;
    if !meta.is_file() {
        return Err(Error::input_file(path, not_regular(&meta)));
    }
    Ok(())
}

/// Reads a whole text file of `kind`, which must be UTF-8.
pub fn read_text(path: &Path, kind: Kind) -> Result<String> {
    let bytes = read(path, kind)?;
    String::from_utf8(bytes).map_err(|e| {
        let offset = e.utf8_error().valid_up_to();
        let line = 1 + e.as_bytes()[..offset].iter().filter(|&&b| b == b'\n').count();
        Error::input_file(format!("{}:{line}", path.display()), "the file is not UTF-8 text")
    })
}

/// Like [`read`], but returns only the problem, for callers that name the file in their own
/// words (a glTF buffer is reported as the asset's, with the buffer's label).
pub fn read_bytes(path: &Path, kind: Kind) -> std::result::Result<Vec<u8>, String> {
    read_bytes_at_most(path, kind, kind.cap())
}

/// Like [`read_bytes`], with a cap below the kind's: for a caller that knows a tighter limit
/// before reading (a cache entry of one kind), so that a larger file is refused unread.
pub fn read_bytes_at_most(path: &Path, kind: Kind, cap: u64) -> std::result::Result<Vec<u8>, String> {
    let cap = cap.min(kind.cap());
    let file = open(path)?;
    let meta = file.metadata().map_err(|e| format!("cannot read the file ({e})"))?;
    if !meta.is_file() {
        return Err(not_regular(&meta));
    }
    if meta.len() > cap {
        return Err(too_large(meta.len(), cap, kind));
    }
    if kind != Kind::Cache {
        inputs::record(path, &meta, kind);
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    // One byte more than the cap tells a file that grew past it from one that fills it.
    file.take(cap + 1).read_to_end(&mut bytes).map_err(|e| format!("cannot read the file ({e})"))?;
    if bytes.len() as u64 > cap {
        return Err(too_large(bytes.len() as u64, cap, kind));
    }
    Ok(bytes)
}

/// Opens for reading without blocking: opening a FIFO with no writer would otherwise wait
/// forever, before the handle could be checked.
fn open(path: &Path) -> std::result::Result<File, String> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    options.open(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => "file not found".to_string(),
        std::io::ErrorKind::PermissionDenied => "permission denied".to_string(),
        _ => format!("cannot open the file ({e})"),
    })
}

fn not_regular(meta: &std::fs::Metadata) -> String {
    format!("not a regular file ({}); lookdev reads only regular files", file_type(meta))
}

fn too_large(len: u64, cap: u64, kind: Kind) -> String {
    format!("the file is {}, larger than the {} lookdev reads as {}", size_text(len), size_text(cap), kind.what())
}

/// A byte count for messages: `3.2 MiB`, `512 bytes`.
pub fn size_text(bytes: u64) -> String {
    match bytes {
        b if b >= 1 << 30 => format!("{:.1} GiB", b as f64 / (1u64 << 30) as f64),
        b if b >= MIB => format!("{:.1} MiB", b as f64 / MIB as f64),
        b if b >= 1 << 10 => format!("{:.1} KiB", b as f64 / 1024.0),
        b => format!("{b} bytes"),
    }
}

fn file_type(meta: &std::fs::Metadata) -> &'static str {
    if meta.is_dir() {
        return "a folder";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let kind = meta.file_type();
        if kind.is_fifo() {
            return "a FIFO";
        }
        if kind.is_char_device() {
            return "a character device";
        }
        if kind.is_block_device() {
            return "a block device";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    "not a file"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_files_are_read_and_everything_else_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("look.toml");
        std::fs::write(&file, "[render]\n").unwrap();
        assert_eq!(read_text(&file, Kind::Toml).unwrap(), "[render]\n");

        let problem = |path: &Path| read(path, Kind::Toml).unwrap_err().to_string();
        assert!(problem(dir.path()).contains("not a regular file (a folder)"), "{}", problem(dir.path()));
        assert!(problem(Path::new("/dev/zero")).contains("a character device"));
        assert!(problem(&dir.path().join("missing.toml")).ends_with("file not found"));
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_is_refused_without_blocking() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe.toml");
        let name = std::ffi::CString::new(fifo.as_os_str().as_encoded_bytes()).unwrap();
        assert_eq!(unsafe { libc::mkfifo(name.as_ptr(), 0o600) }, 0);
        let message = read(&fifo, Kind::Toml).unwrap_err().to_string();
        assert!(message.contains("not a regular file (a FIFO)"), "{message}");
    }

    #[test]
    fn files_over_their_cap_are_refused_and_text_must_be_utf8() {
        let dir = tempfile::tempdir().unwrap();
        let big = dir.path().join("big.toml");
        std::fs::write(&big, vec![b'#'; Kind::Toml.cap() as usize + 1]).unwrap();
        let message = read(&big, Kind::Toml).unwrap_err().to_string();
        assert!(message.contains("larger than the 4.0 MiB lookdev reads as a TOML file"), "{message}");

        let latin1 = dir.path().join("latin1.toml");
        std::fs::write(&latin1, b"# ok\nname = \"caf\xe9\"\n").unwrap();
        let message = read_text(&latin1, Kind::Toml).unwrap_err().to_string();
        assert!(message.ends_with("latin1.toml:2: the file is not UTF-8 text"), "{message}");
    }

    #[test]
    fn a_tighter_cap_refuses_a_file_before_reading_it() {
        let dir = tempfile::tempdir().unwrap();
        let entry = dir.path().join("entry.bin");
        // Sparse: 256 MiB that take no disk, under the kind's own cap but over this caller's.
        std::fs::File::create(&entry).unwrap().set_len(256 * MIB).unwrap();
        let message = read_bytes_at_most(&entry, Kind::Cache, 1024).unwrap_err();
        assert!(message.contains("is 256.0 MiB, larger than the 1.0 KiB lookdev reads as a cache file"), "{message}");
        std::fs::File::create(&entry).unwrap().set_len(1024).unwrap();
        assert_eq!(read_bytes_at_most(&entry, Kind::Cache, 1024).unwrap().len(), 1024);
        // The kind's cap still bounds a looser one.
        std::fs::File::create(&entry).unwrap().set_len(5 * MIB).unwrap();
        let message = read_bytes_at_most(&entry, Kind::Toml, u64::MAX).unwrap_err();
        assert!(message.contains("larger than the 4.0 MiB lookdev reads as a TOML file"), "{message}");
    }
}
