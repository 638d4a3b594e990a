//! The resolve pass (`resolve.comp`): each pixel's layer stack, blended through its masks and
//! maps into one material, written to [`Targets::resolved`](super::Targets). It runs once per
//! edit of the stacks, not per sample.

use super::{groups, Targets};
use crate::gbuffer::gpu::GpuGBuffer;
use crate::gpu::{
    shaders, Binding, BindingKind, Buffer, ComputePipeline, Context, DescriptorSet, GlslLayout, Image, Interface,
};
use crate::material::stack::{GpuLayer, GpuStack, PackedStacks};
use crate::Result;
use ash::vk;

/// Set 0 of `resolve.comp`: stack index per pixel, mask and map channels, stacks, layers, the
/// resolved material.
pub const SET: [BindingKind; 5] = [
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageBuffer,
    BindingKind::StorageBuffer,
    BindingKind::StorageImage,
];

/// What `resolve.comp` and the host agree on: no push constants, and the stacks and layers as
/// [`PackedStacks`] holds them.
pub const INTERFACE: Interface =
    Interface { structs: &[GpuStack::GLSL, GpuLayer::GLSL], ..Interface::compute(&shaders::RESOLVE, &[&SET], None) };

/// The stacks on the GPU, held while the set points at them.
struct Stacks {
    _stack_index: Image,
    _stacks: Buffer,
    _layers: Buffer,
    set: DescriptorSet,
}

pub struct ResolvePass {
    pipeline: ComputePipeline,
    stacks: Option<Stacks>,
}

impl ResolvePass {
    pub fn new(ctx: &Context) -> Result<ResolvePass> {
        Ok(ResolvePass {
            pipeline: ComputePipeline::new(ctx, &shaders::RESOLVE, INTERFACE.sets, INTERFACE.push_size())?,
            stacks: None,
        })
    }

    /// Uploads `packed` (and the g-buffer channels it reads) and binds it for [`Self::record`].
    pub fn set_stacks(
        &mut self,
        ctx: &Context,
        gbuffer: &mut GpuGBuffer,
        packed: &PackedStacks,
        targets: &Targets,
    ) -> Result<()> {
        let stack_index = gbuffer.stack_index(ctx, packed)?;
        let stacks = Buffer::with_data(ctx, bytemuck::cast_slice(&packed.stacks))?;
        let layers = Buffer::with_data(ctx, bytemuck::cast_slice(&packed.layers))?;
        let channels = gbuffer.channel_layers(ctx, packed)?;
        let set = self.pipeline.bind(
            0,
            &[
                Binding::Image(&stack_index),
                Binding::Image(channels),
                Binding::Buffer(&stacks),
                Binding::Buffer(&layers),
                Binding::Image(&targets.resolved),
            ],
        )?;
        self.stacks = Some(Stacks { _stack_index: stack_index, _stacks: stacks, _layers: layers, set });
        Ok(())
    }

    /// Whether stacks have been set.
    pub fn has_stacks(&self) -> bool {
        self.stacks.is_some()
    }

    /// Records the resolve of every pixel of a `width` × `height` image.
    pub fn record(&self, cmd: vk::CommandBuffer, width: u32, height: u32) {
        let stacks = self.stacks.as_ref().expect("set_stacks() runs before the resolve");
        self.pipeline.dispatch(cmd, &[&stacks.set], &[], groups(width, height));
    }
}
