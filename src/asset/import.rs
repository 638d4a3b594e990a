//! Importing an asset's materials: one preset per material, and a look that layers them
//! through the bake's masks (README: lookdev import).
//!
//! The look has one stack, the default one, since every object of a baked asset tells its
//! materials apart by mask rather than by id. The first material fills; each other material is a
//! layer through its own mask, at the start of each of its texture [`Axis`]; a material with
//! textured axes adds a corner layer for every other corner of their box right above its own.

use super::geometry::primitives;
use super::materials::{self, Axis, Mapped, UsedMaterial};
use super::Asset;
use crate::material::look::{EnvironmentSettings, Layer, Look, ObjectStack, RenderSettings};
use crate::material::params::Param;
use crate::material::Preset;
use crate::{Error, Result};
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

impl Import {
    /// Maps every material the scene's primitives use.
    pub fn new(asset: &Asset) -> Result<Import> {
        let primitives = primitives(asset)?;
        let used = materials::used(asset, primitives.iter().map(|(_, p)| p.material().index()));
        let source =
            asset.path.file_name().map_or_else(|| asset.path.display().to_string(), |n| n.to_string_lossy().into());
        let materials = used
            .into_iter()
            .map(|used| {
                let mapped = materials::map(asset, &materials::material_of(asset, used.index));
                let mut description = format!("'{}' from {source}.", used.label);
                for note in &mapped.notes {
                    description.push_str(&format!(" {}{}.", note[..1].to_uppercase(), &note[1..]));
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
        let mut layers = Vec::new();
        for (rank, imported) in self.materials.iter().enumerate() {
            let reference = preset_reference(&imported.preset.name);
            let params = imported.mapped.params;
            let channel = &imported.used.channel;
            let axes = &imported.mapped.axes;
            // The corner of the axes' box where the axes in `corner` are at their end.
            let layer = |mask: Option<String>, corner: usize| {
                let mut layer = Layer { preset: Some(reference.clone()), mask, ..Layer::filling(params) };
                for (i, axis) in axes.iter().enumerate() {
                    axis.apply(&mut layer.params, corner & (1 << i) != 0);
                    layer.overrides.push(match axis {
                        Axis::Metallic { .. } => Param::Metallic,
                        Axis::Roughness { .. } => Param::Roughness,
                        Axis::BaseColor { .. } => Param::BaseColor,
                    });
                }
                layer.overrides.sort();
                layer
            };
            layers.push(layer((rank > 0).then(|| channel.clone()), 0));
            for corner in 1..1usize << axes.len() {
                layers.push(layer(Some(materials::corner_mask(channel, axes, corner)), corner));
            }
        }
        Look {
            file: Some(look_file.to_path_buf()),
            environment: EnvironmentSettings::default(),
            render: RenderSettings::default(),
            model: None,
            objects: vec![ObjectStack { id: None, layers }],
        }
    }

    /// Writes the presets into `presets_dir` and the look to `look_file`, each atomically. Without
    /// `force`, existing files are refused before anything is written.
    pub fn write(&self, asset: &Asset, presets_dir: &Path, look_file: &Path, force: bool) -> Result<Vec<PathBuf>> {
        let look_folder = match look_file.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        if !look_folder.is_dir() {
            return Err(Error::input_file(look_file, "the look's folder does not exist"));
        }
        let preset_paths: Vec<PathBuf> =
            self.materials.iter().map(|m| presets_dir.join(format!("{}.toml", m.preset.name))).collect();
        if !force {
            if let Some(existing) = preset_paths.iter().chain([&look_file.to_path_buf()]).find(|p| p.exists()) {
                return Err(Error::input_file(existing, "already exists (use --force to replace it)"));
            }
        }
        let mut written = Vec::new();
        for imported in &self.materials {
            written.push(crate::material::library::save_preset(presets_dir, &imported.preset, true)?);
        }
        let from_look = relative_path(&look_folder, presets_dir);
        let look = self.look(look_file, |name| {
            let path = from_look.join(format!("{name}.toml"));
            path.to_string_lossy().replace('\\', "/")
        });
        let header = format!(
            "# The materials of {}, imported by lookdev import. Bake the g-buffer with\n\
             # lookdev bake on the same file: the masks below are the bake's.\n",
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
    use crate::material::Params;

    /// What the look's stack blends to at a pixel with these mask values, as `resolve.comp` does.
    fn blend(look: &Look, mask_value: impl Fn(&str) -> f32) -> Params {
        let stack = &look.objects[0];
        let weights = crate::material::stack::layer_weights(stack, mask_value);
        let mut params = stack.layers[0].params;
        for (layer, weight) in stack.layers.iter().zip(weights).skip(1) {
            if let Some(weight) = weight {
                params = params.mix(&layer.params, weight.blend);
            }
        }
        params
    }

    fn imported(channel: &str, base_color: [f32; 3], axes: Vec<Axis>) -> ImportedMaterial {
        let params = Params { base_color, metallic: 0.4, roughness: 0.3, ..Params::default() };
        ImportedMaterial {
            used: UsedMaterial {
                index: Some(0),
                label: channel.into(),
                channel: channel.into(),
                preset: channel.into(),
            },
            mapped: Mapped { params, axes, notes: Vec::new(), unsupported: Vec::new() },
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

    /// The bake's corner masks at a pixel wholly on a material whose texels sit at `x` along
    /// its axes.
    fn texture_masks(channel: &'static str, axes: Vec<Axis>, x: Vec<f32>) -> impl Fn(&str) -> f32 {
        let weights = materials::corner_weights(&x);
        move |name: &str| {
            if name == channel {
                return 1.0;
            }
            (1..weights.len() + 1)
                .find(|&corner| materials::corner_mask(channel, &axes, corner) == name)
                .map(|corner| weights[corner - 1])
                .unwrap_or(0.0)
        }
    }

    #[test]
    fn corner_layers_reproduce_every_texel() {
        let colour = Axis::BaseColor { from: [0.1, 0.2, 0.3], to: [0.7, 0.5, 0.4] };
        let sets: Vec<Vec<Axis>> = vec![
            vec![Axis::Metallic { factor: 0.9 }],
            vec![Axis::Roughness { factor: 0.8 }],
            vec![colour],
            vec![Axis::Metallic { factor: 0.9 }, Axis::Roughness { factor: 0.8 }],
            vec![Axis::Metallic { factor: 1.0 }, Axis::Roughness { factor: 0.5 }, colour],
        ];
        for axes in sets {
            let import =
                Import { materials: vec![imported("paint", [0.8, 0.1, 0.1], axes.clone())], unsupported: Vec::new() };
            let look = import.look(Path::new("look.toml"), str::to_string);
            assert_eq!(look.objects[0].layers.len(), 1 << axes.len());
            for x in [0.0f32, 1.0, 0.25, 0.9, 0.5] {
                // Each axis at a different place: x, 1 − x, then x².
                let at: Vec<f32> = [x, 1.0 - x, x * x][..axes.len()].to_vec();
                let p = blend(&look, texture_masks("paint", axes.clone(), at.clone()));
                let mut want =
                    Params { base_color: [0.8, 0.1, 0.1], metallic: 0.4, roughness: 0.3, ..Params::default() };
                for (axis, &t) in axes.iter().zip(&at) {
                    match *axis {
                        Axis::Metallic { factor } => want.metallic = factor * t,
                        Axis::Roughness { factor } => want.roughness = factor * t,
                        Axis::BaseColor { from, to } => {
                            want.base_color = [0, 1, 2].map(|k| from[k] + t * (to[k] - from[k]))
                        }
                    }
                }
                let error = (0..3)
                    .map(|k| (p.base_color[k] - want.base_color[k]).abs())
                    .chain([(p.metallic - want.metallic).abs(), (p.roughness - want.roughness).abs()])
                    .fold(0.0, f32::max);
                assert!(error < 1e-5, "{axes:?} at {at:?}: {p:?}");
            }
        }
    }

    #[test]
    fn each_material_shows_through_its_own_mask() {
        let axes = vec![Axis::Metallic { factor: 1.0 }, Axis::Roughness { factor: 1.0 }];
        let import = Import {
            materials: vec![
                imported("paint", [0.8, 0.1, 0.1], Vec::new()),
                imported("metal", [0.9, 0.9, 0.9], axes.clone()),
            ],
            unsupported: Vec::new(),
        };
        let look = import.look(Path::new("look.toml"), str::to_string);
        let layers = &look.objects[0].layers;
        assert_eq!(layers[0].mask, None, "the first material fills");
        assert_eq!(layers[1].mask.as_deref(), Some("metal"));
        // On the paint: the metal's mask and its corner masks are 0 there.
        let paint = blend(&look, |name| if name.starts_with("metal") { 0.0 } else { 1.0 });
        assert_eq!(paint.base_color, [0.8, 0.1, 0.1]);
        assert_eq!((paint.metallic, paint.roughness), (0.4, 0.3));
        let metal = blend(&look, texture_masks("metal", axes, vec![1.0, 0.5]));
        assert!(metal.base_color.iter().all(|&c| (c - 0.9).abs() < 1e-6), "{metal:?}");
        assert!((metal.metallic - 1.0).abs() < 1e-6 && (metal.roughness - 0.5).abs() < 1e-6, "{metal:?}");
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
