//! Presets: named sets of BRDF parameter values, the building blocks of layer stacks. The file
//! format, each parameter's default and range, and the complex IOR of metals are specified in
//! docs/formats.md#presets. Unknown keys, wrong types, NaN/inf and out-of-range values are
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
    /// `ior_n` and `ior_k`, per channel, when the file gives them.
    pub ior: Option<([f32; 3], [f32; 3])>,
}

/// How far `base_color` may be from the F0 of `ior_n` and `ior_k`.
pub const IOR_F0_TOLERANCE: f32 = 0.005;

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
    emission: Option<Field>,
    ior_n: Option<Field>,
    ior_k: Option<Field>,
}

impl PresetFile {
    /// The parameter fields, in [`Param::ALL`] order.
    fn params(&self) -> [(Param, &Option<Field>); 12] {
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
            (Param::Emission, &self.emission),
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
            ior: None,
        };
        for (param, field) in raw.params() {
            if let Some(field) = field {
                input::set_param(&mut preset.params, param, field.get_ref())
                    .map_err(|problem| src.error(field.span(), problem))?;
                preset.set.push(param);
            }
        }
        preset.ior = complex_ior(&src, &raw, &preset)?;
        if let Some((n, k)) = preset.ior {
            for c in 0..3 {
                preset.params.ior_edge[c] = crate::shading::brdf::ior_edge(n[c], k[c]);
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
        if let Some((n, k)) = self.ior {
            lines.push(format!("ior_n = {}", input::value(super::params::Value::Color(n))));
            lines.push(format!("ior_k = {}", input::value(super::params::Value::Color(k))));
        }
        lines.push(String::new());
        lines.join("\n")
    }
}

/// `ior_n` and `ior_k`: both or neither, n > 0 and k >= 0, and a `base_color` that is their F0.
fn complex_ior(src: &Source, raw: &PresetFile, preset: &Preset) -> crate::Result<Option<([f32; 3], [f32; 3])>> {
    let (n_field, k_field) = match (&raw.ior_n, &raw.ior_k) {
        (None, None) => return Ok(None),
        (Some(n), Some(k)) => (n, k),
        (Some(n), None) => return Err(src.error(n.span(), "ior_n needs ior_k beside it")),
        (None, Some(k)) => return Err(src.error(k.span(), "ior_k needs ior_n beside it")),
    };
    let n = input::color("ior_n", n_field.get_ref()).map_err(|p| src.error(n_field.span(), p))?;
    let k = input::color("ior_k", k_field.get_ref()).map_err(|p| src.error(k_field.span(), p))?;
    for c in 0..3 {
        if !(n[c] > 0.0 && n[c] <= 100.0) {
            return Err(src.error(n_field.span(), format!("ior_n[{c}] = {} must be in (0, 100]", n[c])));
        }
        if !(k[c] >= 0.0 && k[c] <= 100.0) {
            return Err(src.error(k_field.span(), format!("ior_k[{c}] = {} must be in [0, 100]", k[c])));
        }
        let f0 = crate::shading::brdf::normal_reflectance(n[c] as f64, k[c] as f64) as f32;
        let base = preset.params.base_color[c];
        if (base - f0).abs() > IOR_F0_TOLERANCE {
            return Err(src.error(
                n_field.span(),
                format!(
                    "base_color[{c}] = {base} is not the F0 {f0:.4} of ior_n and ior_k (within {IOR_F0_TOLERANCE})"
                ),
            ));
        }
    }
    Ok(Some((n, k)))
}
