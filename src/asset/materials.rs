//! glTF materials as Disney 2012 parameters (README: lookdev import, where each formula is
//! given), and what the bake needs to know of them.
//!
//! A preset holds constants, so a material's textures become either a constant (the texture's
//! mean) or, for metallic and roughness, mask-driven layers that reproduce the texture exactly:
//! the bake writes the texture's channels (and two products of them) as masks, and the look blends
//! layers whose only difference is the textured parameter.

use super::names::{channel_name, unique};
use super::Asset;
use crate::material::Params;
use gltf::json::Value;

/// Largest values the look format allows (README: Presets).
const SPECULAR_LIMIT: f32 = crate::material::params::SPECULAR_MAX;
const SHEEN_LIMIT: f32 = crate::material::params::SHEEN_MAX;
const CLEARCOAT_LIMIT: f32 = crate::material::params::CLEARCOAT_MAX;
/// A texture channel that varies less than this (two 8-bit steps) is a constant.
const VARIATION: f32 = 2.0 / 255.0;

/// A material the scene's primitives use, and the names derived from it.
#[derive(Clone, Debug, PartialEq)]
pub struct UsedMaterial {
    /// The glTF material index; `None` for glTF's default material.
    pub index: Option<usize>,
    /// The material's own name, or "material N" / "default material".
    pub label: String,
    /// Its mask channel, `mask.<channel>`, and the prefix of its texture masks.
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

/// The texture masks of a material with a metallic-roughness texture (README: lookdev bake).
pub fn metallic_mask(channel: &str) -> String {
    format!("{channel}.metallic")
}
pub fn roughness_mask(channel: &str) -> String {
    format!("{channel}.roughness")
}
/// (1 − metallic)·roughness / (1 − metallic·roughness): the weight of the rough dielectric
/// corner layer.
pub fn rough_dielectric_mask(channel: &str) -> String {
    format!("{channel}.rough_dielectric")
}
/// metallic·roughness: the weight of the rough metal corner layer.
pub fn rough_metal_mask(channel: &str) -> String {
    format!("{channel}.rough_metal")
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

/// How a metallic-roughness texture is carried into the look.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TextureLayers {
    /// No texture, or one whose channels are constant (folded into the preset).
    None,
    /// Metallic varies: a layer with `metallic` = the factor, through `<channel>.metallic`, over
    /// a base with metallic 0.
    Metallic { factor: f32 },
    /// Roughness varies: a layer with `roughness` = the factor, through `<channel>.roughness`.
    Roughness { factor: f32 },
    /// Both vary: three layers, the corners (factor, 0), (0, factor) and (factor, factor) of
    /// (metallic, roughness) over a (0, 0) base, through `.metallic`, `.rough_dielectric` and
    /// `.rough_metal`: bilinear interpolation, exact for every texel.
    Both { metallic: f32, roughness: f32 },
}

/// A glTF material on the Disney parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Mapped {
    /// The preset: the best constant, with each texture at its mean.
    pub params: Params,
    pub layers: TextureLayers,
    /// What the preset cannot hold, one sentence each.
    pub notes: Vec<String>,
    /// The extensions the material uses that lookdev ignores.
    pub unsupported: Vec<String>,
}

/// The mean, the least and the greatest of a texture's blue (metallic) and green (roughness).
fn metal_rough_statistics(image: &image::RgbaImage) -> [(f32, f32, f32); 2] {
    let mut stats = [(0.0f64, 1.0f32, 0.0f32); 2];
    for pixel in image.pixels() {
        for (k, channel) in [2usize, 1].into_iter().enumerate() {
            let v = pixel.0[channel] as f32 / 255.0;
            stats[k].0 += v as f64;
            stats[k].1 = stats[k].1.min(v);
            stats[k].2 = stats[k].2.max(v);
        }
    }
    let n = (image.width() as f64 * image.height() as f64).max(1.0);
    stats.map(|(sum, min, max)| ((sum / n) as f32, min, max))
}

/// The mean linear colour of an sRGB-encoded texture.
fn mean_linear_color(image: &image::RgbaImage) -> [f32; 3] {
    let decode = |c: u8| {
        let c = c as f64 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let table: Vec<f64> = (0..=255u8).map(decode).collect();
    let mut sum = [0.0f64; 3];
    for pixel in image.pixels() {
        for k in 0..3 {
            sum[k] += table[pixel.0[k] as usize];
        }
    }
    let n = (image.width() as f64 * image.height() as f64).max(1.0);
    sum.map(|s| (s / n) as f32)
}

fn luminance(c: [f32; 3]) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// Maps a material (or glTF's default material) onto the Disney parameters.
pub fn map(asset: &Asset, material: &gltf::Material) -> Mapped {
    let mut notes = Vec::new();
    let pbr = material.pbr_metallic_roughness();
    let factor = pbr.base_color_factor();
    let mut base_color = [factor[0], factor[1], factor[2]];
    if let Some(info) = pbr.base_color_texture() {
        let mean = mean_linear_color(asset.texture_image(&info.texture()));
        base_color = [0, 1, 2].map(|k| base_color[k] * mean[k]);
        notes.push("base_color is the base colour factor times the texture's mean colour".into());
    }
    let (metallic_factor, roughness_factor) = (pbr.metallic_factor(), pbr.roughness_factor());
    let (mut metallic, mut roughness) = (metallic_factor, roughness_factor);
    let mut layers = TextureLayers::None;
    if let Some(info) = pbr.metallic_roughness_texture() {
        let [(metal_mean, metal_min, metal_max), (rough_mean, rough_min, rough_max)] =
            metal_rough_statistics(asset.texture_image(&info.texture()));
        metallic *= metal_mean;
        roughness *= rough_mean;
        let (metal_varies, rough_varies) = (metal_max - metal_min > VARIATION, rough_max - rough_min > VARIATION);
        layers = match (metal_varies, rough_varies) {
            (false, false) => TextureLayers::None,
            (true, false) => TextureLayers::Metallic { factor: metallic_factor },
            (false, true) => TextureLayers::Roughness { factor: roughness_factor },
            (true, true) => TextureLayers::Both { metallic: metallic_factor, roughness: roughness_factor },
        };
        if layers != TextureLayers::None {
            notes.push(
                "metallic and roughness are the texture's means; the look layers the texture in through masks".into(),
            );
        }
    }

    // Specular: the dielectric F0 of the IOR, scaled by KHR_materials_specular.
    let ior = material.ior().unwrap_or(1.5).max(1.0);
    let mut f0 = ((ior - 1.0) / (ior + 1.0)).powi(2);
    if let Some(specular) = material.specular() {
        let color = specular.specular_color_factor();
        f0 = (f0 * luminance(color)).min(1.0) * specular.specular_factor();
        if color.iter().any(|&c| (c - color[0]).abs() > 1e-3) {
            notes.push(format!(
                "the specular colour {color:?} is reduced to its luminance: Disney's specular tints only toward the base colour"
            ));
        }
        if specular.specular_texture().is_some() || specular.specular_color_texture().is_some() {
            notes.push("the specular textures are not carried over".into());
        }
    }
    let specular = clamp_noted(f0 / 0.08, SPECULAR_LIMIT, "specular", &mut notes);

    let mut params = Params { base_color, metallic, roughness, specular, specular_tint: 0.0, ..Params::default() };
    params.subsurface = 0.0;

    if let Some(ext) = extension(material, "KHR_materials_clearcoat") {
        let strength = number(ext, "clearcoatFactor").unwrap_or(0.0);
        let coat_roughness = number(ext, "clearcoatRoughnessFactor").unwrap_or(0.0);
        // Disney's clearcoat lobe carries a 0.25 weight: a full glTF coat is clearcoat 4.
        params.clearcoat = clamp_noted(4.0 * strength, CLEARCOAT_LIMIT, "clearcoat", &mut notes);
        // Matching GTR1's alpha, mix(0.1, 0.001, gloss), to the coat's GGX alpha r².
        params.clearcoat_gloss = ((0.1 - coat_roughness * coat_roughness) / 0.099).clamp(0.0, 1.0);
        if ext.get("clearcoatTexture").is_some() || ext.get("clearcoatRoughnessTexture").is_some() {
            notes.push("the clearcoat textures are not carried over".into());
        }
        if ext.get("clearcoatNormalTexture").is_some() {
            notes.push("the clearcoat normal map is not carried over (the coat uses the base normal)".into());
        }
    }
    if let Some(ext) = extension(material, "KHR_materials_sheen") {
        let color = ext
            .get("sheenColorFactor")
            .and_then(Value::as_array)
            .map(|a| [0, 1, 2].map(|k| a.get(k).and_then(Value::as_f64).unwrap_or(0.0) as f32))
            .unwrap_or([0.0; 3]);
        let strength = luminance(color);
        params.sheen = clamp_noted(strength, SHEEN_LIMIT, "sheen", &mut notes);
        params.sheen_tint = sheen_tint(color, base_color);
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
    }
    if material.emissive_factor() != [0.0; 3] || material.emissive_texture().is_some() {
        notes.push("emission is not carried over: lookdev lights with the environment only".into());
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
    Mapped { params: clamp_params(params), layers, notes, unsupported }
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
