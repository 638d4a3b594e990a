//! Importing an asset's materials: one preset per material, and a look that layers them
//! through the bake's masks and binds their maps
//! (docs/commands.md#lookdev-import-modelgltfglb---presets-dir---look-looktoml---gbuffer-gexr---force).
//!
//! The look has one stack, the default one, since every object of a baked asset tells its
//! materials apart by mask rather than by id. The first material fills; each other material is a
//! layer through its own mask. Each layer binds the parameters its material's textures drive to
//! the bake's maps ([`MapKind`]), so that the value at a pixel is the preset's factor times the
//! map's.

use super::geometry::primitives;
use super::materials::{self, MapKind, Mapped, UsedMaterial};
use super::Asset;
use crate::material::look::{EnvironmentSettings, Layer, Look, ObjectStack, RenderSettings};
use crate::material::params::Param;
use crate::material::Preset;
use crate::{Error, Result};
use std::collections::BTreeMap;
use std::path::{Component, Path, PathBuf};

/// One imported material: its names, its preset and what the mapping could not carry.
pub struct ImportedMaterial {
    pub used: UsedMaterial,
    pub mapped: Mapped,
    pub preset: Preset,
}

/// The presets and the look of an asset, before anything is written.
pub struct Import {
    pub materials: Vec<ImportedMaterial>,
    /// The extensions the asset uses that lookdev ignores.
    pub unsupported: Vec<String>,
}

/// The bindings of a layer whose material has these map kinds.
pub fn map_bindings(kinds: &[MapKind]) -> BTreeMap<Param, String> {
    kinds.iter().flat_map(|k| k.bindings()).map(|&(param, map)| (param, map.to_string())).collect()
}

impl Import {
    /// Maps every material the scene's primitives use.
    pub fn new(asset: &Asset) -> Result<Import> {
        let primitives = primitives(asset)?;
        let used = materials::used(asset, primitives.iter().map(|(_, p)| p.material().index()));
        // As the bake sees them: the scene's primitives that carry COLOR_0.
        let colored: Vec<Option<usize>> = primitives
            .iter()
            .filter(|(_, p)| p.get(&gltf::Semantic::Colors(0)).is_some())
            .map(|(_, p)| p.material().index())
            .collect();
        let source =
            asset.path.file_name().map_or_else(|| asset.path.display().to_string(), |n| n.to_string_lossy().into());
        let materials = used
            .into_iter()
            .map(|used| {
                let material = materials::material_of(asset, used.index);
                let mut mapped = materials::map(&material, colored.contains(&used.index));
                mapped.params = significant(mapped.params);
                let mut description = format!("'{}' from {source}.", used.label);
                for note in &mapped.notes {
                    let mut letters = note.chars();
                    let first: String = letters.next().map(|c| c.to_uppercase().collect()).unwrap_or_default();
                    description.push_str(&format!(" {first}{}.", letters.as_str()));
                }
                let preset = Preset {
                    name: used.preset.clone(),
                    description,
                    tags: vec!["imported".into(), "gltf".into()],
                    params: mapped.params,
                    set: Param::ALL.to_vec(),
                    ior: None,
                };
                ImportedMaterial { used, mapped, preset }
            })
            .collect();
        Ok(Import { materials, unsupported: asset.unsupported_extensions() })
    }

    /// The look, its layers naming each preset by `preset_reference(name)`.
    pub fn look(&self, look_file: &Path, preset_reference: impl Fn(&str) -> String) -> Look {
        let layers = self
            .materials
            .iter()
            .enumerate()
            .map(|(rank, imported)| Layer {
                // The viewer shows the material's own name, not the preset file's path.
                name: Some(imported.used.label.clone()),
                preset: Some(preset_reference(&imported.preset.name)),
                // The first material fills; the others show through their masks.
                mask: (rank > 0).then(|| imported.used.channel.clone()),
                maps: map_bindings(&imported.mapped.maps),
                ..Layer::filling(imported.mapped.params)
            })
            .collect();
        Look {
            file: Some(look_file.to_path_buf()),
            environment: EnvironmentSettings::default(),
            render: RenderSettings::default(),
            model: None,
            gbuffer: Default::default(),
            objects: vec![ObjectStack::new(None, layers)],
            lines: Default::default(),
        }
    }

    /// Writes the presets into `presets_dir` and the look to `look_file`, each atomically. Without
    /// `force`, existing files are refused before anything is written. With `gbuffer`, the look
    /// names it as its `[gbuffer] file`, relative to the look.
    pub fn write(
        &self,
        asset: &Asset,
        presets_dir: &Path,
        look_file: &Path,
        gbuffer: Option<&Path>,
        force: bool,
    ) -> Result<Vec<PathBuf>> {
        let look_folder = match look_file.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        if !look_folder.is_dir() {
            return Err(Error::input_file(look_file, "the look's folder does not exist"));
        }
        let preset_paths: Vec<PathBuf> =
            self.materials.iter().map(|m| presets_dir.join(format!("{}.toml", m.preset.name))).collect();
        // The look must not take the place of a preset written beside it, nor any output that of
        // the asset it comes from.
        let look_place = in_folder(&look_folder, look_file);
        if let Some(imported) = self.materials.iter().find(|m| {
            look_place.is_some()
                && in_folder(presets_dir, &presets_dir.join(format!("{}.toml", m.preset.name))) == look_place
        }) {
            return Err(Error::input_file(
                look_file,
                format!(
                    "the look would replace the preset '{}' this import writes there; give the look another name or folder",
                    imported.preset.name
                ),
            ));
        }
        for path in preset_paths.iter().chain([&look_file.to_path_buf()]) {
            crate::input::refuse_replacing_input(path)?;
        }
        if !force {
            if let Some(existing) = preset_paths.iter().chain([&look_file.to_path_buf()]).find(|p| p.exists()) {
                return Err(Error::input_file(existing, "already exists (use --force to replace it)"));
            }
            if let Some(imported) =
                self.materials.iter().find(|m| crate::material::library::shadows_builtin(presets_dir, &m.preset.name))
            {
                return Err(crate::material::library::shadowing_error(&imported.preset.name));
            }
        }
        let mut written = Vec::new();
        for imported in &self.materials {
            written.push(crate::material::library::save_preset(presets_dir, &imported.preset, true)?);
        }
        let from_look = relative_path(&look_folder, presets_dir);
        let mut look = self.look(look_file, |name| {
            let path = from_look.join(format!("{name}.toml"));
            path.to_string_lossy().replace('\\', "/")
        });
        // Relative to the look, as the look reads it back: its folder joined with the way there.
        look.gbuffer.file = gbuffer.map(|file| {
            let folder = file.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
            let way = relative_path(&look_folder, folder).join(file.file_name().unwrap_or(file.as_os_str()));
            look.file.as_deref().and_then(Path::parent).unwrap_or(Path::new("")).join(way)
        });
        let header = format!(
            "# The materials of {}, imported by lookdev import. Bake the g-buffer with\n\
             # lookdev bake on the same file: the masks and maps below are the bake's.\n",
            asset.path.file_name().map_or_else(|| asset.path.display().to_string(), |n| n.to_string_lossy().into())
        );
        let text = format!("{header}{}\n", look.to_toml());
        // The look must read back as written, presets and all.
        Look::parse(&text, look_file)
            .map_err(|e| Error::gpu(format!("the imported look does not read back ({e}); this is a defect")))?;
        crate::atomic_file::write(look_file, text.as_bytes())?;
        written.push(look_file.to_path_buf());
        Ok(written)
    }
}

/// The parameters to six significant digits, as precise as glTF's factors are written, without
/// the float noise of the conversions: IOR 1.5 gives specular 0.5, not 0.50000006.
fn significant(mut params: crate::material::Params) -> crate::material::Params {
    use crate::material::params::Value;
    let round = |x: f32| format!("{x:.5e}").parse::<f32>().unwrap_or(x);
    for param in Param::ALL {
        let value = match params.get(param) {
            Value::Scalar(x) => Value::Scalar(round(x)),
            Value::Color(rgb) => Value::Color(rgb.map(round)),
        };
        // Rounding to six digits keeps a value inside the range it was in.
        let _ = params.set(param, value);
    }
    params
}

/// Where `file` in `folder` lives, by the folder's real path: two names of one place compare
/// equal. None when the folder does not exist (yet), and so holds nothing.
fn in_folder(folder: &Path, file: &Path) -> Option<PathBuf> {
    Some(folder.canonicalize().ok()?.join(file.file_name()?))
}

/// `to` as seen from the folder `from`: relative when both resolve on disk, else absolute.
fn relative_path(from: &Path, to: &Path) -> PathBuf {
    let (Ok(from), Ok(to)) = (from.canonicalize(), to.canonicalize()) else {
        return std::path::absolute(to).unwrap_or_else(|_| to.to_path_buf());
    };
    let (from, to): (Vec<Component>, Vec<Component>) = (from.components().collect(), to.components().collect());
    let common = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
    let mut path: PathBuf = std::iter::repeat_n(Component::ParentDir, from.len() - common).collect();
    path.extend(&to[common..]);
    if path.as_os_str().is_empty() {
        PathBuf::from(".")
    } else {
        path
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gbuffer::GBuffer;
    use crate::material::stack::PackedStacks;
    use crate::material::Params;

    fn imported(channel: &str, base_color: [f32; 3], maps: Vec<MapKind>) -> ImportedMaterial {
        let params = Params { base_color, metallic: 0.4, roughness: 0.3, ..Params::default() };
        ImportedMaterial {
            used: UsedMaterial {
                index: Some(0),
                label: channel.into(),
                channel: channel.into(),
                preset: channel.into(),
            },
            mapped: Mapped { params, maps, notes: Vec::new(), unsupported: Vec::new() },
            preset: Preset {
                name: channel.into(),
                description: String::new(),
                tags: Vec::new(),
                params,
                set: Param::ALL.to_vec(),
                ior: None,
            },
        }
    }

    /// A one-pixel g-buffer of object 1 with these masks and the bake's maps.
    fn pixel(masks: &[(&str, f32)], maps: &[(&str, f32)]) -> GBuffer {
        let mut g = GBuffer::shaderball(1, 1);
        g.object_id = vec![1];
        g.coverage = vec![1.0];
        g.masks = masks.iter().map(|&(n, v)| (n.to_string(), vec![v])).collect();
        g.maps = maps.iter().map(|&(n, v)| (n.to_string(), vec![v])).collect();
        g
    }

    #[test]
    fn imported_values_carry_no_float_noise() {
        let noisy = Params { specular: 0.50000006, metallic: 0.9999996, roughness: 0.123_456_7, ..Params::default() };
        let tidy = significant(noisy);
        assert_eq!((tidy.specular, tidy.metallic, tidy.roughness), (0.5, 1.0, 0.123457));
    }

    #[test]
    fn each_material_shows_through_its_own_mask_with_its_factors_times_its_maps() {
        let import = Import {
            materials: vec![
                imported("paint", [0.8, 0.1, 0.1], Vec::new()),
                imported("metal", [0.9, 0.9, 0.9], vec![MapKind::BaseColor, MapKind::MetallicRoughness]),
            ],
            unsupported: Vec::new(),
        };
        let look = import.look(Path::new("look.toml"), str::to_string);
        let layers = &look.objects[0].layers;
        assert_eq!(layers[0].mask, None, "the first material fills");
        assert!(layers[0].maps.is_empty(), "an untextured material binds nothing");
        assert_eq!(layers[1].mask.as_deref(), Some("metal"));
        let bound: Vec<(Param, &str)> = layers[1].maps.iter().map(|(p, m)| (*p, m.as_str())).collect();
        assert_eq!(
            bound,
            [(Param::BaseColor, "base_color"), (Param::Metallic, "metallic"), (Param::Roughness, "roughness")]
        );

        let maps = [
            ("base_color.R", 0.5),
            ("base_color.G", 0.25),
            ("base_color.B", 1.0),
            ("metallic", 1.0),
            ("roughness", 0.5),
        ];
        let resolve =
            |g: &GBuffer| PackedStacks::pack(&look, [1], g, Path::new("g.exr")).unwrap().resolve_gbuffer_pixel(g, 0);
        let paint = resolve(&pixel(&[("paint", 1.0), ("metal", 0.0)], &maps));
        assert_eq!(paint.base_color, [0.8, 0.1, 0.1]);
        assert_eq!((paint.metallic, paint.roughness), (0.4, 0.3));
        let metal = resolve(&pixel(&[("paint", 0.0), ("metal", 1.0)], &maps));
        let want = [0.9 * 0.5, 0.9 * 0.25, 0.9];
        assert!(metal.base_color.iter().zip(want).all(|(c, w)| (c - w).abs() < 1e-6), "{metal:?}");
        assert!((metal.metallic - 0.4).abs() < 1e-6 && (metal.roughness - 0.15).abs() < 1e-6, "{metal:?}");
    }

    #[test]
    fn every_map_kind_binds_the_parameters_it_drives() {
        let all = map_bindings(&MapKind::ALL);
        let params: Vec<Param> = all.keys().copied().collect();
        assert_eq!(
            params,
            [
                Param::BaseColor,
                Param::Metallic,
                Param::Specular,
                Param::Roughness,
                Param::Sheen,
                Param::SheenTint,
                Param::Clearcoat,
                Param::ClearcoatGloss,
                Param::Emission,
            ]
        );
        // Every map a binding names is one the bake writes.
        for map in all.values() {
            let written =
                materials::MAP_CHANNELS.iter().any(|c| c.name == map || c.name.starts_with(&format!("{map}.")));
            assert!(written, "{map} is bound but never written");
        }
    }

    #[test]
    fn relative_paths_climb_and_descend() {
        let root = std::env::temp_dir().join(format!("lookdev-relative-{}", std::process::id()));
        std::fs::create_dir_all(root.join("looks")).unwrap();
        std::fs::create_dir_all(root.join("lib/presets")).unwrap();
        assert_eq!(relative_path(&root.join("looks"), &root.join("lib/presets")), Path::new("../lib/presets"));
        assert_eq!(relative_path(&root.join("looks"), &root.join("looks")), Path::new("."));
        std::fs::remove_dir_all(&root).unwrap();
    }
}
