//! The textures a material samples: where each comes from (texture, texcoord set and
//! KHR_texture_transform), the colour space it is stored in, and the mip chain the bake samples.
//!
//! Core and specular textures are read through the `gltf` crate; the clearcoat and sheen
//! textures from their JSON, which [`super::Asset::load`] checks first, so that every index here
//! is valid.

use gltf::json::Value;
use image::RgbaImage;

/// The textures the bake samples, one slot each, in the order of `glsl/include/bake_material.glsl`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    Normal,
    BaseColor,
    MetallicRoughness,
    Emissive,
    Clearcoat,
    ClearcoatRoughness,
    SheenColor,
    Specular,
    SpecularColor,
}

/// The number of texture slots.
pub const SLOTS: usize = 9;

impl Slot {
    pub const ALL: [Slot; SLOTS] = [
        Slot::Normal,
        Slot::BaseColor,
        Slot::MetallicRoughness,
        Slot::Emissive,
        Slot::Clearcoat,
        Slot::ClearcoatRoughness,
        Slot::SheenColor,
        Slot::Specular,
        Slot::SpecularColor,
    ];

    /// The textureInfo's key in the glTF material, as messages name it.
    pub fn key(self) -> &'static str {
        match self {
            Slot::Normal => "normalTexture",
            Slot::BaseColor => "baseColorTexture",
            Slot::MetallicRoughness => "metallicRoughnessTexture",
            Slot::Emissive => "emissiveTexture",
            Slot::Clearcoat => "clearcoatTexture",
            Slot::ClearcoatRoughness => "clearcoatRoughnessTexture",
            Slot::SheenColor => "sheenColorTexture",
            Slot::Specular => "specularTexture",
            Slot::SpecularColor => "specularColorTexture",
        }
    }

    /// The extension holding the slot's textureInfo as JSON, for the extensions the `gltf` crate
    /// does not read itself (it reads KHR_materials_specular).
    fn extension(self) -> Option<&'static str> {
        match self {
            Slot::Clearcoat | Slot::ClearcoatRoughness => Some("KHR_materials_clearcoat"),
            Slot::SheenColor => Some("KHR_materials_sheen"),
            _ => None,
        }
    }

    /// Whether glTF stores the texture's colour sRGB-encoded (colours) rather than linear (data).
    pub fn is_srgb(self) -> bool {
        matches!(self, Slot::BaseColor | Slot::Emissive | Slot::SheenColor | Slot::SpecularColor)
    }
}

/// Where one texture is sampled: the glTF texture, the texcoord set, and the affine transform
/// of KHR_texture_transform.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    /// The glTF texture index.
    pub texture: usize,
    /// TEXCOORD_n: the transform's `texCoord` when it has one, else the textureInfo's.
    pub tex_coord: u32,
    /// The rows of the 2×3 matrix: u' = row0 · (u, v, 1), v' = row1 · (u, v, 1).
    pub transform: [[f32; 3]; 2],
}

/// The identity transform.
const IDENTITY: [[f32; 3]; 2] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

/// KHR_texture_transform's matrix, translation · rotation · scale: u' = cos·sx·u + sin·sy·v + ox,
/// v' = −sin·sx·u + cos·sy·v + oy. The rotation's sign is the one the TextureTransformTest sample
/// asset checks (its arrows reach their green markers) and the sample viewers use; the GLSL
/// listing in the extension's text reads the other way.
pub fn transform_matrix(offset: [f32; 2], rotation: f32, scale: [f32; 2]) -> [[f32; 3]; 2] {
    let (sin, cos) = rotation.sin_cos();
    [[cos * scale[0], sin * scale[1], offset[0]], [-sin * scale[0], cos * scale[1], offset[1]]]
}

fn number(value: &Value, key: &str) -> Option<f32> {
    value.get(key).and_then(Value::as_f64).map(|v| v as f32)
}

fn pair(value: &Value, key: &str) -> Option<[f32; 2]> {
    let items = value.get(key)?.as_array()?;
    Some([items.first()?.as_f64()? as f32, items.get(1)?.as_f64()? as f32])
}

impl TextureRef {
    /// A core textureInfo (base colour, metallic-roughness, emissive).
    fn from_info(info: &gltf::texture::Info) -> TextureRef {
        let mut reference =
            TextureRef { texture: info.texture().index(), tex_coord: info.tex_coord(), transform: IDENTITY };
        if let Some(t) = info.texture_transform() {
            reference.transform = transform_matrix(t.offset(), t.rotation(), t.scale());
            reference.tex_coord = t.tex_coord().unwrap_or(reference.tex_coord);
        }
        reference
    }

    /// A textureInfo given as JSON (the extensions' textures). `None` without a valid `index`.
    pub fn from_json(info: &Value) -> Option<TextureRef> {
        let texture = usize::try_from(info.get("index")?.as_u64()?).ok()?;
        let tex_coord = info.get("texCoord").and_then(Value::as_u64).unwrap_or(0) as u32;
        let reference = TextureRef { texture, tex_coord, transform: IDENTITY };
        Some(match info.get("extensions").and_then(|e| e.get("KHR_texture_transform")) {
            Some(transform) => reference.transformed_by(transform),
            None => reference,
        })
    }

    /// With the transform of a KHR_texture_transform object, whose `texCoord` overrides.
    fn transformed_by(self, t: &Value) -> TextureRef {
        let offset = pair(t, "offset").unwrap_or([0.0, 0.0]);
        let scale = pair(t, "scale").unwrap_or([1.0, 1.0]);
        TextureRef {
            transform: transform_matrix(offset, number(t, "rotation").unwrap_or(0.0), scale),
            tex_coord: t.get("texCoord").and_then(Value::as_u64).map_or(self.tex_coord, |c| c as u32),
            ..self
        }
    }
}

/// The texture indices of every textureInfo in a material's JSON (a `…Texture` key holding an
/// `index`), core and extensions alike, appended to `out`.
pub fn texture_indices(value: &Value, out: &mut Vec<u64>) {
    match value {
        Value::Object(map) => {
            for (key, inner) in map {
                if let Some(index) =
                    key.ends_with("Texture").then(|| inner.get("index")).flatten().and_then(Value::as_u64)
                {
                    out.push(index);
                }
                texture_indices(inner, out);
            }
        }
        Value::Array(items) => items.iter().for_each(|item| texture_indices(item, out)),
        _ => {}
    }
}

/// The JSON of a slot's textureInfo, where the material has one.
pub fn slot_json<'a>(material: &'a gltf::Material, slot: Slot) -> Option<&'a Value> {
    material.extension_value(slot.extension()?)?.get(slot.key())
}

/// Every texture a material samples, by slot.
pub fn material_textures(material: &gltf::Material) -> [Option<TextureRef>; SLOTS] {
    let pbr = material.pbr_metallic_roughness();
    Slot::ALL.map(|slot| match slot {
        Slot::BaseColor => pbr.base_color_texture().map(|t| TextureRef::from_info(&t)),
        Slot::MetallicRoughness => pbr.metallic_roughness_texture().map(|t| TextureRef::from_info(&t)),
        Slot::Emissive => material.emissive_texture().map(|t| TextureRef::from_info(&t)),
        Slot::Specular => material.specular().and_then(|s| s.specular_texture()).map(|t| TextureRef::from_info(&t)),
        Slot::SpecularColor => {
            material.specular().and_then(|s| s.specular_color_texture()).map(|t| TextureRef::from_info(&t))
        }
        Slot::Normal => material.normal_texture().map(|t| {
            let reference = TextureRef { texture: t.texture().index(), tex_coord: t.tex_coord(), transform: IDENTITY };
            match t.extension_value("KHR_texture_transform") {
                Some(transform) => reference.transformed_by(transform),
                None => reference,
            }
        }),
        _ => slot_json(material, slot).and_then(TextureRef::from_json),
    })
}

/// sRGB-encoded 8-bit values decoded to linear, as a table.
pub fn srgb_decode_table() -> [f32; 256] {
    std::array::from_fn(|i| {
        let c = i as f64 / 255.0;
        (if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }) as f32
    })
}

/// A linear value in [0, 1] encoded as the nearest sRGB 8-bit value.
fn srgb_encode(linear: f32) -> u8 {
    let c = linear.clamp(0.0, 1.0) as f64;
    let encoded = if c <= 0.003_130_8 { c * 12.92 } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    (encoded * 255.0).round() as u8
}

/// The image and its mip levels down to 1×1, each the mean of the 2×2 texels above it (the
/// last row or column of an odd size folded into its neighbour's). Colour textures are
/// averaged in linear light, as a GPU filters an sRGB image; alpha and data linearly.
pub fn mip_chain(image: &RgbaImage, srgb: bool) -> Vec<RgbaImage> {
    let decode = srgb_decode_table();
    let to_linear = |v: u8, channel: usize| if srgb && channel < 3 { decode[v as usize] } else { v as f32 / 255.0 };
    let to_stored = |v: f32, channel: usize| {
        if srgb && channel < 3 {
            srgb_encode(v)
        } else {
            (v.clamp(0.0, 1.0) * 255.0).round() as u8
        }
    };
    let mut levels = vec![image.clone()];
    while let Some(above) = levels.last().filter(|l| l.width() > 1 || l.height() > 1) {
        let (width, height) = ((above.width() / 2).max(1), (above.height() / 2).max(1));
        let level = RgbaImage::from_fn(width, height, |x, y| {
            // The texels of `above` this one covers: two per axis, three at an odd size's end.
            let span = |at: u32, size: u32, above_size: u32| {
                let start = (at * 2).min(above_size - 1);
                let end = if at + 1 == size { above_size } else { (at * 2 + 2).min(above_size) };
                start..end
            };
            let (xs, ys) = (span(x, width, above.width()), span(y, height, above.height()));
            let count = (xs.len() * ys.len()) as f32;
            let mut sum = [0.0f32; 4];
            for sy in ys {
                for sx in xs.clone() {
                    let texel = above.get_pixel(sx, sy).0;
                    for c in 0..4 {
                        sum[c] += to_linear(texel[c], c);
                    }
                }
            }
            image::Rgba(std::array::from_fn(|c| to_stored(sum[c] / count, c)))
        });
        levels.push(level);
    }
    levels
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_transform_is_translation_rotation_scale() {
        assert_eq!(transform_matrix([0.0, 0.0], 0.0, [1.0, 1.0]), IDENTITY);
        let m = transform_matrix([0.5, 0.25], std::f32::consts::FRAC_PI_2, [2.0, 3.0]);
        let apply = |u: f32, v: f32| (m[0][0] * u + m[0][1] * v + m[0][2], m[1][0] * u + m[1][1] * v + m[1][2]);
        // Scale (1, 0) to (2, 0), turn it a quarter to (0, −2), then offset.
        let (u, v) = apply(1.0, 0.0);
        assert!((u - 0.5).abs() < 1e-6 && (v - (0.25 - 2.0)).abs() < 1e-6, "{u} {v}");
        let (u, v) = apply(0.0, 1.0);
        assert!((u - (0.5 + 3.0)).abs() < 1e-6 && (v - 0.25).abs() < 1e-6, "{u} {v}");
    }

    /// The TextureTransformTest sample asset: each quad spans [−½, ½]² with its uv (0, 0) at the
    /// top left, and shows a texture whose arrow tip is at uv (0.778, 0.778); its "Correct"
    /// marker, in the quad's frame, is where the tip lands when the transform is right, its
    /// "Error" marker where a rotation the other way puts it.
    #[test]
    fn the_arrows_of_texture_transform_test_reach_their_correct_markers() {
        let tip = [0.778, 0.778];
        let shown_at = |m: [[f32; 3]; 2], [x, y]: [f32; 2]| {
            let (u, v) = (x + 0.5, 0.5 - y);
            [m[0][0] * u + m[0][1] * v + m[0][2], m[1][0] * u + m[1][1] * v + m[1][2]]
        };
        let lands = |m, marker, tolerance: f32| {
            let uv = shown_at(m, marker);
            (uv[0] - tip[0]).abs() < tolerance && (uv[1] - tip[1]).abs() < tolerance
        };
        // The sample's rotation, 0.39269908169872414: π/8.
        let rotation = transform_matrix([0.0, 0.0], std::f32::consts::FRAC_PI_8, [1.0, 1.0]);
        assert!(
            lands(rotation, [-0.079_048_22, -0.516_267_5], 0.002),
            "Rotation: {:?}",
            shown_at(rotation, [-0.079, -0.516])
        );
        assert!(!lands(rotation, [0.516_267_5, 0.079_048_22], 0.1), "Rotation points at its Error marker");
        let scale = transform_matrix([0.0, 0.0], 0.0, [1.5, 1.5]);
        assert!(lands(scale, [0.018_544_97, -0.018_544_97], 0.002));
        let all = transform_matrix([-0.2, -0.1], 0.3, [1.5, 1.5]);
        assert!(lands(all, [-0.07, -0.25], 0.03), "All: {:?}", shown_at(all, [-0.07, -0.25]));
    }

    #[test]
    fn json_texture_infos_read_their_transform_and_texcoord_override() {
        let info: Value = serde_json::from_str(
            r#"{"index": 3, "texCoord": 1, "extensions": {"KHR_texture_transform": {"offset": [0.5, 0], "scale": [2, 2], "texCoord": 0}}}"#,
        )
        .unwrap();
        let reference = TextureRef::from_json(&info).unwrap();
        assert_eq!(reference.texture, 3);
        assert_eq!(reference.tex_coord, 0, "the transform's texCoord overrides the textureInfo's");
        assert_eq!(reference.transform, [[2.0, 0.0, 0.5], [0.0, 2.0, 0.0]]);
        let plain: Value = serde_json::from_str(r#"{"index": 1, "texCoord": 1}"#).unwrap();
        assert_eq!(TextureRef::from_json(&plain).unwrap().transform, IDENTITY);
        assert_eq!(TextureRef::from_json(&serde_json::from_str(r#"{"texCoord": 1}"#).unwrap()), None);
    }

    #[test]
    fn mip_levels_average_in_linear_light_down_to_one_texel() {
        // Black and white columns: the mean is half the light, sRGB 188, not 128.
        let image =
            RgbaImage::from_fn(4, 3, |x, _| if x % 2 == 0 { image::Rgba([0, 0, 0, 0]) } else { image::Rgba([255; 4]) });
        let levels = mip_chain(&image, true);
        let sizes: Vec<(u32, u32)> = levels.iter().map(|l| l.dimensions()).collect();
        assert_eq!(sizes, [(4, 3), (2, 1), (1, 1)]);
        let texel = levels[2].get_pixel(0, 0).0;
        assert_eq!(texel[0], srgb_encode(0.5));
        assert_eq!(texel[3], 128, "alpha averages linearly");
        let data = mip_chain(&image, false);
        assert_eq!(data[2].get_pixel(0, 0).0[0], 128, "data averages linearly");
        for v in [0u8, 1, 10, 100, 187, 188, 254, 255] {
            assert_eq!(srgb_encode(srgb_decode_table()[v as usize]), v, "sRGB round trip of {v}");
        }
    }
}
