//! The renderer's three GPU passes, each a small type that owns its pipeline, its descriptor
//! sets and its push constants:
//!
//! - [`resolve::ResolvePass`]: the layer stacks into one material per pixel, once per edit;
//! - [`relight::RelightPass`]: progressive MIS image-based lighting, accumulated per pixel,
//!   with what the AOVs need beside the total;
//! - [`finalize::FinalizePass`]: the mean, composited over the background, as linear radiance
//!   and as display pixels (or the viewer's preview, interpolated from one sample per block);
//! - [`denoise::DenoisePass`]: the viewer's optional display filter of that radiance;
//! - [`pixel_lists::PixelLists`]: the compacted lists of pixels the relight pass runs over.
//!
//! They share the images in [`Targets`] and the g-buffer's surface image
//! ([`crate::gbuffer::gpu::GpuGBuffer`]).

pub mod denoise;
pub mod finalize;
pub mod pixel_lists;
pub mod relight;
pub mod resolve;

use crate::gpu::pipeline::group_count;
use crate::gpu::{Context, Image};
use crate::Result;
use ash::vk;
use relight::{Accumulate, LOBES};

/// Workgroup size of the 2D kernels (`local_size_x`, `local_size_y` in glsl/*.comp).
const LOCAL_SIZE: [u32; 2] = [16, 16];

/// The workgroups covering `width` × `rows` pixels.
fn groups(width: u32, rows: u32) -> [u32; 3] {
    [group_count(width, LOCAL_SIZE[0]), group_count(rows, LOCAL_SIZE[1]), 1]
}

/// Invocations per workgroup of the kernels that run over a pixel list (`local_size_x` in
/// relight.comp and resolve.comp): a multiple of every subgroup size in use (8 on lavapipe, 32
/// or 64 on GPUs).
const LIST_LOCAL_SIZE: u32 = 64;

/// Workgroups per dispatch at most: the least `maxComputeWorkGroupCount[0]` Vulkan allows.
const MAX_GROUPS: u32 = 65_535;

/// The dispatches that run a list kernel over the entries `first..end`: each one's range and
/// workgroups, at most [`MAX_GROUPS`] of them.
fn list_dispatches(first: u32, end: u32) -> impl Iterator<Item = (u32, u32, [u32; 3])> {
    let step = MAX_GROUPS * LIST_LOCAL_SIZE;
    (first..end).step_by(step as usize).map(move |start| {
        let stop = end.min(start.saturating_add(step));
        (start, stop, [(stop - start).div_ceil(LIST_LOCAL_SIZE), 1, 1])
    })
}

/// The resolved material's layers: the five vec4s of `Params::to_gpu`.
pub const RESOLVED_LAYERS: u32 = (crate::material::params::GPU_FLOATS / 4) as u32;

/// The images the passes write and read, all the g-buffer's size (the AOV accumulations 1×1
/// when not asked for).
pub struct Targets {
    /// The material per pixel, [`RESOLVED_LAYERS`] layers: resolve writes it, relight reads it.
    pub resolved: Image,
    /// Running sums (rgb) and sample counts (a).
    pub accumulation: Image,
    /// The environment behind each pixel.
    pub background: Image,
    /// The lobe sums ([`LOBES`] layers), for the light AOVs.
    pub lobe_sums: Image,
    /// The sums of each estimate's squared luminance (r), for the variance AOV.
    pub moments: Image,
    /// Under a noise threshold, the two lists of pixels still sampling (relight.comp's
    /// `active_lists`); 1×1 without the squared luminances, which adaptive sampling needs.
    pub active_lists: Image,
    /// Each covered pixel's sum of estimates with nothing blocked, where some object catches
    /// shadows (a 1×1 placeholder where none does).
    pub unshadowed: Image,
    /// Linear radiance, finalize's output.
    pub radiance: Image,
    /// sRGB-encoded RGBA8 display pixels, finalize's output.
    pub display: Image,
}

impl Targets {
    pub fn new(ctx: &Context, width: u32, height: u32, accumulate: Accumulate) -> Result<Targets> {
        let float = |layers: u32| Image::new(ctx, vk::Format::R32G32B32A32_SFLOAT, width, height, layers, layers > 1);
        let (lobe_sums, moments, active_lists) = accumulation_images(ctx, width, height, accumulate)?;
        Ok(Targets {
            resolved: float(RESOLVED_LAYERS)?,
            accumulation: float(1)?,
            background: float(1)?,
            lobe_sums,
            moments,
            active_lists,
            unshadowed: Image::new(ctx, vk::Format::R32G32B32A32_SFLOAT, 1, 1, 1, false)?,
            radiance: float(1)?,
            display: Image::display(ctx, width, height)?,
        })
    }

    /// Makes the AOV accumulations `accumulate` needs.
    pub fn set_accumulate(&mut self, ctx: &Context, accumulate: Accumulate) -> Result<()> {
        let (width, height) = (self.accumulation.width, self.accumulation.height);
        (self.lobe_sums, self.moments, self.active_lists) = accumulation_images(ctx, width, height, accumulate)?;
        Ok(())
    }
}

impl Targets {
    /// Makes the unshadowed sums full size, for a shadow catcher, unless they are. Returns
    /// whether the image was replaced (the passes bound to it must bind the new one). They stay
    /// full size when no object catches shadows any more: the kernels then ignore them.
    pub fn make_unshadowed(&mut self, ctx: &Context) -> Result<bool> {
        let (width, height) = (self.accumulation.width, self.accumulation.height);
        if (self.unshadowed.width, self.unshadowed.height) == (width, height) {
            return Ok(false);
        }
        self.unshadowed = Image::new(ctx, vk::Format::R32G32B32A32_SFLOAT, width, height, 1, false)?;
        Ok(true)
    }
}

/// The lobe sums, the squared luminances and the active lists, each 1×1 when not asked for.
fn accumulation_images(
    ctx: &Context,
    width: u32,
    height: u32,
    accumulate: Accumulate,
) -> Result<(Image, Image, Image)> {
    let size = |on: bool| if on { (width, height) } else { (1, 1) };
    let (w, h) = size(accumulate.lobes);
    let lobes = Image::new(ctx, vk::Format::R32G32B32A32_SFLOAT, w, h, LOBES.len() as u32, true)?;
    let (w, h) = size(accumulate.variance);
    let moments = Image::new(ctx, vk::Format::R32G32B32A32_SFLOAT, w, h, 1, false)?;
    let active_lists = Image::new(ctx, vk::Format::R32_UINT, w, h, 2, true)?;
    Ok((lobes, moments, active_lists))
}
