//! The resolve pass (`resolve.comp`): each pixel's layer stack, blended through its masks and
//! maps into one material, written to [`Targets::resolved`](super::Targets). It runs once per
//! edit of the stacks, not per sample, and flags the covered pixels whose material it changed,
//! bit for bit, so that an edit can restart only those (docs/commands.md#edit-local-re-convergence).

use super::{groups, Targets};
use crate::gbuffer::gpu::GpuGBuffer;
use crate::gpu::{
    shaders, Binding, BindingKind, Buffer, ComputePipeline, Context, DescriptorSet, GlslLayout, Image, Interface,
};
use crate::material::stack::{GpuLayer, GpuStack, PackedStacks};
use crate::Result;
use ash::vk;

/// Set 0 of `resolve.comp`: stack index per pixel, mask and map channels, stacks, layers, the
/// resolved material, the surface (for coverage), and the bits of the pixels that changed.
pub const SET: [BindingKind; 7] = [
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageBuffer,
    BindingKind::StorageBuffer,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageBuffer,
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

/// The resolve pipeline, the stacks it reads, and the change bits it writes.
pub struct ResolvePass {
    ctx: Context,
    pipeline: ComputePipeline,
    stacks: Option<Stacks>,
    /// One bit per pixel (index y·width + x, 32 to a word), set by the last resolve where a
    /// covered pixel's material changed; made with the first stacks.
    changed: Option<Buffer>,
}

impl ResolvePass {
    /// The pass, with its pipeline compiled by [`ResolvePass::pipeline`].
    pub fn new(ctx: &Context, pipeline: ComputePipeline) -> ResolvePass {
        ResolvePass { ctx: ctx.clone(), pipeline, stacks: None, changed: None }
    }

    /// Compiles `resolve.comp`.
    pub fn pipeline(ctx: &Context) -> Result<ComputePipeline> {
        ComputePipeline::new(ctx, &shaders::RESOLVE, INTERFACE.sets, INTERFACE.push_size())
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
        let pixels = targets.resolved.width as u64 * targets.resolved.height as u64;
        if self.changed.is_none() {
            self.changed = Some(Buffer::storage(ctx, pixels.div_ceil(32) * 4)?);
        }
        let changed = self.changed.as_ref().expect("just made");
        let (surface, channels) = gbuffer.surface_and_channel_layers(ctx, packed)?;
        let set = self.pipeline.bind(
            0,
            &[
                Binding::Image(&stack_index),
                Binding::Image(channels),
                Binding::Buffer(&stacks),
                Binding::Buffer(&layers),
                Binding::Image(&targets.resolved),
                Binding::Image(surface),
                Binding::Buffer(changed),
            ],
        )?;
        self.stacks = Some(Stacks { _stack_index: stack_index, _stacks: stacks, _layers: layers, set });
        Ok(())
    }

    /// Whether stacks have been set.
    pub fn has_stacks(&self) -> bool {
        self.stacks.is_some()
    }

    /// Records the resolve of every pixel of a `width` × `height` image, after clearing the
    /// change bits.
    pub fn record(&self, cmd: vk::CommandBuffer, width: u32, height: u32) {
        let stacks = self.stacks.as_ref().expect("set_stacks() runs before the resolve");
        let changed = self.changed.as_ref().expect("made with the stacks");
        let device = &self.ctx.shared.device;
        unsafe { device.cmd_fill_buffer(cmd, changed.buffer, 0, vk::WHOLE_SIZE, 0) };
        crate::gpu::context::full_barrier(device, cmd);
        self.pipeline.dispatch(cmd, &[&stacks.set], &[], groups(width, height));
    }

    /// The covered pixels whose resolved material the last resolve changed, bit for bit, as
    /// indices y·width + x, ascending.
    pub fn changed_pixels(&self, pixels: usize) -> Result<Vec<u32>> {
        let changed = self.changed.as_ref().expect("set_stacks() runs before the resolve");
        let bytes = changed.read(&self.ctx)?;
        let words: Vec<u32> = bytes
            .chunks_exact(4)
            .take(pixels.div_ceil(32))
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
            .collect();
        Ok(changed_indices(&words, pixels))
    }
}

/// The indices of the set bits of `words` (bit i of word w is index 32·w + i), below `pixels`,
/// ascending.
fn changed_indices(words: &[u32], pixels: usize) -> Vec<u32> {
    let mut indices = Vec::new();
    for (w, &word) in words.iter().enumerate() {
        let mut bits = word;
        while bits != 0 {
            let index = 32 * w as u32 + bits.trailing_zeros();
            if (index as usize) < pixels {
                indices.push(index);
            }
            bits &= bits - 1;
        }
    }
    indices
}

#[cfg(test)]
mod tests {
    use super::changed_indices;

    #[test]
    fn change_bits_become_ascending_indices() {
        assert_eq!(changed_indices(&[], 0), Vec::<u32>::new());
        assert_eq!(changed_indices(&[0b1001, 0, 1 << 31], 96), vec![0, 3, 95]);
        assert_eq!(changed_indices(&[u32::MAX], 5), vec![0, 1, 2, 3, 4], "bits past the image are not pixels");
    }
}
