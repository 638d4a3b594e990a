//! glTF materials as Disney 2012 parameters (each formula is given in
//! docs/commands.md#the-material-mapping), and what the bake needs to know of them.
//!
//! A preset holds the material's factors. Its textures become g-buffer maps ([`MapKind`]): the
//! bake samples each texture into the map of the parameter it drives, and the imported look
//! binds the parameter to it, so that the value at a pixel is glTF's factor × texture. Where a
//! Disney parameter is not linear in the texture, the map holds the parameter's own value (or
//! its ratio to the factor's), as [`MapKind`] says.

use super::names::{channel_name, unique};
use super::Asset;
use crate::material::{Param, Params};
use gltf::json::Value;

/// Largest values the look format allows (docs/formats.md#presets).
const SPECULAR_LIMIT: f32 = crate::material::params::SPECULAR_MAX;
const SHEEN_LIMIT: f32 = crate::material::params::SHEEN_MAX;
const CLEARCOAT_LIMIT: f32 = crate::material::params::CLEARCOAT_MAX;

/// A material the scene's primitives use, and the names derived from it.
#[derive(Clone, Debug, PartialEq)]
pub struct UsedMaterial {
    /// The glTF material index; `None` for glTF's default material.
    pub index: Option<usize>,
    /// The material's own name, or "material N" / "default material".
    pub label: String,
    /// Its mask channel, `mask.<channel>`.
    pub channel: String,
    /// Its preset's name.
    pub preset: String,
}

/// The materials of the scene's primitives (in draw order), in order of first use, with unique
/// names. The bake and the import both call it, so their mask and preset names agree.
pub fn used(asset: &Asset, materials: impl IntoIterator<Item = Option<usize>>) -> Vec<UsedMaterial> {
    let mut indices: Vec<Option<usize>> = Vec::new();
    for material in materials {
        if !indices.contains(&material) {
            indices.push(material);
        }
    }
    let (mut channels, mut presets) = (Vec::new(), Vec::new());
    indices
        .into_iter()
        .map(|index| {
            let label = match index.and_then(|i| asset.document.materials().nth(i)) {
                Some(material) => material
                    .name()
                    .map_or_else(|| format!("material {}", material.index().unwrap_or(0)), str::to_string),
                None => "default material".to_string(),
            };
            let base = channel_name(&label);
            let channel = unique(base.clone(), &mut channels, |a, b| a == b);
            let preset = unique(base.to_ascii_lowercase(), &mut presets, |a, b| a == b);
            UsedMaterial { index, label, channel, preset }
        })
        .collect()
}

/// The material of this index, or glTF's default material for `None`.
pub fn material_of(asset: &Asset, index: Option<usize>) -> gltf::Material<'_> {
    match index {
        Some(i) => asset.document.materials().nth(i).expect("material indices are validated"),
        None => asset
            .document
            .meshes()
            .flat_map(|m| m.primitives())
            .map(|p| p.material())
            .find(|m| m.index().is_none())
            .expect("a primitive uses the default material"),
    }
}

/// A group of maps the bake writes for a material with the textures that drive them, and the
/// parameters the imported look binds to them. Each map channel is in \[0, 1\]:
///
/// | kind | maps | value at a sample |
/// |---|---|---|
/// | base colour | `base_color.R/G/B` | the base colour texel (linear) × `COLOR_0` |
/// | metallic-roughness | `metallic`, `roughness` | the texel's B and G |
/// | emission | `emission.R/G/B` | the emissive texel (linear) |
/// | clearcoat | `clearcoat` | the clearcoat texel's R |
/// | clearcoat gloss | `clearcoat_gloss` | gloss of `clearcoatRoughnessFactor` × the texel's G, itself (the preset's factor is 1) |
/// | sheen | `sheen`, `sheen_tint` | the sheen colour's luminance over the factor's; the fitted tint itself (the preset's is 1) |
/// | specular | `specular` | `specularTexture`'s A × the luminance of the specular colour over the factor's |
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum MapKind {
    BaseColor,
    MetallicRoughness,
    Emission,
    Clearcoat,
    ClearcoatGloss,
    Sheen,
    Specular,
}

/// One map channel the bake writes: its name (without `map.`), its kind, and where the maps
/// pass's fragment shader puts it (target, component).
pub struct MapChannel {
    pub name: &'static str,
    pub kind: MapKind,
    pub target: usize,
    pub component: usize,
}

const fn channel(name: &'static str, kind: MapKind, target: usize, component: usize) -> MapChannel {
    MapChannel { name, kind, target, component }
}

/// Every map channel, in the layout of `glsl/bake_maps.frag`'s four targets.
pub const MAP_CHANNELS: [MapChannel; 13] = [
    channel("base_color.R", MapKind::BaseColor, 0, 0),
    channel("base_color.G", MapKind::BaseColor, 0, 1),
    channel("base_color.B", MapKind::BaseColor, 0, 2),
    channel("emission.R", MapKind::Emission, 1, 0),
    channel("emission.G", MapKind::Emission, 1, 1),
    channel("emission.B", MapKind::Emission, 1, 2),
    channel("metallic", MapKind::MetallicRoughness, 2, 0),
    channel("roughness", MapKind::MetallicRoughness, 2, 1),
    channel("clearcoat", MapKind::Clearcoat, 2, 2),
    channel("clearcoat_gloss", MapKind::ClearcoatGloss, 2, 3),
    channel("sheen", MapKind::Sheen, 3, 0),
    channel("sheen_tint", MapKind::Sheen, 3, 1),
    channel("specular", MapKind::Specular, 3, 2),
];

impl MapKind {
    pub const ALL: [MapKind; 7] = [
        MapKind::BaseColor,
        MapKind::MetallicRoughness,
        MapKind::Emission,
        MapKind::Clearcoat,
        MapKind::ClearcoatGloss,
        MapKind::Sheen,
        MapKind::Specular,
    ];

    /// The bit of this kind in the bake's per-material mask (`glsl/include/bake_material.glsl`).
    pub fn bit(self) -> u32 {
        1 << self as u32
    }

    /// The parameters a look binds for this kind, each with the map's name.
    pub fn bindings(self) -> &'static [(Param, &'static str)] {
        match self {
            MapKind::BaseColor => &[(Param::BaseColor, "base_color")],
            MapKind::MetallicRoughness => &[(Param::Metallic, "metallic"), (Param::Roughness, "roughness")],
            MapKind::Emission => &[(Param::Emission, "emission")],
            MapKind::Clearcoat => &[(Param::Clearcoat, "clearcoat")],
            MapKind::ClearcoatGloss => &[(Param::ClearcoatGloss, "clearcoat_gloss")],
            MapKind::Sheen => &[(Param::Sheen, "sheen"), (Param::SheenTint, "sheen_tint")],
            MapKind::Specular => &[(Param::Specular, "specular")],
        }
    }
}

/// The map kinds a material needs: one for each of its textures that drives a parameter, and
/// base colour too where `COLOR_0` tints it.
pub fn map_kinds(material: &gltf::Material, vertex_colors: bool) -> Vec<MapKind> {
    use super::textures::{material_textures, Slot};
    let textures = material_textures(material);
    let has = |slot: Slot| textures[slot as usize].is_some();
    let base_color_varies = has(Slot::BaseColor) || vertex_colors;
    let sheen = extension(material, "KHR_materials_sheen").is_some_and(|ext| sheen_color(ext) != [0.0; 3]);
    let mut kinds = Vec::new();
    let mut add = |kind: MapKind, needed: bool| {
        if needed {
            kinds.push(kind);
        }
    };
    add(MapKind::BaseColor, base_color_varies);
    add(MapKind::MetallicRoughness, has(Slot::MetallicRoughness));
    add(MapKind::Emission, has(Slot::Emissive) && emission(material) != [0.0; 3]);
    add(MapKind::Clearcoat, has(Slot::Clearcoat));
    add(MapKind::ClearcoatGloss, has(Slot::ClearcoatRoughness));
    // The tint follows the base colour, so a varying base colour varies it too.
    add(MapKind::Sheen, sheen && (has(Slot::SheenColor) || base_color_varies));
    add(MapKind::Specular, has(Slot::Specular) || has(Slot::SpecularColor));
    kinds
}

/// KHR_materials_anisotropy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Anisotropy {
    pub strength: f32,
    /// Radians, counter-clockwise from the tangent toward the bitangent.
    pub rotation: f32,
    pub textured: bool,
}

/// A number from an extension's JSON object.
fn number(extension: &Value, key: &str) -> Option<f32> {
    extension.get(key).and_then(Value::as_f64).map(|v| v as f32)
}

fn extension<'a>(material: &'a gltf::Material, name: &str) -> Option<&'a Value> {
    material.extension_value(name)
}

pub fn anisotropy(material: &gltf::Material) -> Option<Anisotropy> {
    let ext = extension(material, "KHR_materials_anisotropy")?;
    Some(Anisotropy {
        strength: number(ext, "anisotropyStrength").unwrap_or(0.0).clamp(0.0, 1.0),
        rotation: number(ext, "anisotropyRotation").unwrap_or(0.0),
        textured: ext.get("anisotropyTexture").is_some(),
    })
}

/// A glTF material on the Disney parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Mapped {
    /// The preset: the factors, where a texture's map multiplies them.
    pub params: Params,
    /// The maps its textures (and vertex colours) become, in [`MapKind::ALL`] order.
    pub maps: Vec<MapKind>,
    /// What the preset and its maps cannot hold, one sentence each.
    pub notes: Vec<String>,
    /// The extensions the material uses that lookdev ignores.
    pub unsupported: Vec<String>,
}

fn luminance(c: [f32; 3]) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// KHR_materials_sheen's colour factor.
fn sheen_color(ext: &Value) -> [f32; 3] {
    ext.get("sheenColorFactor")
        .and_then(Value::as_array)
        .map(|a| [0, 1, 2].map(|k| a.get(k).and_then(Value::as_f64).unwrap_or(0.0) as f32))
        .unwrap_or([0.0; 3])
}

/// The emitted radiance: `emissiveFactor` × KHR_materials_emissive_strength, within the
/// format's limit.
fn emission(material: &gltf::Material) -> [f32; 3] {
    let strength = extension(material, "KHR_materials_emissive_strength")
        .and_then(|ext| number(ext, "emissiveStrength"))
        .unwrap_or(1.0)
        .max(0.0);
    material.emissive_factor().map(|f| (f * strength).clamp(0.0, crate::material::params::EMISSION_MAX))
}

/// GTR1's gloss for the coat's GGX roughness r: the α mix(0.1, 0.001, gloss) matched to r².
pub fn clearcoat_gloss(roughness: f32) -> f32 {
    ((0.1 - roughness * roughness) / 0.099).clamp(0.0, 1.0)
}

/// Maps a material (or glTF's default material) onto the Disney parameters. `vertex_colors`:
/// whether a primitive with `COLOR_0` uses it.
pub fn map(material: &gltf::Material, vertex_colors: bool) -> Mapped {
    use super::textures::{material_textures, Slot};
    let textures = material_textures(material);
    let maps = map_kinds(material, vertex_colors);
    let mut notes = Vec::new();
    let pbr = material.pbr_metallic_roughness();
    let factor = pbr.base_color_factor();
    let base_color = [factor[0], factor[1], factor[2]];
    let (metallic, roughness) = (pbr.metallic_factor(), pbr.roughness_factor());

    // Specular: the dielectric F0 of the IOR, scaled by KHR_materials_specular.
    let ior = material.ior().unwrap_or(1.5).max(1.0);
    let mut f0 = ((ior - 1.0) / (ior + 1.0)).powi(2);
    if let Some(specular) = material.specular() {
        let color = specular.specular_color_factor();
        f0 = (f0 * luminance(color)).min(1.0) * specular.specular_factor();
        if color.iter().any(|&c| (c - color[0]).abs() > 1e-3) || textures[Slot::SpecularColor as usize].is_some() {
            notes.push(
                "the specular colour is reduced to its luminance: Disney's specular tints only toward the base colour"
                    .into(),
            );
        }
    }
    let specular = clamp_noted(f0 / 0.08, SPECULAR_LIMIT, "specular", &mut notes);

    let mut params = Params {
        base_color,
        metallic,
        roughness,
        specular,
        specular_tint: 0.0,
        emission: emission(material),
        ..Params::default()
    };
    params.subsurface = 0.0;

    if let Some(ext) = extension(material, "KHR_materials_clearcoat") {
        let strength = number(ext, "clearcoatFactor").unwrap_or(0.0);
        let coat_roughness = number(ext, "clearcoatRoughnessFactor").unwrap_or(0.0);
        // Disney's clearcoat lobe carries a 0.25 weight: a full glTF coat is clearcoat 4.
        params.clearcoat = clamp_noted(4.0 * strength, CLEARCOAT_LIMIT, "clearcoat", &mut notes);
        // Not linear in the texture: the map holds the gloss itself.
        params.clearcoat_gloss =
            if maps.contains(&MapKind::ClearcoatGloss) { 1.0 } else { clearcoat_gloss(coat_roughness) };
        if ext.get("clearcoatNormalTexture").is_some() {
            notes.push("the clearcoat normal map is not carried over (the coat uses the base normal)".into());
        }
    }
    if let Some(ext) = extension(material, "KHR_materials_sheen") {
        let color = sheen_color(ext);
        params.sheen = clamp_noted(luminance(color), SHEEN_LIMIT, "sheen", &mut notes);
        // The tint depends on the base colour: where that is a map, the sheen_tint map holds it.
        params.sheen_tint = if maps.contains(&MapKind::Sheen) { 1.0 } else { sheen_tint(color, base_color) };
        if let Some(r) = number(ext, "sheenRoughnessFactor") {
            notes.push(format!("sheen roughness {r} has no Disney counterpart (the sheen lobe has one shape)"));
        }
    }
    if let Some(a) = anisotropy(material) {
        let alpha = params.roughness * params.roughness;
        params.anisotropic = disney_anisotropic(a.strength, alpha);
        if a.rotation != 0.0 {
            notes.push(format!("the anisotropy rotation {} rad is baked into the g-buffer's tangents", a.rotation));
        }
        if a.textured {
            notes.push("the anisotropy texture is not carried over".into());
        }
        if maps.contains(&MapKind::MetallicRoughness) && a.strength > 0.0 {
            notes.push(
                "anisotropic is fitted to the roughness factor; where the roughness map is lower, the highlight is less stretched than glTF's"
                    .into(),
            );
        }
    }
    if material.occlusion_texture().is_some() {
        notes.push("the occlusion texture is not carried over".into());
    }
    if material.alpha_mode() == gltf::material::AlphaMode::Blend {
        notes.push("alpha blending is baked as opaque".into());
    }
    let unsupported: Vec<String> = material
        .extensions()
        .map(|map| map.keys().filter(|k| !super::SUPPORTED_EXTENSIONS.contains(&k.as_str())).cloned().collect())
        .unwrap_or_default();
    for name in &unsupported {
        notes.push(format!("{name} is not supported"));
    }
    Mapped { params: clamp_params(params), maps, notes, unsupported }
}

/// Disney's anisotropic, from KHR_materials_anisotropy's strength s at GGX alpha α: the same
/// ratio of the two alphas. glTF stretches α along the direction to mix(α, 1, s²); Disney's are
/// α/aspect and α·aspect with aspect = √(1 − 0.9·anisotropic), a ratio of 1/aspect².
pub fn disney_anisotropic(strength: f32, alpha: f32) -> f32 {
    let alpha = alpha.max(1e-6);
    let stretched = alpha + strength * strength * (1.0 - alpha);
    ((1.0 - alpha / stretched) / 0.9).clamp(0.0, 1.0)
}

/// Disney's sheen_tint that best matches the sheen's hue: Csheen = mix(1, Ctint, t), where Ctint
/// is the base colour over its luminance, fitted to the sheen colour over its luminance by least
/// squares.
pub fn sheen_tint(sheen: [f32; 3], base_color: [f32; 3]) -> f32 {
    let (lum_sheen, lum_base) = (luminance(sheen), luminance(base_color));
    if lum_sheen <= 0.0 || lum_base <= 0.0 {
        return 0.0;
    }
    let target = sheen.map(|c| c / lum_sheen - 1.0);
    let tint = base_color.map(|c| c / lum_base - 1.0);
    let denominator: f32 = tint.iter().map(|t| t * t).sum();
    if denominator < 1e-8 {
        return 0.0;
    }
    let numerator: f32 = target.iter().zip(&tint).map(|(a, b)| a * b).sum();
    (numerator / denominator).clamp(0.0, 1.0)
}

fn clamp_noted(value: f32, limit: f32, name: &str, notes: &mut Vec<String>) -> f32 {
    if value > limit {
        notes.push(format!("{name} {value} is clamped to the format's limit {limit}"));
    }
    value.clamp(0.0, limit)
}

/// Keeps every parameter within what the look format accepts (glTF allows values out of range).
fn clamp_params(mut p: Params) -> Params {
    p.base_color = p.base_color.map(|c| c.clamp(0.0, 1.0));
    for v in [&mut p.metallic, &mut p.roughness, &mut p.sheen_tint, &mut p.clearcoat_gloss, &mut p.anisotropic] {
        *v = v.clamp(0.0, 1.0);
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn anisotropy_matches_the_ratio_of_alphas() {
        assert_eq!(disney_anisotropic(0.0, 0.25), 0.0, "no strength, no anisotropy");
        for (strength, alpha) in [(0.5f32, 0.09f32), (1.0, 0.25), (0.3, 0.5)] {
            let a = disney_anisotropic(strength, alpha);
            let aspect = (1.0 - 0.9 * a).sqrt();
            let disney_ratio = 1.0 / (aspect * aspect);
            let gltf_ratio = (alpha + strength * strength * (1.0 - alpha)) / alpha;
            assert!((disney_ratio - gltf_ratio.min(10.0)).abs() < 1e-3 * gltf_ratio, "{strength} {alpha}: {a}");
        }
    }

    #[test]
    fn sheen_tint_follows_the_sheen_hue() {
        assert_eq!(sheen_tint([0.5, 0.5, 0.5], [0.8, 0.2, 0.1]), 0.0, "a white sheen is untinted");
        let base = [0.8, 0.2, 0.1];
        let lum = luminance(base);
        let same_hue = base.map(|c| c / lum * 0.3);
        assert!((sheen_tint(same_hue, base) - 1.0).abs() < 1e-5, "the base colour's hue is full tint");
    }
}
