//! glTF materials as Disney 2012 parameters (README: lookdev import, where each formula is
//! given), and what the bake needs to know of them.
//!
//! A preset holds constants, so a material's textures become a constant (the texture's mean)
//! and, where they vary, mask-driven layers: each textured parameter is an [`Axis`], the bake
//! writes each texel's position along the axes and the weights of the corner layers as masks,
//! and the look blends layers whose only difference is the textured parameters. Metallic and
//! roughness are reproduced exactly; a base colour texture along its main colour axis.

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

/// A texture-driven parameter the look carries through masks (README: Texture layers).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Axis {
    /// metallic = factor × the texture's blue channel.
    Metallic { factor: f32 },
    /// roughness = factor × the texture's green channel.
    Roughness { factor: f32 },
    /// base_color = mix(from, to, t), with t the texel's position along the line from `from` to
    /// `to`: the texture's main colour axis (its first principal component).
    BaseColor { from: [f32; 3], to: [f32; 3] },
}

impl Axis {
    /// The word in mask names.
    pub fn name(&self) -> &'static str {
        match self {
            Axis::Metallic { .. } => "metallic",
            Axis::Roughness { .. } => "roughness",
            Axis::BaseColor { .. } => "base_color",
        }
    }

    /// Sets the parameter to its value at the axis's start (`end` false) or end.
    pub fn apply(&self, params: &mut Params, end: bool) {
        match *self {
            Axis::Metallic { factor } => params.metallic = if end { factor } else { 0.0 },
            Axis::Roughness { factor } => params.roughness = if end { factor } else { 0.0 },
            Axis::BaseColor { from, to } => params.base_color = if end { to } else { from },
        }
    }

    /// Where a texel's value lies along the axis, in [0, 1]. `metal_rough` is the
    /// metallic-roughness texel's (blue, green), `color` the base colour texel, linear and
    /// multiplied by the factor.
    pub fn position(&self, metal_rough: [f32; 2], color: [f32; 3]) -> f32 {
        match *self {
            Axis::Metallic { .. } => metal_rough[0],
            Axis::Roughness { .. } => metal_rough[1],
            Axis::BaseColor { from, to } => {
                let direction = [0, 1, 2].map(|k| to[k] - from[k]);
                let length2: f32 = direction.iter().map(|d| d * d).sum();
                let along: f32 = (0..3).map(|k| (color[k] - from[k]) * direction[k]).sum();
                if length2 > 0.0 {
                    (along / length2).clamp(0.0, 1.0)
                } else {
                    0.0
                }
            }
        }
    }
}

/// The mask holding a texture's raw value along one axis: `<channel>.<axis>`.
pub fn value_mask(channel: &str, axis: &Axis) -> String {
    format!("{channel}.{}", axis.name())
}

/// The mask of the corner layer `corner` (a bit set over `axes`, never 0):
/// `<channel>.layer_<axis>_<axis>…`, naming the axes at their end.
pub fn corner_mask(channel: &str, axes: &[Axis], corner: usize) -> String {
    let names: Vec<&str> =
        axes.iter().enumerate().filter(|(i, _)| corner & (1 << i) != 0).map(|(_, a)| a.name()).collect();
    format!("{channel}.layer_{}", names.join("_"))
}

/// The weights of the corner layers 1 .. 2^d at a texel whose positions along the `d` axes are
/// `x`: each corner's multilinear share β_k = Π (x_i or 1 − x_i), over the shares of the
/// corners stacked below it and itself, β_k / (β_0 + … + β_k). Blending the corners in order
/// with these weights gives every axis its value exactly.
pub fn corner_weights(x: &[f32]) -> Vec<f32> {
    let corners = 1usize << x.len();
    let share =
        |k: usize| -> f32 { x.iter().enumerate().map(|(i, &v)| if k & (1 << i) != 0 { v } else { 1.0 - v }).product() };
    let mut below = share(0);
    (1..corners)
        .map(|k| {
            let beta = share(k);
            below += beta;
            if below > 0.0 {
                beta / below
            } else {
                0.0
            }
        })
        .collect()
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
    /// The preset: the best constant, with each texture at its mean.
    pub params: Params,
    /// The textured parameters the look carries through corner layers, in this order.
    pub axes: Vec<Axis>,
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

/// sRGB-encoded 8-bit values decoded to linear, as a table.
pub fn srgb_decode_table() -> [f32; 256] {
    std::array::from_fn(|i| {
        let c = i as f64 / 255.0;
        (if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }) as f32
    })
}

/// What a base colour texture (times its factor) holds: its mean linear colour, and its main
/// colour axis when its colours vary.
struct ColorStatistics {
    mean: [f32; 3],
    /// The axis's ends: the texels projected onto the first principal component span them.
    axis: Option<([f32; 3], [f32; 3])>,
    /// The share of the colours' variance along the axis.
    explained: f32,
}

/// A colour spread less than this along the main axis (linear units) is a constant.
const COLOR_VARIATION: f32 = 0.01;

fn color_statistics(image: &image::RgbaImage, factor: [f32; 3]) -> ColorStatistics {
    let table = srgb_decode_table();
    let texel = |p: &image::Rgba<u8>| [0, 1, 2].map(|k| (table[p.0[k] as usize] * factor[k]) as f64);
    let n = (image.width() as f64 * image.height() as f64).max(1.0);
    let mut sum = [0.0f64; 3];
    for p in image.pixels() {
        let c = texel(p);
        (0..3).for_each(|k| sum[k] += c[k]);
    }
    let mean = sum.map(|s| s / n);
    let mut covariance = [[0.0f64; 3]; 3];
    for p in image.pixels() {
        let c = texel(p);
        for i in 0..3 {
            for j in 0..3 {
                covariance[i][j] += (c[i] - mean[i]) * (c[j] - mean[j]) / n;
            }
        }
    }
    // The first principal component, by power iteration from the diagonal's largest axis.
    let trace = covariance[0][0] + covariance[1][1] + covariance[2][2];
    let start = (0..3).max_by(|&a, &b| covariance[a][a].total_cmp(&covariance[b][b])).unwrap_or(0);
    let mut e = [0.0f64; 3];
    e[start] = 1.0;
    for _ in 0..64 {
        let next: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| covariance[i][j] * e[j]).sum());
        let length = next.iter().map(|v| v * v).sum::<f64>().sqrt();
        if length == 0.0 {
            break;
        }
        e = next.map(|v| v / length);
    }
    let along = |c: [f64; 3]| (0..3).map(|k| (c[k] - mean[k]) * e[k]).sum::<f64>();
    let (mut low, mut high) = (f64::MAX, f64::MIN);
    for p in image.pixels() {
        let t = along(texel(p));
        low = low.min(t);
        high = high.max(t);
    }
    let variance_along: f64 = (0..3).map(|i| (0..3).map(|j| e[i] * covariance[i][j] * e[j]).sum::<f64>()).sum();
    let point = |t: f64| [0, 1, 2].map(|k| (mean[k] + t * e[k]).clamp(0.0, 1.0) as f32);
    let spread = (high - low) as f32;
    ColorStatistics {
        mean: mean.map(|m| m as f32),
        axis: (spread > COLOR_VARIATION).then(|| (point(low), point(high))),
        explained: if trace > 0.0 { (variance_along / trace) as f32 } else { 1.0 },
    }
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
    let mut axes = Vec::new();
    let (metallic_factor, roughness_factor) = (pbr.metallic_factor(), pbr.roughness_factor());
    let (mut metallic, mut roughness) = (metallic_factor, roughness_factor);
    if let Some(info) = pbr.metallic_roughness_texture() {
        let [(metal_mean, metal_min, metal_max), (rough_mean, rough_min, rough_max)] =
            metal_rough_statistics(asset.texture_image(&info.texture()));
        metallic *= metal_mean;
        roughness *= rough_mean;
        if metal_max - metal_min > VARIATION {
            axes.push(Axis::Metallic { factor: metallic_factor });
        }
        if rough_max - rough_min > VARIATION {
            axes.push(Axis::Roughness { factor: roughness_factor });
        }
        if !axes.is_empty() {
            notes.push(
                "the preset holds the metallic-roughness texture's means; the look layers the texture in through masks"
                    .into(),
            );
        }
    }
    if let Some(info) = pbr.base_color_texture() {
        let statistics = color_statistics(asset.texture_image(&info.texture()), base_color);
        base_color = statistics.mean;
        if let Some((from, to)) = statistics.axis {
            axes.push(Axis::BaseColor { from, to });
            notes.push(format!(
                "the preset holds the base colour texture's mean; the look layers the texture in along its main colour axis, which holds {:.0}% of its variance",
                100.0 * statistics.explained
            ));
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
    Mapped { params: clamp_params(params), axes, notes, unsupported }
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
