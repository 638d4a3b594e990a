//! The user's settings file, `$XDG_CONFIG_HOME/lookdev/config.toml` (else
//! `~/.config/lookdev/config.toml`; docs/formats.md#config): the environment library's folders
//! and the environments opened last.

use crate::material::toml_input::{self as input, Field, Source};
use crate::{atomic_file, Error, Result};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// How many recent environments are kept.
pub const RECENT: usize = 10;

/// What the config file holds.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Config {
    /// Folders whose `.exr` and `.hdr` files the environment library lists, in the order added.
    pub environment_folders: Vec<PathBuf>,
    /// Environment files opened last, newest first, at most [`RECENT`].
    pub recent_environments: Vec<PathBuf>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a config file")]
struct ConfigFile {
    environments: Option<EnvironmentsTable>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "an [environments] table")]
struct EnvironmentsTable {
    folders: Option<Field>,
    recent: Option<Field>,
}

/// The config file's place, from the environment variables; `None` when neither
/// `XDG_CONFIG_HOME` nor `HOME` is set.
pub fn path() -> Option<PathBuf> {
    let base = std::env::var_os("XDG_CONFIG_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").filter(|v| !v.is_empty()).map(|home| Path::new(&home).join(".config")))?;
    Some(base.join("lookdev").join("config.toml"))
}

impl Config {
    /// Reads the file; one that does not exist is the empty config. Errors name the file and
    /// line.
    pub fn load(path: &Path) -> Result<Config> {
        if !path.exists() {
            return Ok(Config::default());
        }
        let text = input::read_text(path)?;
        Config::parse(&text, path)
    }

    /// Parses a config file's text; `file` is for messages.
    pub fn parse(text: &str, file: &Path) -> Result<Config> {
        let src = Source { file, text };
        let raw: ConfigFile = src.decode()?;
        let Some(table) = raw.environments else {
            return Ok(Config::default());
        };
        let paths = |key: &str, field: &Option<Field>| -> Result<Vec<PathBuf>> {
            let list = src.read(key, field, input::text_list)?.unwrap_or_default();
            Ok(list.into_iter().map(PathBuf::from).collect())
        };
        let mut recent = paths("recent", &table.recent)?;
        recent.truncate(RECENT);
        Ok(Config { environment_folders: paths("folders", &table.folders)?, recent_environments: recent })
    }

    /// The file's text; [`Config::parse`] gives this config back.
    pub fn to_toml(&self) -> String {
        let list = |paths: &[PathBuf]| {
            let quoted: Vec<String> =
                paths.iter().map(|p| format!("    {},", input::quoted(&p.to_string_lossy()))).collect();
            if quoted.is_empty() {
                "[]".to_string()
            } else {
                format!("[\n{}\n]", quoted.join("\n"))
            }
        };
        format!(
            "# lookdev's settings (docs/formats.md#config)\n\n[environments]\nfolders = {}\nrecent = {}\n",
            list(&self.environment_folders),
            list(&self.recent_environments)
        )
    }

    /// Writes the file atomically, making its folder first.
    pub fn save(&self, path: &Path) -> Result<()> {
        if let Some(folder) = path.parent() {
            std::fs::create_dir_all(folder).map_err(|e| Error::input_file(folder, format!("cannot create ({e})")))?;
        }
        atomic_file::write(path, self.to_toml().as_bytes())
    }

    /// Puts an opened environment file first among the recent ones.
    pub fn add_recent(&mut self, file: &Path) {
        self.recent_environments.retain(|p| p != file);
        self.recent_environments.insert(0, file.to_path_buf());
        self.recent_environments.truncate(RECENT);
    }

    /// Adds a folder to the library; false when it was there already.
    pub fn add_folder(&mut self, folder: &Path) -> bool {
        if self.environment_folders.iter().any(|f| f == folder) {
            return false;
        }
        self.environment_folders.push(folder.to_path_buf());
        true
    }

    /// Takes a folder out of the library; false when it was not there.
    pub fn remove_folder(&mut self, folder: &Path) -> bool {
        let before = self.environment_folders.len();
        self.environment_folders.retain(|f| f != folder);
        self.environment_folders.len() != before
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_config_round_trips_through_its_text() {
        let mut config = Config::default();
        config.add_folder(Path::new("/hdri/outdoor"));
        config.add_folder(Path::new("/hdri/with \"quotes\""));
        assert!(!config.add_folder(Path::new("/hdri/outdoor")));
        for i in 0..12 {
            config.add_recent(Path::new(&format!("/maps/{i}.exr")));
        }
        config.add_recent(Path::new("/maps/5.exr"));
        assert_eq!(config.recent_environments.len(), RECENT);
        assert_eq!(config.recent_environments[0], Path::new("/maps/5.exr"));
        assert_eq!(Config::parse(&config.to_toml(), Path::new("config.toml")).unwrap(), config);
        assert!(config.remove_folder(Path::new("/hdri/outdoor")));
        assert_eq!(config.environment_folders, [Path::new("/hdri/with \"quotes\"")]);
    }

    #[test]
    fn a_bad_config_names_its_file_and_line() {
        let e = Config::parse("[environments]\nfolders = 3\n", Path::new("c.toml")).unwrap_err();
        assert!(e.message.starts_with("c.toml:2:"), "{e}");
        let e = Config::parse("[environment]\n", Path::new("c.toml")).unwrap_err();
        assert!(e.message.contains("did you mean 'environments'"), "{e}");
    }
}
