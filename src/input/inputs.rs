//! The files this process has read as inputs, by device and inode, so that an output never
//! replaces one of them (docs/formats.md#output): `render --gbuffer g.exr --out g.exr` would
//! otherwise destroy the g-buffer it renders, whatever name, link or path leads to it.

use super::Kind;
use crate::{Error, Result};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

/// One input read: where it lives on disk and what it was read as.
struct Input {
    device: u64,
    inode: u64,
    path: PathBuf,
    kind: Kind,
}

static READ: Mutex<Vec<Input>> = Mutex::new(Vec::new());

/// Whether reads are noted: only in a process that runs one command (`lookdev …`), whose reads
/// are that command's inputs; a program using the library reads and writes as it likes.
static TRACKING: AtomicBool = AtomicBool::new(false);

/// From now on, notes every file read as an input of this process's command.
pub fn track_inputs() {
    TRACKING.store(true, Ordering::Relaxed);
}

/// Notes that `path`, whose opened handle has `meta`, was read as `kind`.
pub(super) fn record(path: &Path, meta: &std::fs::Metadata, kind: Kind) {
    if !TRACKING.load(Ordering::Relaxed) {
        return;
    }
    let Some((device, inode)) = identity(meta) else { return };
    let Ok(mut read) = READ.lock() else { return };
    if !read.iter().any(|i| i.device == device && i.inode == inode) {
        read.push(Input { device, inode, path: path.to_path_buf(), kind });
    }
}

/// Refuses to write `output` if it is a file this process has read as an input (the same file by
/// device and inode, through any name or link). Call it before the work, once the inputs are
/// read, and again just before writing.
pub fn refuse_replacing_input(output: &Path) -> Result<()> {
    let Some((device, inode)) = std::fs::metadata(output).ok().as_ref().and_then(identity) else { return Ok(()) };
    let Ok(read) = READ.lock() else { return Ok(()) };
    match read.iter().find(|i| i.device == device && i.inode == inode) {
        Some(input) => Err(Error::input_file(
            output,
            format!(
                "the output would replace {}, {}, that this command reads; write the output to another file",
                input.kind.what(),
                input.path.display()
            ),
        )),
        None => Ok(()),
    }
}

#[cfg(unix)]
fn identity(meta: &std::fs::Metadata) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    Some((meta.dev(), meta.ino()))
}

#[cfg(not(unix))]
fn identity(_: &std::fs::Metadata) -> Option<(u64, u64)> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_output_that_is_an_input_by_any_name_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("look.toml");
        std::fs::write(&input, "[render]\n").unwrap();
        let other = dir.path().join("other.toml");
        std::fs::write(&other, "").unwrap();
        let link = dir.path().join("link.toml");
        std::fs::hard_link(&input, &link).unwrap();
        track_inputs();
        assert!(refuse_replacing_input(&input).is_ok(), "not read yet");
        super::super::read_text(&input, Kind::Toml).unwrap();
        for name in [&input, &link] {
            let message = refuse_replacing_input(name).unwrap_err().to_string();
            assert!(message.contains("would replace a TOML file"), "{message}");
        }
        assert!(refuse_replacing_input(&other).is_ok());
        assert!(refuse_replacing_input(&dir.path().join("new.toml")).is_ok());
    }
}
