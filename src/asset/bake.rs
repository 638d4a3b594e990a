//! Baking: an asset rasterized into a g-buffer (README: lookdev bake).
//!
//! Each of `samples` passes draws the whole scene with the camera nudged by a sub-pixel offset
//! (a stratified pattern), and reads back one sample per pixel of every output. The passes are
//! then averaged on the CPU, as the built-in scene's subsamples are: coverage is the fraction of
//! samples that hit, normals, tangents and view vectors are averaged over the hits, the object
//! ID is the one most samples saw, and each mask is the fraction (or mean value) of the samples
//! that carry it.

use super::camera::{self, Camera, CameraChoice};
use super::geometry::{self, Geometry, Vertex};
use super::materials::{self, material_of, Axis, UsedMaterial};
use super::Asset;
use crate::gbuffer::stable_tangent;
use crate::gbuffer::GBuffer;
use crate::gpu::graphics::{Attribute, GraphicsPipeline, PipelineDesc, Sampler, SamplerDesc, TextureSet};
use crate::gpu::{shaders, Buffer, Context, Image};
use crate::{Error, Result};
use ash::vk;
use glam::{Mat4, Vec3, Vec4};
use std::collections::{BTreeMap, HashMap};

/// What a bake makes.
#[derive(Clone, Debug, PartialEq)]
pub struct BakeOptions {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel, one pass each.
    pub samples: u32,
    pub camera: CameraChoice,
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
    flags: u32,
    normal_scale: f32,
    uv_sets: u32,
    alpha_cutoff: f32,
    anisotropy_cos: f32,
    anisotropy_sin: f32,
}

const DRAW_DOUBLE_SIDED: u32 = 1;
const DRAW_NORMAL_MAP: u32 = 2;
const DRAW_METAL_ROUGH_MAP: u32 = 4;
const DRAW_ALPHA_MASK: u32 = 8;
const DRAW_BASE_COLOR_MAP: u32 = 16;

/// The render targets, in the fragment shader's output order, with their formats.
const TARGETS: [vk::Format; 7] = [
    vk::Format::R32G32B32A32_SFLOAT, // normal, w = covered
    vk::Format::R32G32B32A32_SFLOAT, // tangent, w = bitangent sign
    vk::Format::R32G32B32A32_SFLOAT, // view
    vk::Format::R32G32_UINT,         // object id, material + 1
    vk::Format::R32G32B32A32_SFLOAT, // COLOR_0
    vk::Format::R32G32_SFLOAT,       // metallic, roughness texture values
    vk::Format::R32G32B32A32_SFLOAT, // base colour texture, linear
];

/// A material as the fragment shader sees it: its constants and its textures.
struct GpuMaterial {
    flags: u32,
    normal_scale: f32,
    uv_sets: u32,
    alpha_cutoff: f32,
    anisotropy: (f32, f32),
    set: TextureSet,
}

/// The steps of a bake, for progress reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// Reading and transforming primitives (generating tangents), counted in primitives.
    Meshes,
    /// Rasterizing, counted in passes (samples per pixel).
    Passes,
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

    if ctx.info().max_color_attachments < TARGETS.len() as u32 {
        return Err(Error::gpu(format!(
            "{} draws to {} colour targets at once, and the bake writes {}",
            ctx.info().name,
            ctx.info().max_color_attachments,
            TARGETS.len()
        )));
    }
    let rasterizer = Rasterizer::new(ctx, asset, &geometry, &used, width, height)?;
    let mut accumulator = Accumulator::new(width, height, &used, asset, &geometry);
    for (pass, offset) in jitter_pattern(options.samples).into_iter().enumerate() {
        let samples = rasterizer.pass(&geometry, &camera, offset)?;
        accumulator.add(&samples);
        progress(Step::Passes, pass as u32 + 1, options.samples);
    }
    Ok(accumulator.finish(&camera, &geometry, &used))
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

/// The GPU side of a bake: the pipeline, the scene's vertices and textures, and the targets.
struct Rasterizer {
    ctx: Context,
    width: u32,
    height: u32,
    pipeline: GraphicsPipeline,
    vertices: Buffer,
    materials: Vec<GpuMaterial>,
    /// A draw's glTF material index to its place in `materials`.
    slot_of: HashMap<Option<usize>, usize>,
    targets: Vec<Image>,
    depth: Image,
    staging: Buffer,
    /// Where each target's copy starts in `staging`.
    offsets: Vec<u64>,
    // Held so the texture sets' images and samplers stay alive.
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
    metal_rough: &'a [[f32; 2]],
    base_color: &'a [[f32; 4]],
}

impl Rasterizer {
    fn new(
        ctx: &Context,
        asset: &Asset,
        geometry: &Geometry,
        used: &[UsedMaterial],
        width: u32,
        height: u32,
    ) -> Result<Rasterizer> {
        let attribute = |location, format, offset| Attribute { location, format, offset };
        let f32x = |n: usize| match n {
            2 => vk::Format::R32G32_SFLOAT,
            3 => vk::Format::R32G32B32_SFLOAT,
            _ => vk::Format::R32G32B32A32_SFLOAT,
        };
        let attributes = [
            attribute(0, f32x(3), 0),
            attribute(1, f32x(3), 12),
            attribute(2, f32x(4), 24),
            attribute(3, f32x(2), 40),
            attribute(4, f32x(2), 48),
            attribute(5, f32x(4), 56),
        ];
        let pipeline = GraphicsPipeline::new(
            ctx,
            &PipelineDesc {
                vertex: &shaders::BAKE_VERTEX,
                fragment: &shaders::BAKE_FRAGMENT,
                stride: std::mem::size_of::<Vertex>() as u32,
                attributes: &attributes,
                color_formats: &TARGETS,
                depth_format: vk::Format::D32_SFLOAT,
                textures: 3,
                push_size: std::mem::size_of::<DrawConstants>() as u32,
            },
        )?;
        let vertices = Buffer::vertices(ctx, bytemuck::cast_slice(&geometry.vertices))?;
        let targets = TARGETS
            .iter()
            .map(|&format| Image::color_target(ctx, format, width, height))
            .collect::<Result<Vec<_>>>()?;
        let depth = Image::depth_target(ctx, width, height)?;
        // Each target's copy starts on a 16-byte boundary: copies must start on a whole texel.
        let mut offsets = Vec::new();
        let mut end = 0u64;
        for target in &targets {
            offsets.push(end);
            end = (end + target.byte_size()).next_multiple_of(16);
        }
        let staging = Buffer::staging(ctx, end)?;

        // Textures, each image and sampler made once however many materials share it.
        let mut textures: Vec<Image> = Vec::new();
        let mut samplers: Vec<Sampler> = Vec::new();
        let mut texture_of: HashMap<(usize, usize), usize> = HashMap::new();
        let mut sampler_of: HashMap<SamplerDescKey, usize> = HashMap::new();
        // Neutral stand-ins for missing maps: a flat normal, white.
        textures.push(Image::texture(ctx, 1, 1, &[128, 128, 255, 255])?);
        textures.push(Image::texture(ctx, 1, 1, &[255, 255, 255, 255])?);
        samplers.push(Sampler::new(ctx, SamplerDesc::default())?);
        let (flat, white) = (0usize, 1usize);
        let mut texture = |info: Option<gltf::Texture>, fallback: usize| -> Result<(usize, usize)> {
            let Some(texture) = info else { return Ok((fallback, 0)) };
            let desc = sampler_desc(&texture.sampler());
            let sampler = match sampler_of.get(&SamplerDescKey(desc)) {
                Some(&i) => i,
                None => {
                    samplers.push(Sampler::new(ctx, desc)?);
                    sampler_of.insert(SamplerDescKey(desc), samplers.len() - 1);
                    samplers.len() - 1
                }
            };
            let key = (texture.source().index(), 0);
            let image = match texture_of.get(&key) {
                Some(&i) => i,
                None => {
                    let pixels = asset.texture_image(&texture);
                    textures.push(Image::texture(ctx, pixels.width(), pixels.height(), pixels.as_raw()).map_err(
                        |e| Error::input_file(&asset.path, format!("image {}: {e}", texture.source().index())),
                    )?);
                    texture_of.insert(key, textures.len() - 1);
                    textures.len() - 1
                }
            };
            Ok((image, sampler))
        };
        let mut bindings = Vec::new();
        let mut constants = Vec::new();
        for used_material in used {
            let material = material_of(asset, used_material.index);
            let pbr = material.pbr_metallic_roughness();
            let normal = material.normal_texture();
            let metal_rough = pbr.metallic_roughness_texture();
            let masked = material.alpha_mode() == gltf::material::AlphaMode::Mask;
            let base_color = pbr.base_color_texture();
            let mut flags = 0;
            if material.double_sided() {
                flags |= DRAW_DOUBLE_SIDED;
            }
            if normal.is_some() {
                flags |= DRAW_NORMAL_MAP;
            }
            if metal_rough.is_some() {
                flags |= DRAW_METAL_ROUGH_MAP;
            }
            if masked {
                flags |= DRAW_ALPHA_MASK;
            }
            if base_color.is_some() {
                flags |= DRAW_BASE_COLOR_MAP;
            }
            let uv_sets = normal.as_ref().map_or(0, |t| t.tex_coord().min(1))
                | metal_rough.as_ref().map_or(0, |t| t.tex_coord().min(1)) << 2
                | base_color.as_ref().map_or(0, |t| t.tex_coord().min(1)) << 4;
            let anisotropy = materials::anisotropy(&material).map_or(0.0, |a| a.rotation);
            constants.push((
                flags,
                normal.as_ref().map_or(1.0, |t| t.scale()),
                uv_sets,
                // The shader compares COLOR_0's alpha times the texture's; dividing the cutoff
                // by the factor's alpha brings that in too.
                match pbr.base_color_factor()[3] {
                    factor if factor > 0.0 => material.alpha_cutoff().unwrap_or(0.5) / factor,
                    _ => f32::MAX,
                },
                (anisotropy.cos(), anisotropy.sin()),
            ));
            bindings.push([
                texture(normal.map(|t| t.texture()), flat)?,
                texture(metal_rough.map(|t| t.texture()), white)?,
                texture(base_color.map(|t| t.texture()), white)?,
            ]);
        }
        let mut gpu_materials = Vec::new();
        for (binding, (flags, normal_scale, uv_sets, alpha_cutoff, anisotropy)) in bindings.iter().zip(constants) {
            let set = pipeline.texture_set(&binding.map(|(image, sampler)| (&textures[image], &samplers[sampler])))?;
            gpu_materials.push(GpuMaterial { flags, normal_scale, uv_sets, alpha_cutoff, anisotropy, set });
        }
        Ok(Rasterizer {
            ctx: ctx.clone(),
            width,
            height,
            pipeline,
            vertices,
            materials: gpu_materials,
            slot_of: used.iter().enumerate().map(|(slot, m)| (m.index, slot)).collect(),
            targets,
            depth,
            staging,
            offsets,
            _textures: textures,
            _samplers: samplers,
        })
    }

    /// Draws the scene once, with the camera nudged by `offset` pixels, and reads it back.
    fn pass(&self, geometry: &Geometry, camera: &Camera, offset: (f32, f32)) -> Result<Samples<'_>> {
        let (width, height) = (self.width, self.height);
        // Moving clip space by −offset puts the pixel's sample at +offset from its centre.
        let nudge =
            Mat4::from_translation(Vec3::new(-2.0 * offset.0 / width as f32, -2.0 * offset.1 / height as f32, 0.0));
        let view_projection = nudge * camera.view_projection;
        let device = &self.ctx.device;
        self.ctx.run(|cmd| {
            let clear = vk::ClearValue { color: vk::ClearColorValue { float32: [0.0; 4] } };
            let colors: Vec<_> = self
                .targets
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
                .clear_value(vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } });
            let info = vk::RenderingInfo::default()
                .render_area(vk::Rect2D { offset: vk::Offset2D::default(), extent: vk::Extent2D { width, height } })
                .layer_count(1)
                .color_attachments(&colors)
                .depth_attachment(&depth);
            unsafe {
                device.cmd_begin_rendering(cmd, &info);
                device.cmd_bind_vertex_buffers(cmd, 0, &[self.vertices.buffer], &[0]);
            }
            self.pipeline.record_bind(cmd, width, height);
            let toward_eye = -camera.forward;
            for draw in &geometry.draws {
                let used_index = self.slot_of[&draw.material];
                let material = &self.materials[used_index];
                let constants = DrawConstants {
                    view_projection: view_projection.to_cols_array(),
                    eye: [camera.eye.x, camera.eye.y, camera.eye.z, if camera.orthographic { 0.0 } else { 1.0 }],
                    toward_eye: [toward_eye.x, toward_eye.y, toward_eye.z, 0.0],
                    object_id: draw.object_id,
                    material: used_index as u32 + 1,
                    flags: material.flags,
                    normal_scale: material.normal_scale,
                    uv_sets: material.uv_sets,
                    alpha_cutoff: material.alpha_cutoff,
                    anisotropy_cos: material.anisotropy.0,
                    anisotropy_sin: material.anisotropy.1,
                };
                let both_sides = material.flags & DRAW_DOUBLE_SIDED != 0;
                self.pipeline.record_draw(
                    cmd,
                    &material.set,
                    bytemuck::bytes_of(&constants),
                    both_sides,
                    draw.first_vertex,
                    draw.vertex_count,
                );
            }
            unsafe { device.cmd_end_rendering(cmd) };
            crate::gpu::context::full_barrier(device, cmd);
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
            metal_rough: bytemuck::cast_slice(next(8)),
            base_color: bytemuck::cast_slice(next(16)),
        })
    }
}

/// A hashable form of [`SamplerDesc`].
#[derive(Clone, Copy, PartialEq, Eq)]
struct SamplerDescKey(SamplerDesc);

impl std::hash::Hash for SamplerDescKey {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        let d = self.0;
        [d.magnify.as_raw(), d.minify.as_raw(), d.wrap_u.as_raw(), d.wrap_v.as_raw()].hash(state);
    }
}

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
    // Without mip maps, the mip filter is dropped and the base filter kept.
    let minify = match sampler.min_filter() {
        Some(MinFilter::Nearest | MinFilter::NearestMipmapNearest | MinFilter::NearestMipmapLinear) => {
            vk::Filter::NEAREST
        }
        _ => vk::Filter::LINEAR,
    };
    SamplerDesc { magnify, minify, wrap_u: wrap(sampler.wrap_s()), wrap_v: wrap(sampler.wrap_t()) }
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
    /// Per used material with a metallic-roughness texture or texture axes: its texture sums.
    textures: Vec<Option<TextureSums>>,
}

/// Per-pixel sums, over a material's samples, of its texture values and corner-layer weights
/// (README: Texture layers).
struct TextureSums {
    /// Whether the material has a metallic-roughness texture, whose raw values are always masks.
    metal_rough: bool,
    axes: Vec<Axis>,
    /// The base colour factor, which multiplies the texture's texels.
    color_factor: [f32; 3],
    /// Per pixel: metallic, roughness, then one position per axis, then the weight of each
    /// corner layer but the first.
    sums: Vec<f32>,
    stride: usize,
}

impl TextureSums {
    fn new(material: &gltf::Material, axes: Vec<Axis>, pixels: usize) -> TextureSums {
        let stride = 2 + axes.len() + (1 << axes.len()) - 1;
        let factor = material.pbr_metallic_roughness().base_color_factor();
        TextureSums {
            metal_rough: material.pbr_metallic_roughness().metallic_roughness_texture().is_some(),
            axes,
            color_factor: [factor[0], factor[1], factor[2]],
            sums: vec![0.0; pixels * stride],
            stride,
        }
    }

    fn add(&mut self, pixel: usize, metal_rough: [f32; 2], color: [f32; 4]) {
        let color = [0, 1, 2].map(|k| color[k] * self.color_factor[k]);
        let positions: Vec<f32> = self.axes.iter().map(|axis| axis.position(metal_rough, color)).collect();
        let sums = &mut self.sums[pixel * self.stride..(pixel + 1) * self.stride];
        let values = metal_rough.iter().chain(&positions).copied().chain(materials::corner_weights(&positions));
        for (sum, value) in sums.iter_mut().zip(values) {
            *sum += value;
        }
    }

    /// The masks, each sum over the pixel's hits on any material: so that where materials meet,
    /// each one's texture layers take only its share.
    fn masks(&self, channel: &str, hits: &[u16], masks: &mut BTreeMap<String, Vec<f32>>) {
        let mean = |k: usize| -> Vec<f32> {
            hits.iter()
                .enumerate()
                .map(|(p, &h)| if h > 0 { self.sums[p * self.stride + k] / h as f32 } else { 0.0 })
                .collect()
        };
        if self.metal_rough {
            masks.insert(format!("{channel}.metallic"), mean(0));
            masks.insert(format!("{channel}.roughness"), mean(1));
        }
        for (i, axis) in self.axes.iter().enumerate() {
            if matches!(axis, Axis::BaseColor { .. }) {
                masks.insert(materials::value_mask(channel, axis), mean(2 + i));
            }
        }
        for corner in 1..1usize << self.axes.len() {
            masks.insert(materials::corner_mask(channel, &self.axes, corner), mean(2 + self.axes.len() + corner - 1));
        }
    }
}

impl Accumulator {
    fn new(width: u32, height: u32, used: &[UsedMaterial], asset: &Asset, geometry: &Geometry) -> Accumulator {
        let pixels = (width * height) as usize;
        let textures = used
            .iter()
            .map(|m| {
                let material = material_of(asset, m.index);
                let axes = materials::map(asset, &material).axes;
                let textured = material.pbr_metallic_roughness().metallic_roughness_texture().is_some();
                (textured || !axes.is_empty()).then(|| TextureSums::new(&material, axes, pixels))
            })
            .collect();
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
            material_hits: used.iter().map(|_| vec![0; pixels]).collect(),
            color: geometry.draws.iter().any(|d| d.has_colors).then(|| vec![Vec4::ZERO; pixels]),
            textures,
        }
    }

    fn add(&mut self, s: &Samples) {
        self.samples += 1;
        for p in 0..self.hits.len() {
            if s.normal[p][3] < 0.5 {
                continue;
            }
            self.hits[p] += 1;
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
            if let Some(sums) = &mut self.textures[slot] {
                sums.add(p, s.metal_rough[p], s.base_color[p]);
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
            let toward = -camera.ray(x, y, width, height);
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
        let share = |count: &[u16]| -> Vec<f32> {
            count.iter().zip(&self.hits).map(|(&c, &h)| if h > 0 { c as f32 / h as f32 } else { 0.0 }).collect()
        };
        let mut masks = BTreeMap::new();
        for (slot, material) in used.iter().enumerate() {
            masks.insert(material.channel.clone(), share(&self.material_hits[slot]));
            if let Some(sums) = &self.textures[slot] {
                sums.masks(&material.channel, &self.hits, &mut masks);
            }
        }
        if let Some(color) = &self.color {
            for (k, channel) in ["r", "g", "b", "a"].iter().enumerate() {
                let values =
                    color.iter().zip(&self.hits).map(|(c, &h)| if h > 0 { c[k] / h as f32 } else { 0.0 }).collect();
                masks.insert(format!("color0.{channel}"), values);
            }
        }
        let object_names = geometry.draws.iter().map(|d| (d.object_id, d.name.clone())).collect();
        GBuffer {
            width,
            height,
            normal,
            view,
            tangent,
            coverage,
            object_id,
            masks,
            maps: BTreeMap::new(),
            object_names,
            has_view: true,
            has_tangent: true,
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
