//! Graphics pipelines, for rasterizing scenes into g-buffers: a vertex and a fragment stage from
//! committed SPIR-V, several colour targets and a depth buffer, drawn with dynamic rendering into
//! images that stay in the GENERAL layout like every other image.

use super::context::{Context, Shared};
use super::memory::{Buffer, Image};
use super::pipeline::BindingKind;
use super::pipeline::ShaderModule;
use super::shaders::Stage;
use crate::{Error, Result};
use ash::vk;
use std::sync::Arc;

/// One vertex attribute: its shader location, format and byte offset within a vertex.
#[derive(Clone, Copy, Debug)]
pub struct Attribute {
    pub location: u32,
    pub format: vk::Format,
    pub offset: u32,
}

/// What a pipeline draws from and into.
pub struct PipelineDesc<'a> {
    pub vertex: &'a Stage,
    pub fragment: &'a Stage,
    /// Bytes per vertex in the one interleaved vertex buffer.
    pub stride: u32,
    pub attributes: &'a [Attribute],
    pub color_formats: &'a [vk::Format],
    pub depth_format: vk::Format,
    /// An array of this many combined image samplers at descriptor set 0, binding 0, which the
    /// fragment stage samples; then, at binding 1, one storage buffer both stages read.
    pub textures: u32,
    /// Bytes of push constants, seen by both stages.
    pub push_size: u32,
}

/// A triangle-list pipeline with depth testing and a per-draw cull mode.
pub struct GraphicsPipeline {
    shared: Arc<Shared>,
    pipeline: vk::Pipeline,
    layout: vk::PipelineLayout,
    set_layout: vk::DescriptorSetLayout,
    textures: u32,
    push_size: u32,
}

/// The descriptor set of every graphics pipeline: `textures` combined image samplers at binding
/// 0, then one storage buffer.
pub const fn set_layout(textures: u32) -> [BindingKind; 2] {
    [BindingKind::Textures(textures), BindingKind::StorageBuffer]
}

const STAGES: vk::ShaderStageFlags =
    vk::ShaderStageFlags::from_raw(vk::ShaderStageFlags::VERTEX.as_raw() | vk::ShaderStageFlags::FRAGMENT.as_raw());

impl GraphicsPipeline {
    pub fn new(ctx: &Context, desc: &PipelineDesc) -> Result<GraphicsPipeline> {
        let device = &ctx.shared.device;
        let bindings: Vec<_> = set_layout(desc.textures)
            .into_iter()
            .enumerate()
            .map(|(i, kind)| {
                // Only the fragment stage samples the textures.
                let stages = if kind == BindingKind::StorageBuffer { STAGES } else { vk::ShaderStageFlags::FRAGMENT };
                vk::DescriptorSetLayoutBinding::default()
                    .binding(i as u32)
                    .descriptor_type(kind.descriptor_type())
                    .descriptor_count(kind.count())
                    .stage_flags(stages)
            })
            .collect();
        let set_layout = unsafe {
            device.create_descriptor_set_layout(&vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings), None)
        }?;
        // From here on, Drop releases whatever has been created if a later step fails.
        let mut result = GraphicsPipeline {
            shared: ctx.shared.clone(),
            pipeline: vk::Pipeline::null(),
            layout: vk::PipelineLayout::null(),
            set_layout,
            textures: desc.textures,
            push_size: desc.push_size,
        };
        let ranges = [vk::PushConstantRange::default().stage_flags(STAGES).size(desc.push_size)];
        let set_layouts = [set_layout];
        let layout_info =
            vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts).push_constant_ranges(&ranges);
        result.layout = unsafe { device.create_pipeline_layout(&layout_info, None) }?;

        let vertex = ShaderModule::new(&ctx.shared, desc.vertex.spirv, &format!("shader {}", desc.vertex.file))?;
        let fragment = ShaderModule::new(&ctx.shared, desc.fragment.spirv, &format!("shader {}", desc.fragment.file))?;
        let stages = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::VERTEX)
                .module(vertex.handle)
                .name(c"main"),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(fragment.handle)
                .name(c"main"),
        ];
        let binding = [vk::VertexInputBindingDescription::default()
            .binding(0)
            .stride(desc.stride)
            .input_rate(vk::VertexInputRate::VERTEX)];
        let attributes: Vec<_> = desc
            .attributes
            .iter()
            .map(|a| {
                vk::VertexInputAttributeDescription::default()
                    .location(a.location)
                    .binding(0)
                    .format(a.format)
                    .offset(a.offset)
            })
            .collect();
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
            .vertex_binding_descriptions(&binding)
            .vertex_attribute_descriptions(&attributes);
        let assembly =
            vk::PipelineInputAssemblyStateCreateInfo::default().topology(vk::PrimitiveTopology::TRIANGLE_LIST);
        let viewport = vk::PipelineViewportStateCreateInfo::default().viewport_count(1).scissor_count(1);
        // Counter-clockwise is front, as in glTF; the projection's y flip is undone by the viewport.
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .line_width(1.0);
        let multisample =
            vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let depth = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(true)
            .depth_write_enable(true)
            .depth_compare_op(vk::CompareOp::LESS);
        let blend_attachments: Vec<_> = desc
            .color_formats
            .iter()
            .map(|_| vk::PipelineColorBlendAttachmentState::default().color_write_mask(vk::ColorComponentFlags::RGBA))
            .collect();
        let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
        let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR, vk::DynamicState::CULL_MODE];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let mut rendering = vk::PipelineRenderingCreateInfo::default()
            .color_attachment_formats(desc.color_formats)
            .depth_attachment_format(desc.depth_format);
        let info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(result.layout)
            .push_next(&mut rendering);
        let created = unsafe { device.create_graphics_pipelines(ctx.shared.pipeline_cache(), &[info], None) };
        result.pipeline = created.map_err(|(_, e)| {
            Error::gpu(format!("pipeline {} + {}: creation failed ({e})", desc.vertex.file, desc.fragment.file))
        })?[0];
        Ok(result)
    }

    /// A descriptor set binding `textures` (image and sampler) as the array at binding 0, and
    /// `buffer` at binding 1.
    pub fn texture_set(&self, textures: &[(&Image, &Sampler)], buffer: &Buffer) -> Result<TextureSet> {
        assert_eq!(textures.len() as u32, self.textures, "the pipeline takes {} textures", self.textures);
        let device = &self.shared.device;
        let sizes = [
            vk::DescriptorPoolSize::default()
                .ty(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                .descriptor_count(self.textures.max(1)),
            vk::DescriptorPoolSize::default().ty(vk::DescriptorType::STORAGE_BUFFER).descriptor_count(1),
        ];
        let pool = unsafe {
            device.create_descriptor_pool(&vk::DescriptorPoolCreateInfo::default().max_sets(1).pool_sizes(&sizes), None)
        }?;
        let mut result = TextureSet { shared: self.shared.clone(), pool, set: vk::DescriptorSet::null() };
        let layouts = [self.set_layout];
        let set = unsafe {
            device.allocate_descriptor_sets(
                &vk::DescriptorSetAllocateInfo::default().descriptor_pool(pool).set_layouts(&layouts),
            )
        }?[0];
        result.set = set;
        let infos: Vec<vk::DescriptorImageInfo> = textures
            .iter()
            .map(|(image, sampler)| {
                vk::DescriptorImageInfo::default()
                    .sampler(sampler.sampler)
                    .image_view(image.view)
                    .image_layout(vk::ImageLayout::GENERAL)
            })
            .collect();
        let buffer_info = [vk::DescriptorBufferInfo::default().buffer(buffer.buffer).range(vk::WHOLE_SIZE)];
        let writes = [
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(0)
                .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                .image_info(&infos),
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(1)
                .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                .buffer_info(&buffer_info),
        ];
        unsafe { device.update_descriptor_sets(&writes, &[]) };
        Ok(result)
    }

    /// Records binding the pipeline and setting the viewport and scissor to `width`×`height`.
    pub fn record_bind(&self, cmd: vk::CommandBuffer, width: u32, height: u32) {
        let device = &self.shared.device;
        let viewport =
            vk::Viewport { x: 0.0, y: 0.0, width: width as f32, height: height as f32, min_depth: 0.0, max_depth: 1.0 };
        let scissor = vk::Rect2D { offset: vk::Offset2D::default(), extent: vk::Extent2D { width, height } };
        unsafe {
            device.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
            device.cmd_set_viewport(cmd, 0, &[viewport]);
            device.cmd_set_scissor(cmd, 0, &[scissor]);
        }
    }

    /// Records one draw of `count` vertices from `first`, with its textures and push constants;
    /// back faces are culled unless `both_sides`.
    pub fn record_draw(
        &self,
        cmd: vk::CommandBuffer,
        set: &TextureSet,
        push: &[u8],
        both_sides: bool,
        first: u32,
        count: u32,
    ) {
        assert_eq!(push.len() as u32, self.push_size, "push constant size");
        let device = &self.shared.device;
        let cull = if both_sides { vk::CullModeFlags::NONE } else { vk::CullModeFlags::BACK };
        unsafe {
            device.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::GRAPHICS, self.layout, 0, &[set.set], &[]);
            device.cmd_push_constants(cmd, self.layout, STAGES, 0, push);
            device.cmd_set_cull_mode(cmd, cull);
            device.cmd_draw(cmd, count, 1, first, 0);
        }
    }
}

impl Drop for GraphicsPipeline {
    fn drop(&mut self) {
        let device = &self.shared.device;
        unsafe {
            device.destroy_pipeline(self.pipeline, None);
            device.destroy_pipeline_layout(self.layout, None);
            device.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

/// A pipeline's textures, with its own small descriptor pool.
pub struct TextureSet {
    shared: Arc<Shared>,
    pool: vk::DescriptorPool,
    set: vk::DescriptorSet,
}

impl Drop for TextureSet {
    fn drop(&mut self) {
        unsafe { self.shared.device.destroy_descriptor_pool(self.pool, None) };
    }
}

/// How a texture is filtered and wrapped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SamplerDesc {
    pub magnify: vk::Filter,
    pub minify: vk::Filter,
    /// Between mip levels; `None` samples the full-size level only.
    pub mipmap: Option<vk::SamplerMipmapMode>,
    pub wrap_u: vk::SamplerAddressMode,
    pub wrap_v: vk::SamplerAddressMode,
}

impl Default for SamplerDesc {
    /// Trilinear filtering, repeating: glTF's defaults where a sampler leaves them open.
    fn default() -> Self {
        SamplerDesc {
            magnify: vk::Filter::LINEAR,
            minify: vk::Filter::LINEAR,
            mipmap: Some(vk::SamplerMipmapMode::LINEAR),
            wrap_u: vk::SamplerAddressMode::REPEAT,
            wrap_v: vk::SamplerAddressMode::REPEAT,
        }
    }
}

/// A sampler, destroyed when dropped.
pub struct Sampler {
    shared: Arc<Shared>,
    pub sampler: vk::Sampler,
}

impl Sampler {
    pub fn new(ctx: &Context, desc: SamplerDesc) -> Result<Sampler> {
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(desc.magnify)
            .min_filter(desc.minify)
            .address_mode_u(desc.wrap_u)
            .address_mode_v(desc.wrap_v)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .mipmap_mode(desc.mipmap.unwrap_or(vk::SamplerMipmapMode::NEAREST))
            .max_lod(if desc.mipmap.is_some() { vk::LOD_CLAMP_NONE } else { 0.0 });
        let sampler = unsafe { ctx.shared.device.create_sampler(&info, None) }?;
        Ok(Sampler { shared: ctx.shared.clone(), sampler })
    }
}

impl Drop for Sampler {
    fn drop(&mut self) {
        unsafe { self.shared.device.destroy_sampler(self.sampler, None) };
    }
}
