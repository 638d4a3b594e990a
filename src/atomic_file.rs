//! Writing files so that an existing file is never left half-written: the bytes go to a
//! temporary file in the same folder, which is then renamed over the target in one step. A
//! write that fails, or a process killed mid-write, leaves the old file as it was (and at worst a
//! hidden temporary file beside it).

use crate::{Error, Result};
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The temporary name used while writing `path`: hidden, in the same folder (so the rename
/// stays on one file system), and unique to this process and this write (so concurrent writers,
/// in other processes or other threads, stay apart).
fn temporary_path(path: &Path) -> PathBuf {
    static WRITES: AtomicUsize = AtomicUsize::new(0);
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let write = WRITES.fetch_add(1, Ordering::Relaxed);
    path.with_file_name(format!(".{name}.{}-{write}.tmp", std::process::id()))
}

/// Removes the temporary files of earlier writes of `path` whose process is gone (killed
/// mid-write, say), so that they do not pile up beside it. Best effort: what cannot be read or
/// removed stays.
fn remove_stale_temporaries(path: &Path) {
    let (Some(name), Some(folder)) = (path.file_name(), path.parent()) else { return };
    let prefix = format!(".{}.", name.to_string_lossy());
    let folder = if folder.as_os_str().is_empty() { Path::new(".") } else { folder };
    let Ok(entries) = std::fs::read_dir(folder) else { return };
    for entry in entries.flatten() {
        let file_name = entry.file_name().to_string_lossy().into_owned();
        let Some(rest) = file_name.strip_prefix(&prefix).and_then(|r| r.strip_suffix(".tmp")) else { continue };
        let Some(pid) = rest.split_once('-').and_then(|(pid, n)| n.parse::<u64>().ok().and(pid.parse::<u32>().ok()))
        else {
            continue;
        };
        if !process_is_alive(pid) {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Whether a process with this id exists (on other systems than Unix, always assumed so).
fn process_is_alive(pid: u32) -> bool {
    #[cfg(unix)]
    {
        let Ok(pid) = libc::pid_t::try_from(pid) else { return false };
        // Signal 0 checks only that the process exists; EPERM means it does, as another user's.
        let signalled = unsafe { libc::kill(pid, 0) } == 0;
        signalled || std::io::Error::last_os_error().raw_os_error() == Some(libc::EPERM)
    }
    #[cfg(not(unix))]
    {
        let _ = pid;
        true
    }
}

/// Writes `bytes` to `path` atomically, replacing any existing file.
pub fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    write_with(path, true, |file| file.write_all(bytes))
}

/// Writes `bytes` to `path` atomically, failing if `path` already exists: the check and the
/// write are one step, so a file that appears meanwhile is not overwritten either.
pub fn write_new(path: &Path, bytes: &[u8]) -> Result<()> {
    write_with(path, false, |file| file.write_all(bytes))
}

/// Fills a temporary file with `fill`, syncs it, then puts it at `path`: by rename (replacing)
/// or by hard link (only if `path` does not exist). On any failure the temporary file is
/// removed and `path` is untouched.
pub fn write_with(path: &Path, replace: bool, fill: impl FnOnce(&mut File) -> std::io::Result<()>) -> Result<()> {
    put(path, replace, true, fill)
}

/// Like [`write`], without waiting for the bytes to reach the disk: for files that can be made
/// again (caches), whose readers detect a damaged file. Readers and other writers still never see
/// a half-written file; only a crash of the whole system can leave one.
pub fn write_unsynced(path: &Path, bytes: &[u8]) -> Result<()> {
    put(path, true, false, |file| file.write_all(bytes))
}

fn put(path: &Path, replace: bool, sync: bool, fill: impl FnOnce(&mut File) -> std::io::Result<()>) -> Result<()> {
    // A folder (`.`, say) cannot be replaced by a file; the rename would say only "busy".
    if path.is_dir() || path.file_name().is_none() {
        return Err(Error::input_file(path, "is a folder: name a file to write"));
    }
    remove_stale_temporaries(path);
    let temporary = temporary_path(path);
    let result = (|| {
        let mut file = File::create(&temporary)?;
        fill(&mut file)?;
        if sync {
            file.sync_all()?;
        }
        drop(file);
        if replace {
            std::fs::rename(&temporary, path)
        } else {
            std::fs::hard_link(&temporary, path).and_then(|()| std::fs::remove_file(&temporary))
        }
    })();
    result.map_err(|e| {
        let _ = std::fs::remove_file(&temporary);
        if e.kind() == std::io::ErrorKind::AlreadyExists {
            Error::input_file(path, "already exists (--force replaces it)")
        } else {
            Error::io(path, format!("cannot write: {e}"))
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_folder_is_never_a_file_to_write() {
        let dir = tempfile::tempdir().unwrap();
        for path in [dir.path().to_path_buf(), dir.path().join("."), dir.path().join("..")] {
            let message = write(&path, b"x").unwrap_err().to_string();
            assert!(message.ends_with("is a folder: name a file to write"), "{message}");
        }
    }

    #[test]
    fn temporaries_of_dead_processes_are_removed_and_live_ones_kept() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("gold.toml");
        // No process has the largest pid; this one is alive.
        let dead = dir.path().join(format!(".gold.toml.{}-0.tmp", i32::MAX));
        let live = dir.path().join(format!(".gold.toml.{}-7.tmp", std::process::id()));
        let other = dir.path().join(format!(".silver.toml.{}-0.tmp", i32::MAX));
        for file in [&dead, &live, &other] {
            std::fs::write(file, "partial").unwrap();
        }
        write(&path, b"name = \"gold\"\n").unwrap();
        assert!(!dead.exists(), "a dead process's temporary is removed");
        assert!(live.exists(), "a live process's temporary is kept");
        assert!(other.exists(), "another file's temporary is left alone");
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_and_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("look.toml");
        std::fs::write(&path, "old contents").unwrap();
        let failed = write_with(&path, true, |file| {
            file.write_all(b"half a new fi")?;
            Err(std::io::Error::other("disk full"))
        });
        assert!(failed.is_err());
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old contents");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "the temporary file was removed");
        write(&path, b"new contents").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new contents");
    }

    #[test]
    fn a_leftover_temporary_from_a_killed_write_changes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("gold.toml");
        std::fs::write(&path, "old").unwrap();
        // What a process killed between writing and renaming leaves behind.
        std::fs::write(dir.path().join(format!(".gold.toml.{}-0.tmp", std::process::id() + 1)), "partial").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
        write(&path, b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
    }

    #[test]
    fn write_new_refuses_an_existing_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.toml");
        write_new(&path, b"first").unwrap();
        let error = write_new(&path, b"second").unwrap_err();
        assert!(error.message.contains("already exists"), "{}", error.message);
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "first");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
