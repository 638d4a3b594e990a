//! Baking: an asset rasterized into a g-buffer
//! (docs/commands.md#lookdev-bake-modelgltfglb---out-gbufferexr).
//!
//! Each of `samples` passes draws the whole scene with the camera nudged by a sub-pixel offset
//! (a stratified pattern), and reads back one sample per pixel of every output. A pass draws
//! twice when a material has textures that drive parameters: once for the geometry (normals,
//! tangents, view vectors, ids, `COLOR_0`), then again for the maps (docs/commands.md#maps), each of
//! whose samples names its material. The passes are averaged on the CPU, as the built-in scene's
//! subsamples are: coverage is the fraction of samples that hit, normals, tangents and view
//! vectors are averaged over the hits, the object ID is the one most samples saw, each mask is
//! the fraction (or mean value) of the samples that carry it, and each map the mean over the
//! samples of the materials that write it.

use super::camera::{self, Camera, CameraChoice};
use super::geometry::{self, Geometry, Vertex};
use super::materials::{self, material_of, MapKind, UsedMaterial, MAP_CHANNELS};
use super::textures::{self, Slot, SLOTS};
use super::Asset;
use crate::gbuffer::stable_tangent;
use crate::gbuffer::GBuffer;
use crate::gpu::graphics::{self, Attribute, GraphicsPipeline, PipelineDesc, Sampler, SamplerDesc, TextureSet};
use crate::gpu::shaders::{self, Stage};
use crate::gpu::{BindingKind, Buffer, Context, GlslLayout, GlslStruct, Image, Interface};
use crate::visibility::{self, Grid, Mesh, SurfacePoint, Visibility};
use crate::{Error, Result};
use ash::vk;
use glam::{Mat4, Vec3, Vec4};
use half::f16;
use std::collections::{BTreeMap, HashMap};

/// What a bake makes.
#[derive(Clone, Debug, PartialEq)]
pub struct BakeOptions {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel, one pass each.
    pub samples: u32,
    pub camera: CameraChoice,
    /// Traces the asset's triangles from each pixel's surface for its visibility on this grid
    /// (docs/formats.md#visibility); `None` stores none.
    pub visibility: Option<Grid>,
}

/// The most samples per pixel: the per-pixel tallies are 16-bit.
pub const MAX_SAMPLES: u32 = 1024;

/// `Draw` in glsl/include/bake_draw.glsl.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct DrawConstants {
    view_projection: [f32; 16],
    eye: [f32; 4],
    toward_eye: [f32; 4],
    object_id: u32,
    material: u32,
    lod_bias: f32,
}

/// `TextureSlot` in glsl/include/bake_material.glsl.
#[repr(C)]
#[derive(Clone, Copy, Default, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuTextureSlot {
    u: [f32; 4],
    v: [f32; 4],
    tex_coord: u32,
    present: u32,
    pad0: u32,
    pad1: u32,
}

/// `Material` in glsl/include/bake_material.glsl (std430, 512 bytes).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuMaterial {
    flags: u32,
    alpha_cutoff: f32,
    normal_scale: f32,
    anisotropy_cos: f32,
    anisotropy_sin: f32,
    clearcoat_roughness: f32,
    pad0: f32,
    pad1: f32,
    base_color_factor: [f32; 4],
    sheen_color_factor: [f32; 4],
    specular_color_factor: [f32; 4],
    slots: [GpuTextureSlot; SLOTS],
}

const MATERIAL_DOUBLE_SIDED: u32 = 1;
const MATERIAL_ALPHA_MASK: u32 = 2;

/// The geometry pass's render targets, in bake.frag's output order, with their formats.
const GEOMETRY_TARGETS: [vk::Format; 6] = [
    vk::Format::R32G32B32A32_SFLOAT, // normal, w = covered
    vk::Format::R32G32B32A32_SFLOAT, // tangent, w = bitangent sign
    vk::Format::R32G32B32A32_SFLOAT, // view
    vk::Format::R32G32_UINT,         // object id, material + 1
    vk::Format::R32G32B32A32_SFLOAT, // COLOR_0
    vk::Format::R32G32B32A32_UINT,   // the world position's bits (xyz), the triangle's index (w)
];

/// The maps pass's render targets (bake_maps.frag): four that [`MAP_CHANNELS`] lays out, in half
/// floats, which hold 8-bit texels exactly enough at half the bandwidth, and the material of each
/// sample.
const MAP_TARGETS: [vk::Format; 5] = [
    vk::Format::R16G16B16A16_SFLOAT,
    vk::Format::R16G16B16A16_SFLOAT,
    vk::Format::R16G16B16A16_SFLOAT,
    vk::Format::R16G16B16A16_SFLOAT,
    vk::Format::R32_UINT, // the material's index + 1; 0 for none
];

crate::glsl_struct!(DrawConstants as "Draw", 108 bytes {
    view_projection @ 0,
    eye @ 64,
    toward_eye @ 80,
    object_id @ 96,
    material @ 100,
    lod_bias @ 104,
});
crate::glsl_struct!(GpuTextureSlot as "TextureSlot", 48 bytes {
    u @ 0,
    v @ 16,
    tex_coord @ 32,
    present @ 36,
    pad0 @ 40,
    pad1 @ 44,
});
crate::glsl_struct!(GpuMaterial as "Material", 512 bytes {
    flags @ 0,
    alpha_cutoff @ 4,
    normal_scale @ 8,
    anisotropy_cos @ 12,
    anisotropy_sin @ 16,
    clearcoat_roughness @ 20,
    pad0 @ 24,
    pad1 @ 28,
    base_color_factor @ 32,
    sheen_color_factor @ 48,
    specular_color_factor @ 64,
    slots @ 80,
});

/// [`Vertex`] as bake.vert reads it, location by location.
const VERTEX_ATTRIBUTES: [Attribute; 6] = {
    use std::mem::offset_of;
    const fn attribute(location: u32, format: vk::Format, offset: usize) -> Attribute {
        Attribute { location, format, offset: offset as u32 }
    }
    [
        attribute(0, vk::Format::R32G32B32_SFLOAT, offset_of!(Vertex, position)),
        attribute(1, vk::Format::R32G32B32_SFLOAT, offset_of!(Vertex, normal)),
        attribute(2, vk::Format::R32G32B32A32_SFLOAT, offset_of!(Vertex, tangent)),
        attribute(3, vk::Format::R32G32_SFLOAT, offset_of!(Vertex, uv0)),
        attribute(4, vk::Format::R32G32_SFLOAT, offset_of!(Vertex, uv1)),
        attribute(5, vk::Format::R32G32B32A32_SFLOAT, offset_of!(Vertex, color)),
    ]
};

/// What the bake's stages and the host agree on: the textures and the material table at set 0,
/// the draw's constants, and the vertex layout.
pub const INTERFACES: [Interface; 3] = {
    const SETS: &[&[BindingKind]] = &[&graphics::set_layout(SLOTS as u32)];
    const STRUCTS: &[GlslStruct] = &[GpuMaterial::GLSL, GpuTextureSlot::GLSL];
    const fn stage(stage: &Stage, vertex_inputs: &'static [Attribute]) -> Interface {
        Interface {
            file: stage.file,
            spirv: stage.spirv,
            sets: SETS,
            push: Some(DrawConstants::GLSL),
            structs: STRUCTS,
            vertex_inputs,
        }
    }
    [
        stage(&shaders::BAKE_VERTEX, &VERTEX_ATTRIBUTES),
        stage(&shaders::BAKE_FRAGMENT, &[]),
        stage(&shaders::BAKE_MAPS_FRAGMENT, &[]),
    ]
};

/// The steps of a bake, for progress reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// Reading and transforming primitives (generating tangents), counted in primitives.
    Meshes,
    /// Rasterizing, counted in passes (samples per pixel).
    Passes,
    /// Tracing the visibility.
    Visibility,
}

/// Bakes `asset` into a g-buffer. `progress(step, done, total)` follows the work.
pub fn bake(
    ctx: &Context,
    asset: &Asset,
    options: &BakeOptions,
    mut progress: impl FnMut(Step, u32, u32),
) -> Result<GBuffer> {
    let (width, height) = (options.width, options.height);
    let max = ctx.info().max_image_dimension_2d;
    if width == 0 || height == 0 || width > max || height > max {
        return Err(Error::input(format!(
            "--size {width} {height}: {} draws 1 to {max} pixels a side",
            ctx.info().name
        )));
    }
    if !(1..=MAX_SAMPLES).contains(&options.samples) {
        return Err(Error::input(format!("--samples {}: must be 1 to {MAX_SAMPLES}", options.samples)));
    }
    let geometry = geometry::flatten(asset, |done, total| progress(Step::Meshes, done as u32, total as u32))?;
    if geometry.posed_meshes > 0 {
        crate::warn(format!(
            "{}: {} skinned or morphed primitives are baked in their rest pose",
            asset.path.display(),
            geometry.posed_meshes
        ));
    }
    let camera = camera::choose(asset, &options.camera, geometry.bounds, width, height)?;
    let used = materials::used(asset, geometry.draws.iter().map(|d| d.material));
    for warning in asset.unread_texcoords(used.iter().map(|m| material_of(asset, m.index))) {
        crate::warn(format!("{}: {warning}", asset.path.display()));
    }
    // The map kinds of each used material: a base colour map where its primitives carry COLOR_0.
    let kinds: Vec<Vec<MapKind>> = used
        .iter()
        .map(|m| {
            let colored = geometry.draws.iter().any(|d| d.material == m.index && d.has_colors);
            materials::map_kinds(&material_of(asset, m.index), colored)
        })
        .collect();
    let with_maps = kinds.iter().any(|k| !k.is_empty());
    let targets = if with_maps { GEOMETRY_TARGETS.len().max(MAP_TARGETS.len()) } else { GEOMETRY_TARGETS.len() };
    if ctx.info().max_color_attachments < targets as u32 {
        return Err(Error::gpu(format!(
            "{} draws to {} colour targets at once, and the bake writes {targets}",
            ctx.info().name,
            ctx.info().max_color_attachments,
        )));
    }
    let rasterizer = Rasterizer::new(ctx, asset, &geometry, &used, &kinds, (width, height, options.samples))?;
    let mut accumulator = Accumulator::new(width, height, &kinds, &geometry);
    for (pass, offset) in jitter_pattern(options.samples).into_iter().enumerate() {
        let samples = rasterizer.pass(&geometry, &camera, offset)?;
        accumulator.add(&samples, offset);
        progress(Step::Passes, pass as u32 + 1, options.samples);
    }
    let surfaces = std::mem::take(&mut accumulator.nearest);
    let mut gbuffer = accumulator.finish(&camera, &geometry, &used);
    if let Some(grid) = options.visibility {
        progress(Step::Visibility, 0, 1);
        gbuffer.visibility = Some(trace_visibility(grid, &geometry, &gbuffer, &surfaces));
        progress(Step::Visibility, 1, 1);
    }
    Ok(gbuffer)
}

/// Each covered pixel's visibility, traced through the asset's triangles from the surface its
/// sample nearest the pixel's centre hit. Rays leave from a point moved off the surface by a
/// ten-thousandth of the scene's size along the triangle's normal, turned toward the eye.
fn trace_visibility(grid: Grid, geometry: &Geometry, gbuffer: &GBuffer, surfaces: &[Option<[u32; 4]>]) -> Visibility {
    let corners = |triangle: usize| {
        let vertex = |k: usize| Vec3::from(geometry.vertices[3 * triangle + k].position);
        [vertex(0), vertex(1), vertex(2)]
    };
    let mesh = Mesh::new((0..geometry.vertices.len() / 3).map(corners));
    let points: Vec<Option<SurfacePoint>> = surfaces
        .iter()
        .enumerate()
        .map(|(pixel, surface)| {
            let [x, y, z, triangle] = (*surface)?;
            let position = Vec3::new(f32::from_bits(x), f32::from_bits(y), f32::from_bits(z));
            let view = Vec3::from(gbuffer.view[pixel]);
            let facing = mesh.normal(triangle as usize);
            let geometric = if facing.dot(view) < 0.0 { -facing } else { facing };
            let shading = Vec3::from(gbuffer.normal[pixel]);
            // A degenerate triangle has no normal: the shading normal stands in.
            let geometric = if geometric == Vec3::ZERO { shading } else { geometric };
            Some(SurfacePoint { position, geometric, shading })
        })
        .collect();
    let offset = 1e-4 * 2.0 * geometry.bounds.1.max(f32::MIN_POSITIVE);
    visibility::trace(grid, &points, &mesh, offset)
}

/// Sub-pixel offsets in [−0.5, 0.5)², stratified: a grid when `n` is a square, else a rank-1
/// lattice (one sample in each of n columns and n rows, spread over the square by a step near
/// n/φ that shares no factor with n).
pub fn jitter_pattern(n: u32) -> Vec<(f32, f32)> {
    let side = (n as f64).sqrt().round() as u32;
    if side * side == n {
        let step = 1.0 / side as f32;
        return (0..n)
            .map(|i| (((i % side) as f32 + 0.5) * step - 0.5, ((i / side) as f32 + 0.5) * step - 0.5))
            .collect();
    }
    let golden = (n as f64 / 1.618_033_988_75).round().max(1.0) as u32;
    let step = (golden..n).chain(1..golden).find(|&g| gcd(g, n) == 1).unwrap_or(1);
    (0..n)
        .map(|i| {
            let x = (i as f32 + 0.5) / n as f32;
            let y = ((i * step % n) as f32 + 0.5) / n as f32;
            (x - 0.5, y - 0.5)
        })
        .collect()
}

fn gcd(a: u32, b: u32) -> u32 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// The GPU side of a bake: the pipelines, the scene's vertices, materials and textures, and the
/// targets.
struct Rasterizer {
    ctx: Context,
    width: u32,
    height: u32,
    geometry_pipeline: GraphicsPipeline,
    /// The maps pass, when any material has maps.
    maps_pipeline: Option<GraphicsPipeline>,
    vertices: Buffer,
    /// Per used material: its textures for the geometry pass and for the maps pass.
    sets: Vec<(TextureSet, Option<TextureSet>)>,
    /// Per used material: whether its back faces are drawn.
    double_sided: Vec<bool>,
    /// Textures are sampled for each sample's share of the pixel: −½·log2(samples) levels finer.
    lod_bias: f32,
    /// A draw's glTF material index to its place among the used materials.
    slot_of: HashMap<Option<usize>, usize>,
    /// The geometry targets, then the maps targets.
    targets: Vec<Image>,
    depth: Image,
    staging: Buffer,
    /// Where each target's copy starts in `staging`.
    offsets: Vec<u64>,
    // Held so the texture sets' buffer, images and samplers stay alive.
    _materials: Buffer,
    _textures: Vec<Image>,
    _samplers: Vec<Sampler>,
}

/// One pass's samples, as read back.
struct Samples<'a> {
    normal: &'a [[f32; 4]],
    tangent: &'a [[f32; 4]],
    view: &'a [[f32; 4]],
    ids: &'a [[u32; 2]],
    color: &'a [[f32; 4]],
    /// The world position's bits and the triangle's index.
    surface: &'a [[u32; 4]],
    /// The maps pass's targets, when it ran: the four of values, and each sample's material.
    maps: Vec<&'a [[f16; 4]]>,
    map_material: &'a [u32],
}

/// The sampler a glTF texture asks for: its filters and wrap modes, with mip mapping unless its
/// minification filter rules it out. glTF leaves an unset filter to the viewer: linear, and
/// trilinear between mip levels.
fn sampler_desc(sampler: &gltf::texture::Sampler) -> SamplerDesc {
    use gltf::texture::{MagFilter, MinFilter, WrappingMode};
    let wrap = |mode: WrappingMode| match mode {
        WrappingMode::ClampToEdge => vk::SamplerAddressMode::CLAMP_TO_EDGE,
        WrappingMode::MirroredRepeat => vk::SamplerAddressMode::MIRRORED_REPEAT,
        WrappingMode::Repeat => vk::SamplerAddressMode::REPEAT,
    };
    let magnify = match sampler.mag_filter() {
        Some(MagFilter::Nearest) => vk::Filter::NEAREST,
        _ => vk::Filter::LINEAR,
    };
    let (minify, mipmap) = match sampler.min_filter() {
        Some(MinFilter::Nearest) => (vk::Filter::NEAREST, None),
        Some(MinFilter::Linear) => (vk::Filter::LINEAR, None),
        Some(MinFilter::NearestMipmapNearest) => (vk::Filter::NEAREST, Some(vk::SamplerMipmapMode::NEAREST)),
        Some(MinFilter::LinearMipmapNearest) => (vk::Filter::LINEAR, Some(vk::SamplerMipmapMode::NEAREST)),
        Some(MinFilter::NearestMipmapLinear) => (vk::Filter::NEAREST, Some(vk::SamplerMipmapMode::LINEAR)),
        Some(MinFilter::LinearMipmapLinear) | None => (vk::Filter::LINEAR, Some(vk::SamplerMipmapMode::LINEAR)),
    };
    SamplerDesc { magnify, minify, mipmap, wrap_u: wrap(sampler.wrap_s()), wrap_v: wrap(sampler.wrap_t()) }
}

/// The GPU's view of one material: its constants and where each slot samples.
fn gpu_material(material: &gltf::Material, references: &[Option<textures::TextureRef>]) -> GpuMaterial {
    let pbr = material.pbr_metallic_roughness();
    let mut flags = 0;
    if material.double_sided() {
        flags |= MATERIAL_DOUBLE_SIDED;
    }
    if material.alpha_mode() == gltf::material::AlphaMode::Mask {
        flags |= MATERIAL_ALPHA_MASK;
    }
    let rotation = materials::anisotropy(material).map_or(0.0, |a| a.rotation);
    let extension_color = |extension: &str, key: &str, default: [f32; 3]| -> [f32; 4] {
        let color = material
            .extension_value(extension)
            .and_then(|e| e.get(key))
            .and_then(|v| v.as_array())
            .map(|a| [0, 1, 2].map(|k| a.get(k).and_then(|c| c.as_f64()).unwrap_or(0.0) as f32))
            .unwrap_or(default);
        [color[0], color[1], color[2], 0.0]
    };
    let factor = pbr.base_color_factor();
    let mut slots = [GpuTextureSlot::default(); SLOTS];
    for (slot, reference) in slots.iter_mut().zip(references) {
        if let Some(r) = reference {
            let [row0, row1] = r.transform;
            *slot = GpuTextureSlot {
                u: [row0[0], row0[1], row0[2], 0.0],
                v: [row1[0], row1[1], row1[2], 0.0],
                // Sets beyond TEXCOORD_1 are not read; they were reported, and sample set 0.
                tex_coord: if r.tex_coord == 1 { 1 } else { 0 },
                present: 1,
                pad0: 0,
                pad1: 0,
            };
        }
    }
    GpuMaterial {
        flags,
        alpha_cutoff: material.alpha_cutoff().unwrap_or(0.5),
        normal_scale: material.normal_texture().map_or(1.0, |t| t.scale()),
        anisotropy_cos: rotation.cos(),
        anisotropy_sin: rotation.sin(),
        clearcoat_roughness: material
            .extension_value("KHR_materials_clearcoat")
            .and_then(|e| e.get("clearcoatRoughnessFactor"))
            .and_then(|v| v.as_f64())
            .unwrap_or(0.0) as f32,
        pad0: 0.0,
        pad1: 0.0,
        base_color_factor: factor,
        sheen_color_factor: extension_color("KHR_materials_sheen", "sheenColorFactor", [0.0; 3]),
        specular_color_factor: {
            let [r, g, b] = material.specular().map_or([1.0; 3], |s| s.specular_color_factor());
            [r, g, b, 0.0]
        },
        slots,
    }
}

impl Rasterizer {
    fn new(
        ctx: &Context,
        asset: &Asset,
        geometry: &Geometry,
        used: &[UsedMaterial],
        kinds: &[Vec<MapKind>],
        (width, height, samples): (u32, u32, u32),
    ) -> Result<Rasterizer> {
        let pipeline = |fragment, color_formats| {
            GraphicsPipeline::new(
                ctx,
                &PipelineDesc {
                    vertex: &shaders::BAKE_VERTEX,
                    fragment,
                    stride: std::mem::size_of::<Vertex>() as u32,
                    attributes: &VERTEX_ATTRIBUTES,
                    color_formats,
                    depth_format: vk::Format::D32_SFLOAT,
                    textures: SLOTS as u32,
                    push_size: INTERFACES[0].push_size(),
                },
            )
        };
        let geometry_pipeline = pipeline(&shaders::BAKE_FRAGMENT, &GEOMETRY_TARGETS)?;
        let with_maps = kinds.iter().any(|k| !k.is_empty());
        let maps_pipeline = match with_maps {
            true => Some(pipeline(&shaders::BAKE_MAPS_FRAGMENT, &MAP_TARGETS)?),
            false => None,
        };
        let vertices = Buffer::vertices(ctx, bytemuck::cast_slice(&geometry.vertices))?;
        let formats = GEOMETRY_TARGETS.iter().chain(if with_maps { &MAP_TARGETS[..] } else { &[] });
        let targets =
            formats.map(|&format| Image::color_target(ctx, format, width, height)).collect::<Result<Vec<_>>>()?;
        let depth = Image::depth_target(ctx, width, height)?;
        // Each target's copy starts on a 16-byte boundary: copies must start on a whole texel.
        let mut offsets = Vec::new();
        let mut end = 0u64;
        for target in &targets {
            offsets.push(end);
            end = (end + target.byte_size()).next_multiple_of(16);
        }
        let staging = Buffer::staging(ctx, end)?;

        // Textures, each image (in its colour space) and sampler made once however many
        // materials share it, with stand-ins for empty slots: a flat normal, white.
        let mut images: Vec<Image> = vec![
            Image::texture(ctx, &[image::RgbaImage::from_pixel(1, 1, image::Rgba([128, 128, 255, 255]))], false)?,
            Image::texture(ctx, &[image::RgbaImage::from_pixel(1, 1, image::Rgba([255; 4]))], false)?,
        ];
        let (flat, white) = (0usize, 1usize);
        let mut samplers: Vec<Sampler> = vec![Sampler::new(ctx, SamplerDesc::default())?];
        let mut image_of: HashMap<(usize, bool), usize> = HashMap::new();
        let mut sampler_of: HashMap<SamplerDesc, usize> = HashMap::new();
        let mut gpu_materials = Vec::new();
        let mut bindings = Vec::new();
        for used_material in used {
            let material = material_of(asset, used_material.index);
            let references = textures::material_textures(&material);
            gpu_materials.push(gpu_material(&material, &references));
            let mut binding = [(white, 0usize); SLOTS];
            binding[Slot::Normal as usize].0 = flat;
            for (slot, reference) in Slot::ALL.into_iter().zip(references) {
                let Some(reference) = reference else { continue };
                let texture = asset.document.textures().nth(reference.texture).expect("checked on load");
                let desc = sampler_desc(&texture.sampler());
                let sampler = match sampler_of.get(&desc) {
                    Some(&i) => i,
                    None => {
                        samplers.push(Sampler::new(ctx, desc)?);
                        sampler_of.insert(desc, samplers.len() - 1);
                        samplers.len() - 1
                    }
                };
                let key = (texture.source().index(), slot.is_srgb());
                let image = match image_of.get(&key) {
                    Some(&i) => i,
                    None => {
                        let levels = textures::mip_chain(asset.texture_image(&texture), key.1);
                        images.push(Image::texture(ctx, &levels, key.1).map_err(|e| {
                            Error::input_file(&asset.path, format!("image {}: {e}", texture.source().index()))
                        })?);
                        image_of.insert(key, images.len() - 1);
                        images.len() - 1
                    }
                };
                binding[slot as usize] = (image, sampler);
            }
            bindings.push(binding);
        }
        let material_buffer = Buffer::with_data(ctx, bytemuck::cast_slice(&gpu_materials))?;
        let mut sets = Vec::new();
        for binding in &bindings {
            let textures: Vec<(&Image, &Sampler)> = binding.iter().map(|&(i, s)| (&images[i], &samplers[s])).collect();
            let maps_set = match &maps_pipeline {
                Some(p) => Some(p.texture_set(&textures, &material_buffer)?),
                None => None,
            };
            sets.push((geometry_pipeline.texture_set(&textures, &material_buffer)?, maps_set));
        }
        Ok(Rasterizer {
            ctx: ctx.clone(),
            width,
            height,
            geometry_pipeline,
            maps_pipeline,
            vertices,
            sets,
            double_sided: gpu_materials.iter().map(|m| m.flags & MATERIAL_DOUBLE_SIDED != 0).collect(),
            lod_bias: -0.5 * (samples as f32).log2(),
            slot_of: used.iter().enumerate().map(|(slot, m)| (m.index, slot)).collect(),
            targets,
            depth,
            staging,
            offsets,
            _materials: material_buffer,
            _textures: images,
            _samplers: samplers,
        })
    }

    /// Draws the scene once (twice with maps), with the camera nudged by `offset` pixels, and
    /// reads it back.
    fn pass(&self, geometry: &Geometry, camera: &Camera, offset: (f32, f32)) -> Result<Samples<'_>> {
        let (width, height) = (self.width, self.height);
        // Moving clip space by −offset puts the pixel's sample at +offset from its centre.
        let nudge =
            Mat4::from_translation(Vec3::new(-2.0 * offset.0 / width as f32, -2.0 * offset.1 / height as f32, 0.0));
        let view_projection = nudge * camera.view_projection;
        let device = &self.ctx.shared.device;
        let toward_eye = -camera.forward;
        let (geometry_targets, map_targets) = self.targets.split_at(GEOMETRY_TARGETS.len());
        self.ctx.run(|cmd| {
            let draw_all = |cmd, pipeline: &GraphicsPipeline, targets: &[Image], maps: bool| {
                let clear = vk::ClearValue { color: vk::ClearColorValue { float32: [0.0; 4] } };
                let colors: Vec<_> = targets
                    .iter()
                    .map(|target| {
                        vk::RenderingAttachmentInfo::default()
                            .image_view(target.view)
                            .image_layout(vk::ImageLayout::GENERAL)
                            .load_op(vk::AttachmentLoadOp::CLEAR)
                            .store_op(vk::AttachmentStoreOp::STORE)
                            .clear_value(clear)
                    })
                    .collect();
                let depth = vk::RenderingAttachmentInfo::default()
                    .image_view(self.depth.view)
                    .image_layout(vk::ImageLayout::GENERAL)
                    .load_op(vk::AttachmentLoadOp::CLEAR)
                    .store_op(vk::AttachmentStoreOp::DONT_CARE)
                    .clear_value(vk::ClearValue {
                        depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 },
                    });
                let info = vk::RenderingInfo::default()
                    .render_area(vk::Rect2D { offset: vk::Offset2D::default(), extent: vk::Extent2D { width, height } })
                    .layer_count(1)
                    .color_attachments(&colors)
                    .depth_attachment(&depth);
                unsafe {
                    device.cmd_begin_rendering(cmd, &info);
                    device.cmd_bind_vertex_buffers(cmd, 0, &[self.vertices.buffer], &[0]);
                }
                pipeline.record_bind(cmd, width, height);
                for draw in &geometry.draws {
                    let slot = self.slot_of[&draw.material];
                    let constants = DrawConstants {
                        view_projection: view_projection.to_cols_array(),
                        eye: [camera.eye.x, camera.eye.y, camera.eye.z, if camera.orthographic { 0.0 } else { 1.0 }],
                        toward_eye: [toward_eye.x, toward_eye.y, toward_eye.z, 0.0],
                        object_id: draw.object_id,
                        material: slot as u32,
                        lod_bias: self.lod_bias,
                    };
                    let (geometry_set, maps_set) = &self.sets[slot];
                    let set =
                        if maps { maps_set.as_ref().expect("a maps set with the maps pass") } else { geometry_set };
                    pipeline.record_draw(
                        cmd,
                        set,
                        bytemuck::bytes_of(&constants),
                        self.double_sided[slot],
                        draw.first_vertex,
                        draw.vertex_count,
                    );
                }
                unsafe { device.cmd_end_rendering(cmd) };
                crate::gpu::context::full_barrier(device, cmd);
            };
            draw_all(cmd, &self.geometry_pipeline, geometry_targets, false);
            if let Some(maps) = &self.maps_pipeline {
                draw_all(cmd, maps, map_targets, true);
            }
            for (target, &offset) in self.targets.iter().zip(&self.offsets) {
                target.record_read_at(cmd, &self.staging, offset);
            }
            Ok(())
        })?;
        let bytes = self.staging.bytes();
        let pixels = (width * height) as usize;
        let mut targets = self.offsets.iter().map(|&offset| offset as usize);
        let mut next = |texel: usize| {
            let at = targets.next().expect("one offset per target");
            &bytes[at..at + pixels * texel]
        };
        Ok(Samples {
            normal: bytemuck::cast_slice(next(16)),
            tangent: bytemuck::cast_slice(next(16)),
            view: bytemuck::cast_slice(next(16)),
            ids: bytemuck::cast_slice(next(8)),
            color: bytemuck::cast_slice(next(16)),
            surface: bytemuck::cast_slice(next(16)),
            maps: (0..self.maps_pipeline.as_ref().map_or(0, |_| 4)).map(|_| bytemuck::cast_slice(next(8))).collect(),
            map_material: match self.maps_pipeline {
                Some(_) => bytemuck::cast_slice(next(4)),
                None => &[],
            },
        })
    }
}

/// Per-pixel sums over the passes.
struct Accumulator {
    width: u32,
    height: u32,
    samples: u32,
    hits: Vec<u16>,
    normal: Vec<Vec3>,
    tangent: Vec<Vec3>,
    /// Positive and negative bitangent signs, as a count (which wins).
    handedness: Vec<i16>,
    view: Vec<Vec3>,
    /// Boyer–Moore majority vote over the object ids a pixel's samples saw.
    vote: Vec<(u32, u16)>,
    /// Per used material: samples that hit it.
    material_hits: Vec<Vec<u16>>,
    /// COLOR_0 sums, when any primitive has vertex colours.
    color: Option<Vec<Vec4>>,
    /// Per used material: the bits of its map kinds.
    material_kinds: Vec<u32>,
    /// Per map kind any material has: samples of materials with it.
    kind_hits: Vec<(MapKind, Vec<u16>)>,
    /// Per map channel of those kinds ([`MAP_CHANNELS`] index): the sum of its values.
    map_sums: Vec<(usize, Vec<f32>)>,
    /// Per pixel: the surface (position bits, triangle) of its hit nearest the centre so far,
    /// and that hit's squared distance from the centre.
    nearest: Vec<Option<[u32; 4]>>,
    nearest_distance: Vec<f32>,
}

impl Accumulator {
    fn new(width: u32, height: u32, kinds: &[Vec<MapKind>], geometry: &Geometry) -> Accumulator {
        let pixels = (width * height) as usize;
        let present: Vec<MapKind> = MapKind::ALL.into_iter().filter(|k| kinds.iter().any(|m| m.contains(k))).collect();
        Accumulator {
            width,
            height,
            samples: 0,
            hits: vec![0; pixels],
            normal: vec![Vec3::ZERO; pixels],
            tangent: vec![Vec3::ZERO; pixels],
            handedness: vec![0; pixels],
            view: vec![Vec3::ZERO; pixels],
            vote: vec![(0, 0); pixels],
            material_hits: kinds.iter().map(|_| vec![0; pixels]).collect(),
            color: geometry.draws.iter().any(|d| d.has_colors).then(|| vec![Vec4::ZERO; pixels]),
            material_kinds: kinds.iter().map(|k| k.iter().map(|k| k.bit()).sum()).collect(),
            kind_hits: present.iter().map(|&k| (k, vec![0; pixels])).collect(),
            map_sums: (0..MAP_CHANNELS.len())
                .filter(|&c| present.contains(&MAP_CHANNELS[c].kind))
                .map(|c| (c, vec![0.0; pixels]))
                .collect(),
            nearest: vec![None; pixels],
            nearest_distance: vec![f32::INFINITY; pixels],
        }
    }

    /// Adds a pass's samples, taken `offset` pixels from the centres.
    fn add(&mut self, s: &Samples, offset: (f32, f32)) {
        self.samples += 1;
        let distance = offset.0 * offset.0 + offset.1 * offset.1;
        for p in 0..self.hits.len() {
            if s.normal[p][3] < 0.5 {
                continue;
            }
            self.hits[p] += 1;
            if distance < self.nearest_distance[p] {
                self.nearest_distance[p] = distance;
                self.nearest[p] = Some(s.surface[p]);
            }
            self.normal[p] += Vec3::from_slice(&s.normal[p][..3]);
            self.tangent[p] += Vec3::from_slice(&s.tangent[p][..3]);
            self.handedness[p] += if s.tangent[p][3] < 0.0 { -1 } else { 1 };
            self.view[p] += Vec3::from_slice(&s.view[p][..3]);
            let [id, material] = s.ids[p];
            let vote = &mut self.vote[p];
            if vote.1 == 0 {
                *vote = (id, 1);
            } else if vote.0 == id {
                vote.1 += 1;
            } else {
                vote.1 -= 1;
            }
            let slot = material as usize - 1;
            self.material_hits[slot][p] += 1;
            if let Some(color) = &mut self.color {
                color[p] += Vec4::from(s.color[p]);
            }
        }
        // The maps pass's samples, each counted for the material it names.
        for (p, &material) in s.map_material.iter().enumerate() {
            let Some(&kinds) = (material as usize).checked_sub(1).and_then(|slot| self.material_kinds.get(slot)) else {
                continue;
            };
            for (kind, hits) in &mut self.kind_hits {
                hits[p] += u16::from(kinds & kind.bit() != 0);
            }
            for (channel, sums) in &mut self.map_sums {
                let c = &MAP_CHANNELS[*channel];
                if kinds & c.kind.bit() != 0 {
                    sums[p] += s.maps[c.target][p][c.component].to_f32();
                }
            }
        }
    }

    fn finish(self, camera: &Camera, geometry: &Geometry, used: &[UsedMaterial]) -> GBuffer {
        let (width, height) = (self.width, self.height);
        let pixels = self.hits.len();
        let mut normal = Vec::with_capacity(pixels);
        let mut view = Vec::with_capacity(pixels);
        let mut tangent = Vec::with_capacity(pixels);
        let mut coverage = Vec::with_capacity(pixels);
        let mut object_id = Vec::with_capacity(pixels);
        for p in 0..pixels {
            let hits = self.hits[p];
            let (x, y) = ((p as u32 % width) as f32 + 0.5, (p as u32 / width) as f32 + 0.5);
            // Background and edges: the view vector of the ray through the pixel's centre.
            // At scales beyond 32-bit floats the ray is lost; the camera's axis keeps V a unit vector.
            let toward = (-camera.ray(x, y, width, height)).try_normalize().unwrap_or(-camera.forward);
            let n = if hits > 0 { self.normal[p].normalize_or_zero() } else { Vec3::ZERO };
            let (n, v) =
                if n == Vec3::ZERO { (toward, toward) } else { (n, self.view[p].try_normalize().unwrap_or(toward)) };
            let t = crate::gbuffer::orthogonalize(n, self.tangent[p])
                .unwrap_or_else(|| Vec3::from(stable_tangent(n.to_array())));
            normal.push(n.to_array());
            view.push(v.to_array());
            tangent.push(t.to_array());
            coverage.push(hits as f32 / self.samples as f32);
            object_id.push(if hits > 0 { self.vote[p].0 } else { 0 });
        }
        // Each material's mask is its weight over the materials before it, in the order the
        // import stacks their layers: its hits over its own and theirs. Blended in that order, the
        // layers then take exactly their shares of the pixel, however many meet there.
        let mut masks = BTreeMap::new();
        let mut below = vec![0u32; pixels];
        for (slot, material) in used.iter().enumerate() {
            let hits = &self.material_hits[slot];
            let weights = hits
                .iter()
                .zip(below.iter_mut())
                .map(|(&h, below)| {
                    *below += h as u32;
                    if *below > 0 {
                        h as f32 / *below as f32
                    } else {
                        0.0
                    }
                })
                .collect();
            masks.insert(material.channel.clone(), weights);
        }
        // Each map is the mean over the samples of the materials that write it: where a textured
        // material meets another, the map holds the textured one's value for its layer.
        let mut maps = BTreeMap::new();
        for (channel, sums) in &self.map_sums {
            let c = &MAP_CHANNELS[*channel];
            let (_, hits) = self.kind_hits.iter().find(|(k, _)| *k == c.kind).expect("a count per kind present");
            let values = sums.iter().zip(hits).map(|(&sum, &h)| if h > 0 { sum / h as f32 } else { 0.0 }).collect();
            maps.insert(c.name.to_string(), values);
        }
        if let Some(color) = &self.color {
            for (k, channel) in ["r", "g", "b", "a"].iter().enumerate() {
                let values =
                    color.iter().zip(&self.hits).map(|(c, &h)| if h > 0 { c[k] / h as f32 } else { 0.0 }).collect();
                masks.insert(format!("color0.{channel}"), values);
            }
        }
        let object_names = geometry.draws.iter().map(|d| (d.object_id, d.name.clone())).collect();
        let mask_names =
            used.iter().filter(|m| m.label != m.channel).map(|m| (m.channel.clone(), m.label.clone())).collect();
        GBuffer {
            width,
            height,
            normal,
            view,
            tangent,
            coverage,
            object_id,
            masks,
            maps,
            object_names,
            mask_names,
            visibility: None,
            has_view: true,
            has_tangent: true,
            supersample: 1,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_jitter_pattern_is_stratified_and_centred() {
        for n in [1u32, 4, 5, 16, 8] {
            let pattern = jitter_pattern(n);
            assert_eq!(pattern.len(), n as usize);
            let mean = pattern.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
            assert!(mean.0.abs() / (n as f32) < 0.07 && mean.1.abs() / (n as f32) < 0.07, "{n}: {mean:?}");
            // One sample in each of n columns and each of n rows.
            for axis in 0..2 {
                let mut cells: Vec<u32> = pattern
                    .iter()
                    .map(|p| (((if axis == 0 { p.0 } else { p.1 }) + 0.5) * n as f32).floor() as u32)
                    .collect();
                cells.sort_unstable();
                cells.dedup();
                let side = (n as f64).sqrt().round() as u32;
                let expected = if side * side == n { side } else { n };
                assert_eq!(cells.len() as u32, expected, "{n}: axis {axis}");
            }
        }
    }
}
