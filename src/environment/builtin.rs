//! The environments built into the binary, and how looks, flags and scripts name an
//! environment: a built-in by name, or a file.
//!
//! All five are CC0 (public domain) by Greg Zaal (HDRI Haven), 1024×512, DWAB-compressed; see
//! LICENSE.txt beside them.

use super::{content_hash, load, Environment, LoadOptions};
use crate::Result;
use std::fmt;
use std::path::{Path, PathBuf};

/// One environment embedded in the binary.
#[derive(Debug)]
pub struct Builtin {
    /// The name looks, flags and scripts use.
    pub name: &'static str,
    /// What it shows, for the browser and `--help`.
    pub description: &'static str,
    bytes: &'static [u8],
}

/// The built-in environments, in the library's order.
pub const BUILTINS: &[Builtin] = &[
    Builtin {
        name: "studio",
        description: "a dark photo studio lit by soft boxes: dim, small highlights",
        bytes: include_bytes!("studio.exr"),
    },
    Builtin {
        name: "courtyard",
        description: "a sunlit courtyard, warm brick walls and a tiled floor: a strong warm cast",
        bytes: include_bytes!("courtyard.exr"),
    },
    Builtin {
        name: "city",
        description: "a paved plaza among buildings under a bright overcast sky: neutral daylight (the default)",
        bytes: include_bytes!("city.exr"),
    },
    Builtin {
        name: "interior",
        description: "a furnished room lit through large windows: warm",
        bytes: include_bytes!("interior.exr"),
    },
    Builtin {
        name: "sunrise",
        description: "a meadow with trees at sunrise: a low warm sun, cool sky fill",
        bytes: include_bytes!("sunrise.exr"),
    },
];

/// The environment a look that names none is lit by: neutral daylight with detail to reflect,
/// under which metals read as metals and a glossy white looks white and glossy.
pub const DEFAULT: &str = "city";

/// The prefix that makes a flag's or script's value a built-in's name: `builtin:courtyard`.
pub const PREFIX: &str = "builtin:";

impl Builtin {
    /// The built-in of this name; the error lists the names and suggests the closest.
    pub fn find(name: &str) -> std::result::Result<&'static Builtin, String> {
        BUILTINS.iter().find(|b| b.name == name).ok_or_else(|| {
            let names: Vec<&str> = BUILTINS.iter().map(|b| b.name).collect();
            crate::suggest::unknown("built-in environment", name, "", &names)
        })
    }

    /// The default environment.
    pub fn default_one() -> &'static Builtin {
        Builtin::find(DEFAULT).expect("the default is a built-in")
    }

    /// The FNV-1a hash of its file, as renders record it; cheap, no decoding.
    pub fn content_hash(&self) -> u64 {
        content_hash(self.bytes)
    }

    /// Decodes it, or takes it from the cache of decoded built-ins.
    pub fn load(&self) -> Environment {
        super::cache::builtin(self.name, self.content_hash(), || self.decode())
    }

    fn decode(&self) -> Environment {
        let name = format!("built-in {}", self.name);
        let (width, height, mut texels) =
            load::read_exr_texels(self.bytes, &name).expect("an embedded environment reads");
        // DWAB is lossy: its ringing leaves a few texels of these files a hair below zero. They
        // are known and harmless, so they are zeroed here rather than reported on every run.
        for v in texels.iter_mut().flatten() {
            *v = v.max(0.0);
        }
        load::validate(width, height, texels, &name, &LoadOptions::default(), self.content_hash())
            .expect("an embedded environment is valid")
    }
}

/// Which environment lights a render: a built-in, by name, or a file. Where it is optional,
/// `None` is the [`DEFAULT`] built-in.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum EnvironmentRef {
    /// A name from [`BUILTINS`].
    Builtin(&'static str),
    File(PathBuf),
}

impl EnvironmentRef {
    /// The built-in of this name (the error suggests the closest).
    pub fn builtin(name: &str) -> std::result::Result<EnvironmentRef, String> {
        Ok(EnvironmentRef::Builtin(Builtin::find(name)?.name))
    }

    /// The environment an optional reference means: `None` is the default.
    pub fn or_default(reference: Option<&EnvironmentRef>) -> EnvironmentRef {
        reference.cloned().unwrap_or(EnvironmentRef::Builtin(DEFAULT))
    }

    /// A flag's or script's value: `builtin:NAME` is a built-in; a bare name (no folder, no
    /// extension) that is no file here is a built-in too, so `--env courtyard` works; anything
    /// else is a file.
    pub fn parse(text: &str) -> std::result::Result<EnvironmentRef, String> {
        if let Some(name) = text.strip_prefix(PREFIX) {
            return EnvironmentRef::builtin(name);
        }
        if text.is_empty() {
            return Err("the environment must not be empty".to_string());
        }
        let path = Path::new(text);
        let bare = path.extension().is_none() && !text.contains(['/', '\\']);
        if bare && !path.exists() {
            return EnvironmentRef::builtin(text);
        }
        Ok(EnvironmentRef::File(path.to_path_buf()))
    }

    /// Reads it: decodes a built-in, loads a file with `options`.
    pub fn load(&self, options: &LoadOptions) -> Result<Environment> {
        match self {
            EnvironmentRef::Builtin(name) => Ok(Builtin::find(name).map_err(crate::Error::input)?.load()),
            EnvironmentRef::File(path) => load::load(path, options),
        }
    }

    /// A short name for the interface: the built-in's name, or the file's name.
    pub fn label(&self) -> String {
        match self {
            EnvironmentRef::Builtin(name) => format!("{name} (built-in)"),
            EnvironmentRef::File(path) => path.file_name().unwrap_or(path.as_os_str()).to_string_lossy().into_owned(),
        }
    }

    pub fn file(&self) -> Option<&Path> {
        match self {
            EnvironmentRef::File(path) => Some(path),
            EnvironmentRef::Builtin(_) => None,
        }
    }
}

/// As [`EnvironmentRef::parse`] reads it back: `builtin:NAME` or the file's path.
impl fmt::Display for EnvironmentRef {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            EnvironmentRef::Builtin(name) => write!(f, "{PREFIX}{name}"),
            EnvironmentRef::File(path) => write!(f, "{}", path.display()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_explicitly_and_bare() {
        assert_eq!(EnvironmentRef::parse("builtin:city"), Ok(EnvironmentRef::Builtin("city")));
        assert_eq!(EnvironmentRef::parse("sunrise"), Ok(EnvironmentRef::Builtin("sunrise")));
        assert_eq!(EnvironmentRef::parse("a/sky.hdr"), Ok(EnvironmentRef::File("a/sky.hdr".into())));
        assert_eq!(EnvironmentRef::parse("sky.exr"), Ok(EnvironmentRef::File("sky.exr".into())));
        let typo = EnvironmentRef::parse("courtyrad").unwrap_err();
        assert!(typo.contains("did you mean 'courtyard'?"), "{typo}");
        let explicit = EnvironmentRef::parse("builtin:studo").unwrap_err();
        assert!(explicit.contains("did you mean 'studio'?"), "{explicit}");
        for b in BUILTINS {
            let reference = EnvironmentRef::Builtin(b.name);
            assert_eq!(EnvironmentRef::parse(&reference.to_string()), Ok(reference));
        }
    }

    #[test]
    fn the_default_is_built_in() {
        assert_eq!(EnvironmentRef::or_default(None), EnvironmentRef::Builtin(Builtin::default_one().name));
    }
}
