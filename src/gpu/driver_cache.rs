//! The Vulkan driver's own shader cache. Mesa keeps one under `$XDG_CACHE_HOME/mesa_shader_cache`
//! and maps its files into memory: on a full file system a store through such a mapping kills
//! the process with SIGBUS, before anything can be reported, and a folder it cannot make is
//! reported on stderr in Mesa's own words. lookdev keeps the driver's cache in its own cache
//! folder, `driver/`, sized so that it fits, and turns it off where that folder cannot take it
//! (docs/formats.md#caches). A user's own `MESA_SHADER_CACHE_*` settings are kept, and their
//! folder is checked the same way.

use std::path::{Path, PathBuf};

const MIB: u64 = 1 << 20;

/// The most the driver's cache may hold.
pub const MAX_BYTES: u64 = 256 * MIB;

/// The free space a cache folder needs for the driver's cache to be kept there: twice what
/// the cache may grow to, so that it never fills the file system.
pub const MIN_FREE_BYTES: u64 = 2 * MAX_BYTES;

/// What to tell the driver about its cache.
#[derive(Debug, PartialEq, Eq)]
pub enum Decision {
    /// Keep the cache in this folder, at most [`MAX_BYTES`].
    Keep(PathBuf),
    /// Turn it off, for this reason (shown with `LOOKDEV_TIMINGS=1`).
    Disable(String),
    /// The user has chosen; leave it.
    Leave,
}

/// Where the driver's cache goes, given the environment's variables (`var`) and what a folder
/// can take (`room`: free bytes once the folder is made, or why it cannot be).
pub fn decide(var: impl Fn(&str) -> Option<String>, room: impl Fn(&Path) -> Result<u64, String>) -> Decision {
    let set = |name: &str| var(name).filter(|v| !v.is_empty());
    if set("MESA_SHADER_CACHE_DISABLE").is_some_and(|v| v != "false" && v != "0") {
        return Decision::Leave;
    }
    let folder = match set("MESA_SHADER_CACHE_DIR") {
        Some(dir) => PathBuf::from(dir),
        None => match crate::cache::folder_with("driver", |name| var(name).map(Into::into)) {
            Some(folder) => folder,
            None => return Decision::Disable("no cache folder (neither XDG_CACHE_HOME nor HOME is set)".into()),
        },
    };
    match room(&folder) {
        Ok(free) if free >= MIN_FREE_BYTES => {
            if set("MESA_SHADER_CACHE_DIR").is_some() {
                Decision::Leave
            } else {
                Decision::Keep(folder)
            }
        }
        Ok(free) => Decision::Disable(format!(
            "{}: {} free, less than the {} the driver's cache needs",
            folder.display(),
            crate::input::size_text(free),
            crate::input::size_text(MIN_FREE_BYTES)
        )),
        Err(problem) => Decision::Disable(format!("{}: {problem}", folder.display())),
    }
}

/// Makes `folder` and returns the bytes free on its file system, or why it cannot be used: it
/// must be a folder that a file can be created in.
pub fn room(folder: &Path) -> Result<u64, String> {
    std::fs::create_dir_all(folder).map_err(|e| format!("cannot make the folder ({e})"))?;
    let probe = folder.join(format!(".lookdev-probe-{}", std::process::id()));
    std::fs::write(&probe, b"").map_err(|e| format!("cannot write there ({e})"))?;
    let _ = std::fs::remove_file(&probe);
    free_bytes(folder)
}

#[cfg(unix)]
fn free_bytes(folder: &Path) -> Result<u64, String> {
    use std::os::unix::ffi::OsStrExt;
    let path = std::ffi::CString::new(folder.as_os_str().as_bytes()).map_err(|_| "a NUL in the path".to_string())?;
    let mut stats: libc::statvfs = unsafe { std::mem::zeroed() };
    if unsafe { libc::statvfs(path.as_ptr(), &mut stats) } != 0 {
        return Err(format!("cannot read its free space ({})", std::io::Error::last_os_error()));
    }
    Ok((stats.f_bavail as u64).saturating_mul(stats.f_frsize as u64))
}

#[cfg(not(unix))]
fn free_bytes(_: &Path) -> Result<u64, String> {
    Ok(u64::MAX)
}

/// Applies [`decide`] to this process's environment. Call it first thing in `main`, before any
/// thread starts and before the Vulkan loader is opened: the driver reads these variables when
/// it creates a device.
pub fn prepare() {
    let decision = decide(|name| std::env::var(name).ok(), room);
    match &decision {
        Decision::Keep(folder) => {
            std::env::set_var("MESA_SHADER_CACHE_DIR", folder);
            if std::env::var_os("MESA_SHADER_CACHE_MAX_SIZE").is_none() {
                std::env::set_var("MESA_SHADER_CACHE_MAX_SIZE", format!("{}M", MAX_BYTES / MIB));
            }
        }
        Decision::Disable(_) => std::env::set_var("MESA_SHADER_CACHE_DISABLE", "true"),
        Decision::Leave => {}
    }
    if let Decision::Disable(why) = decision {
        crate::timings::note(|| format!("driver shader cache off: {why}"));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vars(pairs: &'static [(&'static str, &'static str)]) -> impl Fn(&str) -> Option<String> {
        move |name| pairs.iter().find(|(n, _)| *n == name).map(|(_, v)| v.to_string())
    }

    #[test]
    fn the_cache_is_kept_only_where_it_fits() {
        let home = vars(&[("XDG_CACHE_HOME", "/c")]);
        assert_eq!(decide(&home, |_| Ok(MIN_FREE_BYTES)), Decision::Keep(PathBuf::from("/c/lookdev/driver")));
        let full = decide(&home, |_| Ok(4096));
        assert!(matches!(&full, Decision::Disable(why) if why.contains("4.0 KiB free")), "{full:?}");
        let unwritable = decide(&home, |_| Err("cannot write there (read-only)".into()));
        assert!(matches!(&unwritable, Decision::Disable(why) if why.contains("read-only")), "{unwritable:?}");
        assert!(matches!(decide(vars(&[]), |_| Ok(u64::MAX)), Decision::Disable(_)));
    }

    #[test]
    fn the_users_own_settings_are_kept_but_checked() {
        let off = vars(&[("MESA_SHADER_CACHE_DISABLE", "true")]);
        assert_eq!(decide(off, |_| panic!("not looked at")), Decision::Leave);
        let own = vars(&[("MESA_SHADER_CACHE_DIR", "/mine"), ("XDG_CACHE_HOME", "/c")]);
        assert_eq!(decide(&own, |_| Ok(MIN_FREE_BYTES)), Decision::Leave);
        let full = decide(&own, |folder| if folder == Path::new("/mine") { Ok(0) } else { Ok(u64::MAX) });
        assert!(matches!(&full, Decision::Disable(why) if why.starts_with("/mine")), "{full:?}");
    }
}
