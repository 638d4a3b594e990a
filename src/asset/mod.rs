//! glTF 2.0 assets: read and checked ([`Asset::load`]), flattened into world-space triangles
//! ([`geometry`]), seen through a camera ([`camera`]), rasterized into a g-buffer ([`bake`]), and
//! their materials mapped onto the Disney parameters ([`materials`]) and written out as presets
//! and a look ([`import`]).
//!
//! Reading checks everything the later steps rely on, so they can index freely: the JSON is
//! validated, every buffer and every image a material uses is present and decodes, and the
//! extensions the file requires are ones lookdev reads. Mesh compression (Draco, meshopt) is
//! refused by name.

pub mod bake;
pub mod camera;
pub mod geometry;
pub mod import;
pub mod materials;
pub mod names;
pub mod textures;
pub mod validate;

pub use names::channel_name;

use crate::input::{self, Kind};
use crate::{Error, Result};
use base64::Engine;
use gltf::json::Value;
use image::RgbaImage;
use std::path::{Path, PathBuf};

/// Extensions lookdev reads, for the bake or the material import.
pub const SUPPORTED_EXTENSIONS: [&str; 7] = [
    "KHR_materials_ior",
    "KHR_materials_specular",
    "KHR_materials_clearcoat",
    "KHR_materials_sheen",
    "KHR_materials_anisotropy",
    "KHR_materials_emissive_strength",
    "KHR_texture_transform",
];

/// Texture formats lookdev cannot decode, by the extension that brings them.
const UNDECODABLE_TEXTURES: [(&str, &str); 3] =
    [("KHR_texture_basisu", "KTX2"), ("EXT_texture_webp", "WebP"), ("MSFT_texture_dds", "DDS")];

/// Mesh compression extensions, which lookdev cannot decode.
const COMPRESSION: [(&str, &str); 3] = [
    ("KHR_draco_mesh_compression", "Draco mesh compression"),
    ("EXT_meshopt_compression", "meshopt compression"),
    ("KHR_meshopt_compression", "meshopt compression"),
];

/// The largest texture side lookdev decodes: the GPU's image limit on lavapipe and most devices.
const MAX_TEXTURE_SIDE: u32 = 16384;

/// Whether loading an asset decodes its textures' images or only checks them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Texels {
    Decode,
    Check,
}

/// A glTF asset with its buffers and images, checked.
pub struct Asset {
    pub path: PathBuf,
    pub document: gltf::Document,
    pub buffers: Vec<Vec<u8>>,
    /// Decoded images by index, RGBA8 as stored (sRGB-encoded colour, linear data); `None` for
    /// an image no material uses, and for every image when loaded with [`Texels::Check`].
    pub images: Vec<Option<RgbaImage>>,
}

impl Asset {
    /// Reads a `.gltf` (with its external or embedded buffers and images) or a `.glb`, and
    /// decodes the images its materials use, for the bake.
    pub fn load(path: &Path) -> Result<Asset> {
        Asset::load_with(path, Texels::Decode)
    }

    /// Reads an asset; with [`Texels::Check`], the images its materials use are read and their
    /// format recognised but not decoded (what the import needs: it reads no texel).
    pub fn load_with(path: &Path, texels: Texels) -> Result<Asset> {
        Asset::from_bytes(&input::read(path, Kind::Gltf)?, path, texels)
    }

    /// Reads an asset from the bytes of its `.gltf` or `.glb` file; `path` names it in messages,
    /// and its folder is where external buffers and images are looked for.
    pub fn from_bytes(bytes: &[u8], path: &Path, texels: Texels) -> Result<Asset> {
        let gltf = gltf::Gltf::from_slice_without_validation(bytes)
            .map_err(|e| Error::input_file(path, format!("not a readable glTF file ({e})")))?;
        let blob = gltf.blob;
        check_texture_formats(path, gltf.document.as_json())?;
        check_required_extensions(path, &gltf.document)?;
        let warnings = validate::check(gltf.document.as_json()).map_err(|problem| Error::input_file(path, problem))?;
        for warning in warnings {
            crate::warn(format!("{}: {warning}", path.display()));
        }
        // Required extensions are checked above; everything else is validated as usual.
        let mut json = gltf.document.into_json();
        json.extensions_required.clear();
        let document = gltf::Document::from_json(json)
            .map_err(|e| Error::input_file(path, format!("not a valid glTF file ({})", one_line(&e.to_string()))))?;
        let folder = path.parent().unwrap_or(Path::new(""));
        let buffers = document
            .buffers()
            .map(|buffer| load_buffer(path, folder, &buffer, blob.as_deref()))
            .collect::<Result<Vec<_>>>()?;
        let mut asset = Asset { path: path.to_path_buf(), document, buffers, images: Vec::new() };
        asset.check_extension_textures()?;
        asset.images = asset.load_images(folder, texels)?;
        Ok(asset)
    }

    /// The extensions' textureInfos are JSON the `gltf` crate does not check: each must name a
    /// texture of the file.
    fn check_extension_textures(&self) -> Result<()> {
        let count = self.document.textures().len();
        for material in self.document.materials() {
            let label = material_label(&material);
            for slot in textures::Slot::ALL {
                let Some(info) = textures::slot_json(&material, slot) else { continue };
                match textures::TextureRef::from_json(info) {
                    Some(reference) if reference.texture < count => {}
                    Some(reference) => {
                        return Err(Error::input_file(
                            &self.path,
                            format!(
                                "{label}: {} names texture {}, and the file has {count}",
                                slot.key(),
                                reference.texture
                            ),
                        ))
                    }
                    None => {
                        return Err(Error::input_file(
                            &self.path,
                            format!("{label}: {} has no valid texture index", slot.key()),
                        ))
                    }
                }
            }
        }
        Ok(())
    }

    /// The texture references of these materials that name a texcoord set beyond TEXCOORD_1,
    /// which the bake does not read: each is sampled with TEXCOORD_0 instead, and reported.
    pub fn unread_texcoords<'a>(&self, materials: impl IntoIterator<Item = gltf::Material<'a>>) -> Vec<String> {
        let mut found = Vec::new();
        for material in materials {
            for (slot, reference) in textures::Slot::ALL.iter().zip(textures::material_textures(&material)) {
                if let Some(reference) = reference.filter(|r| r.tex_coord > 1) {
                    found.push(format!(
                        "{}: {} uses TEXCOORD_{}, which is not read; TEXCOORD_0 is used",
                        material_label(&material),
                        slot.key(),
                        reference.tex_coord
                    ));
                }
            }
        }
        found
    }

    /// The images materials use, decoded (or, with [`Texels::Check`], checked and left out).
    fn load_images(&self, folder: &Path, texels: Texels) -> Result<Vec<Option<RgbaImage>>> {
        let mut used = vec![false; self.document.images().len()];
        for material in self.document.materials() {
            for reference in textures::material_textures(&material).into_iter().flatten() {
                let texture = self.document.textures().nth(reference.texture).expect("checked on load");
                used[texture.source().index()] = true;
            }
        }
        self.document
            .images()
            .map(|image| match used[image.index()] {
                true => self.load_image(folder, &image, texels),
                false => Ok(None),
            })
            .collect()
    }

    fn load_image(&self, folder: &Path, image: &gltf::Image, texels: Texels) -> Result<Option<RgbaImage>> {
        let label = match image.name() {
            Some(name) => format!("image {} '{name}'", image.index()),
            None => format!("image {}", image.index()),
        };
        let bytes: Vec<u8> = match image.source() {
            gltf::image::Source::View { view, .. } => {
                let buffer = &self.buffers[view.buffer().index()];
                let range = view.offset()..view.offset() + view.length();
                buffer
                    .get(range)
                    .ok_or_else(|| {
                        Error::input_file(&self.path, format!("{label}: its buffer view runs past the buffer"))
                    })?
                    .to_vec()
            }
            gltf::image::Source::Uri { uri, .. } => read_uri(&self.path, folder, uri, &label)?,
        };
        if texels == Texels::Check {
            image::guess_format(&bytes)
                .map_err(|e| Error::input_file(&self.path, format!("{label} cannot be decoded ({e})")))?;
            return Ok(None);
        }
        let decoded = input::image::decode(&bytes, MAX_TEXTURE_SIDE)
            .map_err(|problem| Error::input_file(&self.path, format!("{label} {problem}")))?;
        Ok(Some(decoded.into_rgba8()))
    }

    /// The decoded image a texture shows, of an asset loaded with [`Texels::Decode`].
    pub fn texture_image(&self, texture: &gltf::Texture) -> &RgbaImage {
        self.images[texture.source().index()].as_ref().expect("an asset for the bake decodes every image it uses")
    }

    /// The extensions the file uses that lookdev ignores, each with what uses it: reported, so
    /// that nothing is dropped silently.
    pub fn unsupported_extensions(&self) -> Vec<String> {
        self.document
            .extensions_used()
            .filter(|name| !SUPPORTED_EXTENSIONS.contains(name))
            .map(|name| name.to_string())
            .collect()
    }
}

/// "material 3 'paint'", as messages name a material.
pub fn material_label(material: &gltf::Material) -> String {
    match (material.index(), material.name()) {
        (Some(i), Some(name)) => format!("material {i} '{name}'"),
        (Some(i), None) => format!("material {i}"),
        (None, _) => "the default material".to_string(),
    }
}

/// Textures in a format lookdev cannot decode (KTX2 / Basis Universal, WebP, DDS) are refused
/// before anything else, naming the image, its URI and the extension: the `gltf` crate would
/// only say that a texture lacks its source. A texture that also gives a plain `source` (a PNG
/// or JPEG fallback) uses that.
fn check_texture_formats(path: &Path, json: &gltf::json::Root) -> Result<()> {
    let image_label = |index: u64| -> String {
        let Some(image) = usize::try_from(index).ok().and_then(|i| json.images.get(i)) else {
            return format!("image {index}");
        };
        let name = image.name.as_deref().map(|n| format!(" '{n}'")).unwrap_or_default();
        let uri = match (&image.uri, &image.mime_type) {
            (Some(uri), _) if !uri.starts_with("data:") => format!(" ({uri})"),
            (_, Some(mime)) => format!(" (embedded, {})", mime.0),
            _ => " (embedded)".to_string(),
        };
        format!("image {index}{name}{uri}")
    };
    let refuse = |texture: usize, image: String, format: &str, extension: &str| {
        Error::input_file(
            path,
            format!(
                "texture {texture} uses {image} in {format} format ({extension}), which lookdev cannot decode; \
                 convert the textures to PNG or JPEG"
            ),
        )
    };
    // Only the textures materials use: an unused one is never read.
    let mut used = Vec::new();
    for material in &json.materials {
        if let Ok(value) = gltf::json::serialize::to_value(material) {
            textures::texture_indices(&value, &mut used);
        }
    }
    for (index, texture) in json.textures.iter().enumerate().filter(|(i, _)| used.contains(&(*i as u64))) {
        let source = texture.source.value();
        match json.images.get(source) {
            Some(image) => {
                let mime = image.mime_type.as_ref().map(|m| m.0.as_str());
                let uri = image.uri.as_deref().unwrap_or("").to_ascii_lowercase();
                if mime == Some("image/ktx2") || uri.ends_with(".ktx2") {
                    return Err(refuse(index, image_label(source as u64), "KTX2", "KHR_texture_basisu"));
                }
            }
            None => {
                let extensions = texture.extensions.as_ref().map(|e| &e.others);
                for (extension, format) in UNDECODABLE_TEXTURES {
                    if let Some(ext) = extensions.and_then(|e| e.get(extension)) {
                        let image = ext.get("source").and_then(Value::as_u64).map_or("an image".into(), image_label);
                        return Err(refuse(index, image, format, extension));
                    }
                }
            }
        }
    }
    Ok(())
}

fn check_required_extensions(path: &Path, document: &gltf::Document) -> Result<()> {
    for required in document.extensions_required() {
        if let Some((_, what)) = COMPRESSION.iter().find(|(name, _)| *name == required) {
            return Err(Error::input_file(
                path,
                format!(
                    "the meshes use {what} ({required}), which is not supported: lookdev does not decode \
                     compressed meshes; export the asset without mesh compression"
                ),
            ));
        }
        if !SUPPORTED_EXTENSIONS.contains(&required) {
            return Err(Error::input_file(
                path,
                format!("the asset requires the extension {required}, which lookdev does not support"),
            ));
        }
    }
    Ok(())
}

fn load_buffer(path: &Path, folder: &Path, buffer: &gltf::Buffer, blob: Option<&[u8]>) -> Result<Vec<u8>> {
    let label = match buffer.name() {
        Some(name) => format!("buffer {} '{name}'", buffer.index()),
        None => format!("buffer {}", buffer.index()),
    };
    let data = match buffer.source() {
        gltf::buffer::Source::Bin => blob
            .ok_or_else(|| Error::input_file(path, format!("{label} is the binary chunk, but the file has none")))?
            .to_vec(),
        gltf::buffer::Source::Uri(uri) => read_uri(path, folder, uri, &label)?,
    };
    if data.len() < buffer.length() {
        return Err(Error::input_file(
            path,
            format!("{label} holds {} bytes, fewer than the {} the file declares", data.len(), buffer.length()),
        ));
    }
    Ok(data)
}

/// The bytes a URI names: embedded base64 data, or a file relative to the asset.
fn read_uri(path: &Path, folder: &Path, uri: &str, label: &str) -> Result<Vec<u8>> {
    if let Some(data) = uri.strip_prefix("data:") {
        let (_, encoded) = data
            .split_once(";base64,")
            .ok_or_else(|| Error::input_file(path, format!("{label}: only base64 data URIs are supported")))?;
        return base64::engine::general_purpose::STANDARD
            .decode(encoded)
            .map_err(|e| Error::input_file(path, format!("{label}: its embedded data is not valid base64 ({e})")));
    }
    if uri.contains("://") {
        return Err(Error::input_file(path, format!("{label}: '{uri}' is not a local file")));
    }
    let file = folder.join(percent_decode(uri));
    input::read_bytes(&file, Kind::GltfResource)
        .map_err(|problem| Error::input_file(path, format!("{label}: cannot read {}: {problem}", file.display())))
}

/// URIs escape spaces and other characters as %XX.
fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = bytes.get(i + 1..i + 3).and_then(|h| std::str::from_utf8(h).ok());
        match (bytes[i], hex.and_then(|h| u8::from_str_radix(h, 16).ok())) {
            (b'%', Some(byte)) => {
                out.push(byte);
                i += 3;
            }
            (byte, _) => {
                out.push(byte);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

fn one_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uris_are_percent_decoded() {
        assert_eq!(percent_decode("my%20model.bin"), "my model.bin");
        assert_eq!(percent_decode("100%"), "100%");
        assert_eq!(percent_decode("a%2Fb%zz"), "a/b%zz");
    }
}
