//! Compute pipelines from committed SPIR-V, and their descriptor sets.

use super::context::{Context, Shared};
use super::inject::{self, Step};
use super::memory::{Buffer, Image};
use super::shaders::Kernel;
use crate::{Error, Result};
use ash::vk;
use std::sync::Arc;

/// The kind of one binding in a descriptor set layout.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BindingKind {
    StorageImage,
    StorageBuffer,
    /// A small block of constants every invocation reads alike: a CPU driver loads a uniform
    /// buffer's values once for all lanes, where it reads a storage buffer lane by lane.
    UniformBuffer,
    /// An array of this many combined image samplers (the bake's textures).
    Textures(u32),
}

impl BindingKind {
    pub fn descriptor_type(self) -> vk::DescriptorType {
        match self {
            BindingKind::StorageImage => vk::DescriptorType::STORAGE_IMAGE,
            BindingKind::StorageBuffer => vk::DescriptorType::STORAGE_BUFFER,
            BindingKind::UniformBuffer => vk::DescriptorType::UNIFORM_BUFFER,
            BindingKind::Textures(_) => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
        }
    }

    /// Descriptors at the binding.
    pub fn count(self) -> u32 {
        match self {
            BindingKind::Textures(count) => count,
            _ => 1,
        }
    }
}

/// A shader module for as long as pipelines are being made from it: destroyed when dropped.
pub(crate) struct ShaderModule<'a> {
    device: &'a ash::Device,
    pub(crate) handle: vk::ShaderModule,
}

impl<'a> ShaderModule<'a> {
    /// `what` names the SPIR-V in errors.
    pub(crate) fn new(shared: &'a Shared, spirv: &[u8], what: &str) -> Result<ShaderModule<'a>> {
        let code = ash::util::read_spv(&mut std::io::Cursor::new(spirv))
            .map_err(|e| Error::gpu(format!("{what}: bad SPIR-V ({e})")))?;
        let info = vk::ShaderModuleCreateInfo::default().code(&code);
        let handle = unsafe { shared.device.create_shader_module(&info, None) }?;
        Ok(ShaderModule { device: &shared.device, handle })
    }
}

impl Drop for ShaderModule<'_> {
    fn drop(&mut self) {
        unsafe { self.device.destroy_shader_module(self.handle, None) };
    }
}

/// A resource bound at one binding.
pub enum Binding<'a> {
    Image(&'a Image),
    Buffer(&'a Buffer),
}

/// A compute pipeline with its set layouts (binding i of set s has kind `sets[s][i]`) and a
/// push-constant block.
pub struct ComputePipeline {
    shared: Arc<Shared>,
    pub name: &'static str,
    pipeline: vk::Pipeline,
    layout: vk::PipelineLayout,
    set_layouts: Vec<vk::DescriptorSetLayout>,
    set_kinds: Vec<Vec<BindingKind>>,
    push_size: u32,
}

impl ComputePipeline {
    pub fn new(ctx: &Context, kernel: &Kernel, sets: &[&[BindingKind]], push_size: u32) -> Result<ComputePipeline> {
        ComputePipeline::specialized(ctx, kernel, sets, push_size, &[])
    }

    /// A pipeline whose specialization constants 0, 1, … take the 32-bit values `constants`
    /// (model.glsl's model choices); the rest keep their defaults.
    pub fn specialized(
        ctx: &Context,
        kernel: &Kernel,
        sets: &[&[BindingKind]],
        push_size: u32,
        constants: &[u32],
    ) -> Result<ComputePipeline> {
        let _timing = crate::timings::phase(format_args!("pipeline {}", kernel.name));
        let device = &ctx.shared.device;
        // From here on, Drop releases whatever has been created if a later step fails.
        let mut result = ComputePipeline {
            shared: ctx.shared.clone(),
            name: kernel.name,
            pipeline: vk::Pipeline::null(),
            layout: vk::PipelineLayout::null(),
            set_layouts: Vec::new(),
            set_kinds: sets.iter().map(|s| s.to_vec()).collect(),
            push_size,
        };
        let module = ShaderModule::new(&ctx.shared, kernel.spirv, &format!("kernel {}", kernel.name))?;
        for kinds in sets {
            let bindings: Vec<_> = kinds
                .iter()
                .enumerate()
                .map(|(i, kind)| {
                    vk::DescriptorSetLayoutBinding::default()
                        .binding(i as u32)
                        .descriptor_type(kind.descriptor_type())
                        .descriptor_count(1)
                        .stage_flags(vk::ShaderStageFlags::COMPUTE)
                })
                .collect();
            let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings);
            inject::check(Step::SetLayout)?;
            result.set_layouts.push(unsafe { device.create_descriptor_set_layout(&info, None) }?);
        }
        let ranges = [vk::PushConstantRange::default().stage_flags(vk::ShaderStageFlags::COMPUTE).size(push_size)];
        let mut layout_info = vk::PipelineLayoutCreateInfo::default().set_layouts(&result.set_layouts);
        if push_size > 0 {
            layout_info = layout_info.push_constant_ranges(&ranges);
        }
        inject::check(Step::PipelineLayout)?;
        result.layout = unsafe { device.create_pipeline_layout(&layout_info, None) }?;
        let entries: Vec<vk::SpecializationMapEntry> = (0..constants.len() as u32)
            .map(|i| vk::SpecializationMapEntry::default().constant_id(i).offset(4 * i).size(4))
            .collect();
        let specialization =
            vk::SpecializationInfo::default().map_entries(&entries).data(bytemuck::cast_slice(constants));
        let mut stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module.handle)
            .name(c"main");
        if !constants.is_empty() {
            stage = stage.specialization_info(&specialization);
        }
        let info = vk::ComputePipelineCreateInfo::default().stage(stage).layout(result.layout);
        inject::check(Step::Pipeline)?;
        result.pipeline = unsafe { device.create_compute_pipelines(ctx.shared.pipeline_cache(), &[info], None) }
            .map_err(|(_, e)| Error::gpu(format!("kernel {}: pipeline creation failed ({e})", kernel.name)))?[0];
        Ok(result)
    }

    /// Makes descriptor set `set` from `bindings`, which must match the layout.
    pub fn bind(&self, set: usize, bindings: &[Binding]) -> Result<DescriptorSet> {
        let kinds = &self.set_kinds[set];
        assert_eq!(kinds.len(), bindings.len(), "kernel {}: set {set} needs {} bindings", self.name, kinds.len());
        DescriptorSet::new(&self.shared, self.set_layouts[set], kinds, bindings)
    }

    /// Records a dispatch of `groups` workgroups with the given sets and push constants.
    pub fn dispatch(&self, cmd: vk::CommandBuffer, sets: &[&DescriptorSet], push: &[u8], groups: [u32; 3]) {
        assert_eq!(push.len() as u32, self.push_size, "kernel {}: push constant size", self.name);
        let device = &self.shared.device;
        let handles: Vec<_> = sets.iter().map(|s| s.set).collect();
        unsafe {
            device.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline);
            device.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.layout, 0, &handles, &[]);
            if !push.is_empty() {
                device.cmd_push_constants(cmd, self.layout, vk::ShaderStageFlags::COMPUTE, 0, push);
            }
            device.cmd_dispatch(cmd, groups[0], groups[1], groups[2]);
        }
    }
}

impl Drop for ComputePipeline {
    fn drop(&mut self) {
        // Destroying a null handle does nothing, so a half-made pipeline drops cleanly.
        unsafe {
            let device = &self.shared.device;
            device.destroy_pipeline(self.pipeline, None);
            device.destroy_pipeline_layout(self.layout, None);
            for layout in &self.set_layouts {
                device.destroy_descriptor_set_layout(*layout, None);
            }
        }
    }
}

/// One descriptor set with its own small pool, freed when dropped.
pub struct DescriptorSet {
    shared: Arc<Shared>,
    pool: vk::DescriptorPool,
    pub(crate) set: vk::DescriptorSet,
}

impl DescriptorSet {
    fn new(
        shared: &Arc<Shared>,
        layout: vk::DescriptorSetLayout,
        kinds: &[BindingKind],
        bindings: &[Binding],
    ) -> Result<DescriptorSet> {
        let device = &shared.device;
        let sizes: Vec<_> = [BindingKind::StorageImage, BindingKind::StorageBuffer, BindingKind::UniformBuffer]
            .into_iter()
            .filter_map(|kind| {
                let count = kinds.iter().filter(|k| **k == kind).count() as u32;
                (count > 0)
                    .then(|| vk::DescriptorPoolSize::default().ty(kind.descriptor_type()).descriptor_count(count))
            })
            .collect();
        let pool_info = vk::DescriptorPoolCreateInfo::default().max_sets(1).pool_sizes(&sizes);
        let pool = unsafe { device.create_descriptor_pool(&pool_info, None) }?;
        // From here on, Drop releases whatever has been created if a later step fails.
        let mut result = DescriptorSet { shared: shared.clone(), pool, set: vk::DescriptorSet::null() };
        let layouts = [layout];
        let alloc = vk::DescriptorSetAllocateInfo::default().descriptor_pool(pool).set_layouts(&layouts);
        let set = unsafe { device.allocate_descriptor_sets(&alloc) }?[0];
        result.set = set;
        let image_infos: Vec<[vk::DescriptorImageInfo; 1]> = bindings
            .iter()
            .map(|b| match b {
                Binding::Image(image) => {
                    [vk::DescriptorImageInfo::default().image_view(image.view).image_layout(vk::ImageLayout::GENERAL)]
                }
                Binding::Buffer(_) => [vk::DescriptorImageInfo::default()],
            })
            .collect();
        let buffer_infos: Vec<[vk::DescriptorBufferInfo; 1]> = bindings
            .iter()
            .map(|b| match b {
                Binding::Buffer(buffer) => {
                    [vk::DescriptorBufferInfo::default().buffer(buffer.buffer).range(vk::WHOLE_SIZE)]
                }
                Binding::Image(_) => [vk::DescriptorBufferInfo::default()],
            })
            .collect();
        let writes: Vec<_> = bindings
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let fits = match b {
                    Binding::Image(_) => kinds[i] == BindingKind::StorageImage,
                    Binding::Buffer(_) => matches!(kinds[i], BindingKind::StorageBuffer | BindingKind::UniformBuffer),
                };
                assert!(fits, "binding {i} has the wrong kind");
                let write = vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(i as u32)
                    .descriptor_type(kinds[i].descriptor_type());
                match b {
                    Binding::Image(_) => write.image_info(&image_infos[i]),
                    Binding::Buffer(_) => write.buffer_info(&buffer_infos[i]),
                }
            })
            .collect();
        unsafe { device.update_descriptor_sets(&writes, &[]) };
        Ok(result)
    }
}

impl Drop for DescriptorSet {
    fn drop(&mut self) {
        unsafe { self.shared.device.destroy_descriptor_pool(self.pool, None) };
    }
}

/// The number of workgroups of `local` invocations that cover `size`.
pub fn group_count(size: u32, local: u32) -> u32 {
    size.div_ceil(local)
}
