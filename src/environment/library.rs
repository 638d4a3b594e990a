//! The environment library: the built-ins, the `.exr`/`.hdr` files in the folders the config
//! file names, and the files opened last, in that order. The viewer's browser shows it and the
//! arrow keys step through it.

use super::builtin::{EnvironmentRef, BUILTINS};
use crate::config::Config;
use std::path::{Path, PathBuf};

/// Where a library entry is listed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Section {
    Builtin,
    /// A folder from the config file.
    Folder(PathBuf),
    /// A recently opened file.
    Recent,
}

/// One environment as the library lists it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Entry {
    pub reference: EnvironmentRef,
    pub section: Section,
}

/// The library's entries, and what could not be listed (a folder that is gone).
#[derive(Clone, Debug, Default)]
pub struct Listing {
    pub entries: Vec<Entry>,
    pub problems: Vec<String>,
}

/// Whether a file name is one the library lists.
pub fn is_environment_file(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("exr") || e.eq_ignore_ascii_case("hdr"))
}

/// Lists the library as `config` describes it. Folders are read now, not recursively; their
/// files are sorted by name.
pub fn list(config: &Config) -> Listing {
    let mut listing = Listing::default();
    let builtins =
        BUILTINS.iter().map(|b| Entry { reference: EnvironmentRef::Builtin(b.name), section: Section::Builtin });
    listing.entries.extend(builtins);
    for folder in &config.environment_folders {
        match std::fs::read_dir(folder) {
            Ok(read) => {
                let mut files: Vec<PathBuf> = read
                    .flatten()
                    .map(|entry| entry.path())
                    .filter(|p| {
                        let hidden = p.file_name().is_some_and(|n| n.to_string_lossy().starts_with('.'));
                        !hidden && is_environment_file(p) && p.is_file()
                    })
                    .collect();
                files.sort();
                listing.entries.extend(
                    files.into_iter().map(|f| Entry {
                        reference: EnvironmentRef::File(f),
                        section: Section::Folder(folder.clone()),
                    }),
                );
            }
            Err(e) => listing.problems.push(format!("{}: cannot list the folder ({e})", folder.display())),
        }
    }
    let recent = config.recent_environments.iter().cloned();
    listing.entries.extend(recent.map(|f| Entry { reference: EnvironmentRef::File(f), section: Section::Recent }));
    listing
}

impl Listing {
    /// The environments in stepping order: each once, where it is first listed.
    pub fn order(&self) -> Vec<EnvironmentRef> {
        let mut order: Vec<EnvironmentRef> = Vec::new();
        for entry in &self.entries {
            if !order.contains(&entry.reference) {
                order.push(entry.reference.clone());
            }
        }
        order
    }
}

/// The environment `by` steps from `current` in `order`, wrapping round. One not listed steps
/// from just before the first (so → gives the first and ← the last).
pub fn step(order: &[EnvironmentRef], current: &EnvironmentRef, by: i32) -> Option<EnvironmentRef> {
    if order.is_empty() {
        return None;
    }
    let n = order.len() as i64;
    let at = match order.iter().position(|r| r == current) {
        Some(i) => i as i64,
        None if by > 0 => -1,
        None => n,
    };
    Some(order[(at + by as i64).rem_euclid(n) as usize].clone())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folders_list_their_maps_between_the_builtins_and_the_recent_files() {
        let dir = std::env::temp_dir().join(format!("lookdev-library-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for name in ["b.hdr", "a.EXR", "notes.txt", ".hidden.exr"] {
            std::fs::write(dir.join(name), b"").unwrap();
        }
        let config = Config {
            environment_folders: vec![dir.clone(), dir.join("gone")],
            recent_environments: vec![dir.join("b.hdr"), PathBuf::from("/elsewhere/c.exr")],
        };
        let listing = list(&config);
        let order = listing.order();
        let n = BUILTINS.len();
        assert_eq!(order.len(), n + 3, "{order:?}");
        assert_eq!(order[n], EnvironmentRef::File(dir.join("a.EXR")));
        assert_eq!(order[n + 1], EnvironmentRef::File(dir.join("b.hdr")));
        assert_eq!(order[n + 2], EnvironmentRef::File("/elsewhere/c.exr".into()));
        assert_eq!(listing.entries.len(), n + 4, "the recent b.hdr is listed in both sections");
        assert!(listing.problems[0].contains("gone"), "{:?}", listing.problems);
        let first = EnvironmentRef::Builtin(BUILTINS[0].name);
        assert_eq!(step(&order, &first, 1), Some(EnvironmentRef::Builtin(BUILTINS[1].name)));
        assert_eq!(step(&order, &first, -1), order.last().cloned());
        let stray = EnvironmentRef::File("/x.exr".into());
        assert_eq!(step(&order, &stray, 1), Some(first));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
