//! The resolve pass (`resolve.comp`): each pixel's layer stack, blended through its masks and
//! maps into one material, written to [`Targets::resolved`](super::Targets). It runs once per
//! edit of the stacks, not per sample, over the covered pixels of the stacks that changed since
//! the last resolve, and flags the pixels whose material it changed, bit for bit, so that an
//! edit can restart only those (docs/commands.md#edit-local-re-convergence).

use super::pixel_lists::{self, PixelLists};
use super::Targets;
use crate::gbuffer::gpu::GpuGBuffer;
use crate::gpu::{
    shaders, Binding, BindingKind, Buffer, ComputePipeline, Context, DescriptorSet, GlslLayout, Image, Interface,
};
use crate::material::stack::{PackedStacks, LAYER_TEXELS};
use crate::Result;
use ash::vk;

/// Set 0 of `resolve.comp`: stack index per pixel, mask and map channels, stacks, layers, the
/// resolved material, the list of pixels to resolve, and the bits of the pixels that changed.
pub const SET: [BindingKind; 7] = [
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageBuffer,
];

/// What `resolve.comp` and the host agree on: the push constants. The stacks and layers are
/// images of their [`GpuStack`](crate::material::stack::GpuStack) and
/// [`GpuLayer`](crate::material::stack::GpuLayer) texels.
pub const INTERFACE: Interface = Interface::compute(&shaders::RESOLVE, &[&SET], Some(ResolvePush::GLSL));

/// Stacks per row of the `stacks` image, and layers per row of the `layers` image, as
/// `resolve.comp` finds them (powers of two: a mask and a shift).
const STACKS_PER_ROW: u32 = 1024;
const LAYERS_PER_ROW: u32 = 64;

/// `resolve.comp`'s push constants: the entries of the pixel list one dispatch resolves.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct ResolvePush {
    first: u32,
    end: u32,
}

crate::glsl_struct!(ResolvePush as "Pass", 8 bytes { first @ 0, end @ 4 });

/// The stacks on the GPU, held while the set points at them.
struct Stacks {
    _stacks: Image,
    _layers: Image,
    set: DescriptorSet,
    /// Entries of the pixel list to resolve.
    pixels: u32,
}

/// The resolve pipeline, the stacks it reads, and the change bits it writes.
pub struct ResolvePass {
    ctx: Context,
    pipeline: ComputePipeline,
    /// Whether `pipeline` has the map code ([`ResolvePass::pipeline`]).
    maps: bool,
    stacks: Option<Stacks>,
    /// The stacks whose resolve the resolved image holds, once a resolve of them has run: a
    /// later resolve skips the pixels of every stack unchanged since.
    resolved: Option<PackedStacks>,
    /// One bit per pixel (index y·width + x, 32 to a word), set by the last resolve where a
    /// covered pixel's material changed; made with the first stacks.
    changed: Option<Buffer>,
    /// The pixels to resolve, a list image; made with the first stacks.
    list: Option<Image>,
}

impl ResolvePass {
    /// The pass, with its pipeline compiled by [`ResolvePass::pipeline`] for `maps`.
    pub fn new(ctx: &Context, pipeline: ComputePipeline, maps: bool) -> ResolvePass {
        ResolvePass { ctx: ctx.clone(), pipeline, maps, stacks: None, resolved: None, changed: None, list: None }
    }

    /// Compiles `resolve.comp`, with the code that multiplies values by their maps when `maps`
    /// (stacks that bind none resolve the same without it, faster).
    pub fn pipeline(ctx: &Context, maps: bool) -> Result<ComputePipeline> {
        ComputePipeline::specialized(ctx, &shaders::RESOLVE, INTERFACE.sets, INTERFACE.push_size(), &[maps as u32])
    }

    /// Uploads `packed` (and the g-buffer channels it reads) and binds it for [`Self::record`],
    /// with the list of the covered pixels (of `lists`) whose stack differs from the one last
    /// resolved there: the covered list itself when every stack does. Until
    /// [`Self::mark_resolved`], none counts as resolved.
    pub fn set_stacks(
        &mut self,
        ctx: &Context,
        gbuffer: &mut GpuGBuffer,
        packed: &PackedStacks,
        targets: &Targets,
        lists: &PixelLists,
    ) -> Result<()> {
        let (width, height) = (targets.resolved.width, targets.resolved.height);
        let maps = packed.binds_maps();
        let respecialized = if maps != self.maps { Some(ResolvePass::pipeline(ctx, maps)?) } else { None };
        let changed_stacks = packed.changed_since(self.resolved.take().as_ref());
        let (stack_index, channels) = gbuffer.resolve_inputs(ctx, packed)?;
        let (list, pixels) =
            match pixels_to_resolve(&lists.covered.pixels, width, &stack_index.of_pixel, &changed_stacks) {
                None => (&lists.covered_image, lists.covered.pixels.len()),
                Some(pixels) => {
                    if self.list.is_none() {
                        self.list = Some(pixel_lists::list_image(ctx, width, height)?);
                    }
                    let list = self.list.as_ref().expect("just made");
                    pixel_lists::upload_list(ctx, list, &pixels)?;
                    (list, pixels.len())
                }
            };
        // Each GpuStack is one RGBA32_UINT texel, each GpuLayer LAYER_TEXELS.
        let rgba = vk::Format::R32G32B32A32_UINT;
        let stacks = Image::rows_of::<[u32; 4]>(ctx, rgba, STACKS_PER_ROW, bytemuck::cast_slice(&packed.stacks))?;
        let layers_per_row = LAYERS_PER_ROW * LAYER_TEXELS as u32;
        let layers = Image::rows_of::<[u32; 4]>(ctx, rgba, layers_per_row, bytemuck::cast_slice(&packed.layers))?;
        if self.changed.is_none() {
            self.changed = Some(Buffer::storage(ctx, (width as u64 * height as u64).div_ceil(32) * 4)?);
        }
        let changed = self.changed.as_ref().expect("just made");
        let set = respecialized.as_ref().unwrap_or(&self.pipeline).bind(
            0,
            &[
                Binding::Image(&stack_index.image),
                Binding::Image(channels),
                Binding::Image(&stacks),
                Binding::Image(&layers),
                Binding::Image(&targets.resolved),
                Binding::Image(list),
                Binding::Buffer(changed),
            ],
        )?;
        self.stacks = Some(Stacks { _stacks: stacks, _layers: layers, set, pixels: pixels as u32 });
        if let Some(pipeline) = respecialized {
            self.pipeline = pipeline;
            self.maps = maps;
        }
        Ok(())
    }

    /// Notes that the resolve of the stacks last set has run, so that the next
    /// [`Self::set_stacks`] flags only the stacks that differ from them.
    pub fn mark_resolved(&mut self, packed: &PackedStacks) {
        self.resolved = Some(packed.clone());
    }

    /// Whether stacks have been set.
    pub fn has_stacks(&self) -> bool {
        self.stacks.is_some()
    }

    /// Records the resolve of the listed pixels, after clearing the change bits.
    pub fn record(&self, cmd: vk::CommandBuffer) {
        let stacks = self.stacks.as_ref().expect("set_stacks() runs before the resolve");
        let changed = self.changed.as_ref().expect("made with the stacks");
        let device = &self.ctx.shared.device;
        unsafe { device.cmd_fill_buffer(cmd, changed.buffer, 0, vk::WHOLE_SIZE, 0) };
        crate::gpu::context::full_barrier(device, cmd);
        for (first, end, groups) in super::list_dispatches(0, stacks.pixels) {
            self.pipeline.dispatch(cmd, &[&stacks.set], bytemuck::bytes_of(&ResolvePush { first, end }), groups);
        }
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

/// The entries of `covered` (packed pixels of a `width`-wide image) whose stack, by
/// `stack_of_pixel` (indexed `y * width + x`), is marked in `changed_stacks`; None when every
/// stack is, and so every entry.
fn pixels_to_resolve(covered: &[u32], width: u32, stack_of_pixel: &[u32], changed_stacks: &[bool]) -> Option<Vec<u32>> {
    if changed_stacks.iter().all(|&c| c) {
        return None;
    }
    let index = |p: u32| ((p >> 16) * width + (p & 0xffff)) as usize;
    Some(covered.iter().copied().filter(|&p| changed_stacks[stack_of_pixel[index(p)] as usize]).collect())
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
    use super::{changed_indices, pixels_to_resolve};
    use crate::render::passes::pixel_lists::pack;

    #[test]
    fn change_bits_become_ascending_indices() {
        assert_eq!(changed_indices(&[], 0), Vec::<u32>::new());
        assert_eq!(changed_indices(&[0b1001, 0, 1 << 31], 96), vec![0, 3, 95]);
        assert_eq!(changed_indices(&[u32::MAX], 5), vec![0, 1, 2, 3, 4], "bits past the image are not pixels");
    }

    #[test]
    fn only_the_covered_pixels_of_changed_stacks_are_resolved() {
        // 3 × 2, stacks per pixel [0 1 1 / 2 0 1]; the covered pixels leave out (1, 0).
        let stack_of_pixel = [0, 1, 1, 2, 0, 1];
        let covered = [pack(0, 0), pack(2, 0), pack(0, 1), pack(1, 1), pack(2, 1)];
        let resolved = |changed: &[bool]| pixels_to_resolve(&covered, 3, &stack_of_pixel, changed);
        assert_eq!(resolved(&[false, true, false]), Some(vec![pack(2, 0), pack(2, 1)]));
        assert_eq!(resolved(&[true, false, true]), Some(vec![pack(0, 0), pack(0, 1), pack(1, 1)]));
        assert_eq!(resolved(&[false; 3]), Some(Vec::new()));
        assert_eq!(resolved(&[true; 3]), None, "every covered pixel: the covered list itself");
    }
}
