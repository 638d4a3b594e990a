//! AOVs: what a render writes beside the beauty (docs/formats.md#aovs), each an entry of
//! [`Aov`], computed from the renderer and the scene by [`layers`], as EXR layers named
//! `<aov>.R .G .B` (or `.Y` for a scalar), as Nuke, Arnold and Blender name them.
//!
//! - Light: `diffuse` (with subsurface), `specular`, `clearcoat`, `sheen` and `emission`, each
//!   premultiplied by coverage like the beauty: with the background off they sum to it.
//! - Material: `albedo` and each resolved parameter, as `param_<name>` (`param_base_color`,
//!   `param_roughness`, …; named without the prefix where no light AOV has the name).
//! - Layers: `layers`, each layer's share of the blend, for every layer of every stack.
//! - Geometry: `N`, `V` and `objectId`, as the g-buffer has them, and `occlusion`, the
//!   cosine-weighted share of each pixel's hemisphere its stored visibility sees (1 without).
//! - Shadow: `shadow`, the share of a shadow catcher's light that reaches it (1 elsewhere),
//!   the factor its pixels darken what is behind them by; light AOVs are 0 there.
//! - Error: `variance`, of each pixel's mean luminance.
//! - Inputs: `masks` and `maps`, the g-buffer's masks and maps as read, as `mask_<name>` and
//!   `map_<name>`.

use crate::gbuffer::GBuffer;
use crate::lab::albedo::AlbedoTables;
use crate::material::look::{Look, ObjectStack};
use crate::material::stack::layer_shares;
use crate::material::{Param, Params};
use crate::render::renderer::{Accumulate, Renderer, LOBES};
use crate::Result;

/// One AOV.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Aov {
    /// A lobe's share of the light, in [`LOBES`] order.
    Lobe(usize),
    Emission,
    Albedo,
    Param(Param),
    Layers,
    Normal,
    View,
    ObjectId,
    Occlusion,
    Shadow,
    Variance,
    /// Every g-buffer mask, as `mask_<name>.Y`.
    Masks,
    /// Every g-buffer map, as `map_<name>.R/G/B` (a colour map) or `map_<name>.Y`.
    Maps,
}

/// Names that stand for several AOVs.
const GROUPS: [(&str, &str); 6] = [
    ("light", "diffuse, specular, clearcoat, sheen and emission"),
    ("material", "albedo and every parameter"),
    ("geometry", "N, V, objectId and occlusion"),
    ("error", "variance"),
    ("inputs", "masks and maps"),
    ("all", "every AOV"),
];

impl Aov {
    /// Every AOV, in the order they are written.
    pub fn all() -> Vec<Aov> {
        let mut all: Vec<Aov> = (0..LOBES.len()).map(Aov::Lobe).collect();
        all.push(Aov::Emission);
        all.push(Aov::Albedo);
        all.extend(Param::ALL.into_iter().filter(|p| *p != Param::Emission).map(Aov::Param));
        all.extend([
            Aov::Layers,
            Aov::Normal,
            Aov::View,
            Aov::ObjectId,
            Aov::Occlusion,
            Aov::Shadow,
            Aov::Variance,
            Aov::Masks,
            Aov::Maps,
        ]);
        all
    }

    /// The AOV's name, which is also its EXR layer's (for `layers`, the prefix of one per layer).
    pub fn name(self) -> String {
        match self {
            Aov::Lobe(k) => LOBES[k].to_string(),
            Aov::Emission => "emission".into(),
            Aov::Albedo => "albedo".into(),
            Aov::Param(p) => format!("param_{}", p.name()),
            Aov::Layers => "layers".into(),
            Aov::Normal => "N".into(),
            Aov::View => "V".into(),
            Aov::ObjectId => "objectId".into(),
            Aov::Occlusion => "occlusion".into(),
            Aov::Shadow => "shadow".into(),
            Aov::Variance => "variance".into(),
            Aov::Masks => "masks".into(),
            Aov::Maps => "maps".into(),
        }
    }

    /// The AOVs a name stands for: one, or a group. Unknown names list the names and suggest the
    /// closest.
    pub fn parse(name: &str) -> std::result::Result<Vec<Aov>, String> {
        let name = name.trim();
        let all = Aov::all();
        let group = match name {
            "light" => Some(all.iter().copied().filter(|a| matches!(a, Aov::Lobe(_) | Aov::Emission)).collect()),
            "material" => Some(all.iter().copied().filter(|a| matches!(a, Aov::Albedo | Aov::Param(_))).collect()),
            "geometry" => Some(vec![Aov::Normal, Aov::View, Aov::ObjectId, Aov::Occlusion]),
            "error" => Some(vec![Aov::Variance]),
            "inputs" => Some(vec![Aov::Masks, Aov::Maps]),
            "all" => Some(all.clone()),
            _ => None,
        };
        if let Some(group) = group {
            return Ok(group);
        }
        if let Some(aov) = all.iter().find(|a| a.name() == name) {
            return Ok(vec![*aov]);
        }
        // A parameter by its own name, where no light AOV has it (specular, clearcoat and sheen
        // are the lobes; their parameters are param_specular and so on).
        if let Some(param) = Param::from_name(name).filter(|p| *p != Param::Emission) {
            return Ok(vec![Aov::Param(param)]);
        }
        let mut names: Vec<String> = all.iter().map(|a| a.name()).collect();
        names.extend(GROUPS.iter().map(|(g, _)| g.to_string()));
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        Err(crate::suggest::unknown("AOV", name, "", &names))
    }

    /// Parses a list of names (from `--aov` or a look's `[render] aovs`), in the order of
    /// [`Aov::all`], each once.
    pub fn parse_all(names: &[String]) -> std::result::Result<Vec<Aov>, String> {
        let mut aovs = Vec::new();
        for name in names {
            aovs.extend(Aov::parse(name)?);
        }
        aovs.sort();
        aovs.dedup();
        Ok(aovs)
    }

    /// Whether a PNG shows it through exposure and the tone map (radiance and colours), rather
    /// than as the values themselves.
    pub fn is_radiance(self) -> bool {
        matches!(self, Aov::Lobe(_) | Aov::Emission | Aov::Albedo | Aov::Param(Param::BaseColor))
    }
}

/// What the relight kernel must accumulate for these AOVs.
pub fn accumulate(aovs: &[Aov]) -> Accumulate {
    Accumulate { lobes: aovs.iter().any(|a| matches!(a, Aov::Lobe(_))), variance: aovs.contains(&Aov::Variance) }
}

/// One EXR layer: its name and its channels (`R`, `G`, `B`, or `Y`), per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    pub name: String,
    pub channels: Vec<(&'static str, Vec<f32>)>,
}

impl Layer {
    fn color(name: impl Into<String>, values: impl Iterator<Item = [f32; 3]>) -> Layer {
        let values: Vec<[f32; 3]> = values.collect();
        let channel = |k: usize| values.iter().map(|v| v[k]).collect();
        Layer { name: name.into(), channels: vec![("R", channel(0)), ("G", channel(1)), ("B", channel(2))] }
    }

    fn scalar(name: impl Into<String>, values: Vec<f32>) -> Layer {
        Layer { name: name.into(), channels: vec![("Y", values)] }
    }
}

/// What the AOVs are computed from: the g-buffer, the look (its names resolved against the
/// g-buffer), and the renderer after its accumulation.
pub struct Sources<'a> {
    pub gbuffer: &'a GBuffer,
    pub look: &'a Look,
    pub renderer: &'a Renderer,
}

/// The AOVs' layers, in the order of `aovs`.
pub fn layers(aovs: &[Aov], sources: &Sources) -> Result<Vec<Layer>> {
    let g = sources.gbuffer;
    let coverage = &g.coverage;
    let premultiplied = |v: [f32; 3], a: f32| v.map(|c| c * a);
    let needs_material = aovs.iter().any(|a| matches!(a, Aov::Albedo | Aov::Param(_) | Aov::Emission));
    let materials: Vec<Params> = if needs_material {
        let resolved = sources.renderer.read_resolved()?;
        let pixels = g.pixel_count();
        (0..pixels)
            .map(|p| {
                let v: [f32; crate::material::params::GPU_FLOATS] =
                    std::array::from_fn(|k| resolved[(k / 4) * pixels + p][k % 4]);
                Params::from_gpu(&v)
            })
            .collect()
    } else {
        Vec::new()
    };
    let lobes = if aovs.iter().any(|a| matches!(a, Aov::Lobe(_))) {
        sources.renderer.read_lobes(coverage)?
    } else {
        Vec::new()
    };
    // A shadow catcher's pixels show no light of their own, so its light AOVs are 0 there.
    let shown: Vec<f32> = (0..g.pixel_count())
        .map(|p| {
            let catches = sources.look.stack_for(g.object_id[p]).is_some_and(|s| s.shadow_catcher);
            if catches {
                0.0
            } else {
                coverage[p]
            }
        })
        .collect();
    let mut out = Vec::new();
    for &aov in aovs {
        match aov {
            Aov::Lobe(k) => {
                let values = lobes[k].iter().zip(&shown).map(|(&v, &a)| premultiplied(v, a));
                out.push(Layer::color(aov.name(), values));
            }
            Aov::Emission => {
                let values = materials.iter().zip(&shown).map(|(m, &a)| premultiplied(m.emission, a));
                out.push(Layer::color(aov.name(), values));
            }
            Aov::Albedo => {
                let tables = AlbedoTables::build(sources.renderer.shading());
                let values = materials.iter().enumerate().map(|(p, m)| {
                    let mu = glam::Vec3::from(g.normal[p]).dot(glam::Vec3::from(g.view[p])).clamp(0.0, 1.0);
                    if coverage[p] > 0.0 {
                        tables.albedo(m, mu).to_array()
                    } else {
                        [0.0; 3]
                    }
                });
                out.push(Layer::color(aov.name(), values));
            }
            Aov::Param(param) => {
                let shaded = |p: usize| coverage[p] > 0.0;
                match param.is_color() {
                    true => out.push(Layer::color(
                        aov.name(),
                        (0..materials.len()).map(|p| if shaded(p) { color_of(&materials[p], param) } else { [0.0; 3] }),
                    )),
                    false => out.push(Layer::scalar(
                        aov.name(),
                        (0..materials.len())
                            .map(|p| if shaded(p) { scalar_of(&materials[p], param) } else { 0.0 })
                            .collect(),
                    )),
                }
            }
            Aov::Layers => out.extend(layer_weight_layers(sources)),
            Aov::Normal => out.push(Layer::color(aov.name(), g.normal.iter().copied())),
            Aov::View => out.push(Layer::color(aov.name(), g.view.iter().copied())),
            Aov::ObjectId => out.push(Layer::scalar(aov.name(), g.object_id.iter().map(|&id| id as f32).collect())),
            Aov::Occlusion => out.push(Layer::scalar(aov.name(), crate::visibility::occlusion(g))),
            Aov::Shadow => out.push(Layer::color(aov.name(), sources.renderer.read_shadow()?.into_iter())),
            Aov::Variance => out.push(Layer::scalar(aov.name(), sources.renderer.read_variance(coverage)?)),
            Aov::Masks => {
                out.extend(g.masks.iter().map(|(name, values)| Layer::scalar(mask_layer(name), values.clone())))
            }
            Aov::Maps => out.extend(map_layers(g)),
        }
    }
    Ok(out)
}

/// The layer a g-buffer mask is written as: `mask_<name>`.
pub fn mask_layer(mask: &str) -> String {
    format!("mask_{}", crate::asset::channel_name(mask))
}

/// The layer a g-buffer map (as [`GBuffer::maps`] names it) is written as: `map_<name>`.
pub fn map_layer(map: &str) -> String {
    format!("map_{}", crate::asset::channel_name(map))
}

/// One layer per map, as read: a colour map as RGB, a scalar map as Y.
fn map_layers(g: &GBuffer) -> Vec<Layer> {
    g.maps()
        .into_iter()
        .filter_map(|map| match g.map_source(&map.name)? {
            crate::gbuffer::MapSource::Color([r, gr, b]) => {
                let (r, gr, b) = (&g.maps[&r], &g.maps[&gr], &g.maps[&b]);
                Some(Layer::color(map_layer(&map.name), (0..r.len()).map(|p| [r[p], gr[p], b[p]])))
            }
            crate::gbuffer::MapSource::Channel(channel) => {
                Some(Layer::scalar(map_layer(&map.name), g.maps[&channel].clone()))
            }
        })
        .collect()
}

/// The names of the `layers` AOV's layers, in the order [`layers`] writes them, each with the
/// label of the stack it belongs to and the layer's index in it.
pub fn layer_weight_names(gbuffer: &GBuffer, look: &Look) -> Vec<String> {
    let mut names = Vec::new();
    for stack in &look.objects {
        let label = stack_label(stack, gbuffer);
        for (i, layer) in stack.layers.iter().enumerate() {
            names.push(format!("layers_{label}_{i}_{}", preset_label(layer.preset.as_deref())));
        }
    }
    names
}

/// A distinct colour per object id, as sRGB bytes (0, the background, black): a hash of the id,
/// so the same id has the same colour in every run and every tool.
pub fn id_colour(id: u32) -> [u8; 3] {
    if id == 0 {
        return [0; 3];
    }
    let h = id.wrapping_mul(0x9e37_79b9);
    [(h >> 24) as u8 | 0x40, (h >> 16) as u8 | 0x40, (h >> 8) as u8 | 0x40]
}

fn color_of(m: &Params, param: Param) -> [f32; 3] {
    match m.get(param) {
        crate::material::Value::Color(c) => c,
        crate::material::Value::Scalar(x) => [x; 3],
    }
}

fn scalar_of(m: &Params, param: Param) -> f32 {
    match m.get(param) {
        crate::material::Value::Scalar(x) => x,
        crate::material::Value::Color(c) => c[0],
    }
}

/// The name a stack's layers are written under: `default`, the object's name, or `object<id>`.
fn stack_label(stack: &ObjectStack, gbuffer: &GBuffer) -> String {
    let name = match (&stack.name, stack.id) {
        (Some(name), _) => name.clone(),
        (None, Some(id)) => gbuffer.object_names.get(&id).cloned().unwrap_or_else(|| format!("object{id}")),
        (None, None) => "default".into(),
    };
    crate::asset::channel_name(&name)
}

/// One layer per layer of every stack: `layers_<stack>_<index>_<preset>.Y`, the layer's weight
/// in the blend where that stack shades: its share of the resolved material (the matte of where
/// it shows), so a stack's layers sum to 1 there; 0 elsewhere.
fn layer_weight_layers(sources: &Sources) -> Vec<Layer> {
    let g = sources.gbuffer;
    let look = sources.look;
    let mut out = Vec::new();
    for stack in &look.objects {
        let label = stack_label(stack, g);
        let values = layer_shares(look, stack, g);
        let names = stack
            .layers
            .iter()
            .enumerate()
            .map(|(i, layer)| format!("layers_{label}_{i}_{}", preset_label(layer.preset.as_deref())));
        for (name, values) in names.zip(values) {
            out.push(Layer::scalar(name, values));
        }
    }
    out
}

/// A layer's preset as a channel name: a preset file by its stem (`presets/brass.toml` is
/// `brass`), a library preset by its name, and `layer` for a layer without one.
fn preset_label(preset: Option<&str>) -> String {
    let name = match preset {
        Some(file) if file.ends_with(".toml") => {
            std::path::Path::new(file).file_stem().and_then(|s| s.to_str()).unwrap_or(file)
        }
        Some(name) => name,
        None => "layer",
    };
    crate::asset::channel_name(name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layers_are_named_by_their_presets() {
        assert_eq!(preset_label(Some("gold")), "gold");
        assert_eq!(preset_label(Some("presets/material_004.toml")), "material_004");
        assert_eq!(preset_label(Some("../looks/Rusty Metal.toml")), "Rusty_Metal");
        assert_eq!(preset_label(None), "layer");
    }

    #[test]
    fn names_and_groups_parse() {
        assert_eq!(Aov::parse("specular").unwrap(), vec![Aov::Lobe(1)]);
        assert_eq!(Aov::parse("light").unwrap().len(), 5);
        assert_eq!(Aov::parse("roughness").unwrap(), vec![Aov::Param(Param::Roughness)]);
        assert_eq!(Aov::parse("param_specular").unwrap(), vec![Aov::Param(Param::Specular)]);
        assert_eq!(Aov::parse("specular").unwrap(), vec![Aov::Lobe(1)], "the lobe, not the parameter");
        let all = Aov::parse_all(&["N".into(), "light".into(), "diffuse".into()]).unwrap();
        assert_eq!(all.first(), Some(&Aov::Lobe(0)), "in the order written, each once");
        assert_eq!(all.iter().filter(|a| **a == Aov::Lobe(0)).count(), 1);
        let message = Aov::parse("specullar").unwrap_err();
        assert!(
            message.contains("unknown AOV 'specullar'") && message.contains("did you mean 'specular'?"),
            "{message}"
        );
    }
}
