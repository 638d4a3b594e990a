//! Presets: named sets of BRDF parameter values, the building blocks of layer stacks.
//!
//! A preset file (`presets/<name>.toml`, a file beside a look, or one in the user's library):
//!
//! ```toml
//! name = "gold"                        # optional; defaults to the file name without .toml
//! description = "Polished gold: ..."   # optional; what it models, where the numbers come from
//! tags = ["metal", "measured"]         # optional
//! base_color = [0.9626, 0.8276, 0.4082]  # linear Rec.709
//! metallic = 1.0
//! roughness = 0.25
//! ```
//!
//! Any of the eleven parameters may appear at the top level; those left out take the defaults
//! of [`Params::default`]. Unknown keys, wrong types, NaN/inf and out-of-range values are
//! errors of the form `FILE:LINE: problem`.

use std::path::Path;

use serde::Deserialize;

use super::params::{Param, Params};
use super::toml_input::{self as input, Field, Source};

/// A named set of parameter values, from `presets/<name>.toml` or the user's library.
#[derive(Clone, Debug, PartialEq)]
pub struct Preset {
    /// The `name` key, or the file name without `.toml` when the file has none.
    pub name: String,
    pub description: String,
    pub tags: Vec<String>,
    /// Every parameter: the file's values over the defaults.
    pub params: Params,
    /// Which parameters the file set explicitly, in [`Param::ALL`] order.
    pub set: Vec<Param>,
}

/// The file as written. Every value is spanned so that errors can name its line.
#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a preset table")]
struct PresetFile {
    name: Option<Field>,
    description: Option<Field>,
    tags: Option<Field>,
    base_color: Option<Field>,
    metallic: Option<Field>,
    subsurface: Option<Field>,
    specular: Option<Field>,
    specular_tint: Option<Field>,
    roughness: Option<Field>,
    anisotropic: Option<Field>,
    sheen: Option<Field>,
    sheen_tint: Option<Field>,
    clearcoat: Option<Field>,
    clearcoat_gloss: Option<Field>,
}

impl PresetFile {
    /// The parameter fields, in [`Param::ALL`] order.
    fn params(&self) -> [(Param, &Option<Field>); 11] {
        [
            (Param::BaseColor, &self.base_color),
            (Param::Metallic, &self.metallic),
            (Param::Subsurface, &self.subsurface),
            (Param::Specular, &self.specular),
            (Param::SpecularTint, &self.specular_tint),
            (Param::Roughness, &self.roughness),
            (Param::Anisotropic, &self.anisotropic),
            (Param::Sheen, &self.sheen),
            (Param::SheenTint, &self.sheen_tint),
            (Param::Clearcoat, &self.clearcoat),
            (Param::ClearcoatGloss, &self.clearcoat_gloss),
        ]
    }
}

impl Preset {
    /// Parses a preset file's text. `file` names it in errors and supplies the default name.
    pub fn parse(text: &str, file: &Path) -> crate::Result<Preset> {
        let src = Source { file, text };
        let raw: PresetFile = src.decode()?;
        let default_name = file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let mut preset = Preset {
            name: src.read("name", &raw.name, input::text)?.unwrap_or(default_name),
            description: src.read("description", &raw.description, input::any_text)?.unwrap_or_default(),
            tags: src.read("tags", &raw.tags, input::text_list)?.unwrap_or_default(),
            params: Params::default(),
            set: Vec::new(),
        };
        for (param, field) in raw.params() {
            if let Some(field) = field {
                input::set_param(&mut preset.params, param, field.get_ref())
                    .map_err(|problem| src.error(field.span(), problem))?;
                preset.set.push(param);
            }
        }
        Ok(preset)
    }

    /// Reads and parses a preset file. A missing file is an error naming it.
    pub fn load(path: &Path) -> crate::Result<Preset> {
        Preset::parse(&input::read_text(path)?, path)
    }

    /// The preset in its file format: name, description, tags, then only the parameters it
    /// sets, in [`Param::ALL`] order. [`Preset::parse`] reads it back to an equal preset.
    pub fn to_toml(&self) -> String {
        let mut lines = vec![
            format!("name = {}", input::quoted(&self.name)),
            format!("description = {}", input::quoted(&self.description)),
        ];
        let tags: Vec<String> = self.tags.iter().map(|t| input::quoted(t)).collect();
        lines.push(format!("tags = [{}]", tags.join(", ")));
        for param in Param::ALL.into_iter().filter(|p| self.set.contains(p)) {
            lines.push(format!("{param} = {}", input::value(self.params.get(param))));
        }
        lines.push(String::new());
        lines.join("\n")
    }
}
