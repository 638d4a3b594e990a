//! The viewer's environment library: the config file that names its folders and recent files,
//! read at start and written (atomically) whenever they change.

use crate::config::{self, Config};
use crate::environment::library::{self, Listing};
use crate::environment::EnvironmentRef;
use crate::{Error, Result};
use std::path::{Path, PathBuf};

/// The library's settings and where they are kept.
pub struct EnvironmentLibrary {
    pub config: Config,
    /// The config file; `None` when there is nowhere to keep it.
    path: Option<PathBuf>,
    /// False when the file exists but did not read: it is then left alone, not overwritten.
    writable: bool,
}

impl EnvironmentLibrary {
    /// Reads the config file; a bad one is a warning (returned), and the library then starts
    /// empty and leaves the file as it is.
    pub fn load() -> (EnvironmentLibrary, Option<String>) {
        let path = config::path();
        let read = path.as_deref().map(Config::load).transpose();
        match read {
            Ok(config) => (EnvironmentLibrary { config: config.unwrap_or_default(), path, writable: true }, None),
            Err(e) => {
                let warning =
                    format!("{e}; the environment library's folders and recent files are not kept this session");
                (EnvironmentLibrary { config: Config::default(), path, writable: false }, Some(warning))
            }
        }
    }

    /// The library as it is on disk now.
    pub fn listing(&self) -> Listing {
        library::list(&self.config)
    }

    /// The environment `by` steps from `current` in the library's order. The library holds
    /// absolute paths, so a file named relative to here is found as one.
    pub fn step(&self, current: &EnvironmentRef, by: i32) -> Option<EnvironmentRef> {
        let current = match current {
            EnvironmentRef::File(file) => EnvironmentRef::File(absolute(file)),
            builtin => builtin.clone(),
        };
        library::step(&self.listing().order(), &current, by)
    }

    /// Notes an environment file as opened (a built-in is not a recent file).
    pub fn opened(&mut self, reference: &EnvironmentRef) -> Result<()> {
        let Some(file) = reference.file() else { return Ok(()) };
        self.config.add_recent(&absolute(file));
        self.save()
    }

    /// Adds a folder; it must exist.
    pub fn add_folder(&mut self, folder: &Path) -> Result<bool> {
        if !folder.is_dir() {
            return Err(Error::input_file(folder, "not a folder"));
        }
        let added = self.config.add_folder(&absolute(folder));
        self.save()?;
        Ok(added)
    }

    pub fn remove_folder(&mut self, folder: &Path) -> Result<bool> {
        let removed = self.config.remove_folder(folder);
        self.save()?;
        Ok(removed)
    }

    fn save(&self) -> Result<()> {
        match &self.path {
            Some(path) if self.writable => self.config.save(path),
            Some(path) => Err(Error::input_file(path, "not written: it did not read at start; fix or remove it")),
            None => Err(Error::input("the library is not kept: set XDG_CONFIG_HOME or HOME")),
        }
    }
}

fn absolute(path: &Path) -> PathBuf {
    std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf())
}
