//! The g-buffer on the GPU: the surface image every pass reads, and the mask and map channels
//! the layer stacks choose from, uploaded as the stacks need them.

use super::{GBuffer, MAP_PREFIX, MASK_PREFIX};
use crate::gpu::{Context, Image};
use crate::material::stack::PackedStacks;
use crate::Result;
use ash::vk;
use std::collections::BTreeMap;

/// A g-buffer uploaded for rendering.
pub struct GpuGBuffer {
    pub width: u32,
    pub height: u32,
    /// Three layers: normal and coverage, view vector, tangent (`relight.comp`'s `surface`).
    pub surface: Image,
    /// Each pixel's object id (R32_UINT), for the preview's and the display filter's edges.
    pub object_ids: Image,
    /// The visibility words (RGBA32_UINT, `relight.comp`'s `visibility`: [`upload_visibility`]),
    /// and the grid's side; a 1×1 placeholder and side 0 without visibility.
    pub visibility: Image,
    pub visibility_side: u32,
    ids: Vec<u32>,
    /// The masks and maps by full channel name (`mask.stripes`, `map.baseColor.R`).
    channels: BTreeMap<String, Vec<f32>>,
    /// The channels the current stacks read, one layer each, with their names: kept while
    /// edits leave the list alone, so that changing a value uploads no channel again.
    channel_layers: Option<(Vec<String>, Image)>,
    /// The current stacks' index per pixel, kept while edits leave the objects' stacks where
    /// they are.
    stack_index: Option<StackIndex>,
}

/// Each pixel's stack, as resolve.comp reads it, and for which objects' stacks it was made.
pub struct StackIndex {
    stack_of_object: BTreeMap<u32, u32>,
    /// Per pixel (`y * width + x`): its index into the stacks.
    pub of_pixel: Vec<u32>,
    /// The same, R32_UINT.
    pub image: Image,
}

impl GpuGBuffer {
    pub fn upload(ctx: &Context, gbuffer: &GBuffer) -> Result<GpuGBuffer> {
        let (width, height) = (gbuffer.width, gbuffer.height);
        // Written straight into the staging memory, a band of rows at a time: no third copy.
        let surface = Image::new(ctx, vk::Format::R32G32B32A32_SFLOAT, width, height, 3, true)?;
        surface.upload_rows(ctx, |layer, first_row, bytes| {
            let out: &mut [[f32; 4]] = bytemuck::cast_slice_mut(bytes);
            let start = first_row as usize * width as usize;
            let pixels = start..start + out.len();
            match layer {
                0 => {
                    let normals = gbuffer.normal[pixels.clone()].iter().zip(&gbuffer.coverage[pixels]);
                    out.iter_mut().zip(normals).for_each(|(o, (n, a))| *o = [n[0], n[1], n[2], *a]);
                }
                1 => out.iter_mut().zip(&gbuffer.view[pixels]).for_each(|(o, v)| *o = [v[0], v[1], v[2], 0.0]),
                _ => out.iter_mut().zip(&gbuffer.tangent[pixels]).for_each(|(o, t)| *o = [t[0], t[1], t[2], 0.0]),
            }
        })?;
        let object_ids = Image::new(ctx, vk::Format::R32_UINT, width, height, 1, false)?;
        object_ids.upload(ctx, bytemuck::cast_slice(&gbuffer.object_id))?;
        let (visibility, visibility_side) = upload_visibility(ctx, gbuffer)?;
        let masks = gbuffer.masks.iter().map(|(name, values)| (format!("{MASK_PREFIX}{name}"), values.clone()));
        let maps = gbuffer.maps.iter().map(|(name, values)| (format!("{MAP_PREFIX}{name}"), values.clone()));
        Ok(GpuGBuffer {
            width,
            height,
            surface,
            object_ids,
            visibility,
            visibility_side,
            ids: gbuffer.object_id.clone(),
            channels: masks.chain(maps).collect(),
            channel_layers: None,
            stack_index: None,
        })
    }

    /// Each pixel's index into `packed`'s stacks, on the host and as an R32_UINT image; made
    /// again only when the objects map to other stacks.
    fn stack_index(&mut self, ctx: &Context, packed: &PackedStacks) -> Result<&StackIndex> {
        if self.stack_index.as_ref().is_none_or(|s| s.stack_of_object != packed.stack_of_object) {
            // Uncovered pixels may carry ids the stacks leave out; they shade nothing, so stack 0 does.
            let of_pixel: Vec<u32> =
                self.ids.iter().map(|id| packed.stack_of_object.get(id).copied().unwrap_or(0)).collect();
            let image = Image::new(ctx, vk::Format::R32_UINT, self.width, self.height, 1, false)?;
            image.upload(ctx, bytemuck::cast_slice(&of_pixel))?;
            self.stack_index = Some(StackIndex { stack_of_object: packed.stack_of_object.clone(), of_pixel, image });
        }
        Ok(self.stack_index.as_ref().expect("just made"))
    }

    /// The mask and map channels `packed` reads, one layer each in its order (at least one
    /// layer, so the binding is always valid); uploaded only when the list changes.
    fn channel_layers(&mut self, ctx: &Context, packed: &PackedStacks) -> Result<&Image> {
        if self.channel_layers.as_ref().is_none_or(|(names, _)| *names != packed.channels) {
            let layers = packed.channels.len().max(1) as u32;
            let blurred = self.blurred_masks(&packed.channels);
            let image = Image::new(ctx, vk::Format::R32_SFLOAT, self.width, self.height, layers, true)?;
            let width = self.width as usize;
            image.upload_rows(ctx, |layer, first_row, bytes| {
                let out: &mut [f32] = bytemuck::cast_slice_mut(bytes);
                match packed.channels.get(layer as usize) {
                    Some(name) => {
                        let values = self
                            .channels
                            .get(name)
                            .or_else(|| blurred.get(name))
                            .expect("pack() checked the masks and maps");
                        let start = first_row as usize * width;
                        out.copy_from_slice(&values[start..start + out.len()]);
                    }
                    None => out.fill(0.0),
                }
            })?;
            self.channel_layers = Some((packed.channels.clone(), image));
        }
        Ok(&self.channel_layers.as_ref().expect("just made").1)
    }

    /// The blurred masks among `channels` (`mask.stripes@blur2`), made from the g-buffer's.
    fn blurred_masks(&self, channels: &[String]) -> BTreeMap<String, Vec<f32>> {
        let blurred = channels.iter().filter_map(|name| {
            let key = name.strip_prefix(MASK_PREFIX)?;
            let (mask, sigma) = crate::material::mask::parse_blurred(key)?;
            let source = self.channels.get(&format!("{MASK_PREFIX}{mask}"))?;
            Some((name.clone(), super::blur::blur(source, self.width, self.height, sigma)))
        });
        blurred.filter(|(name, _)| !self.channels.contains_key(name)).collect()
    }

    /// What the resolve of `packed` reads: each pixel's stack ([`Self::stack_index`]) and the
    /// channels ([`Self::channel_layers`]).
    pub fn resolve_inputs(&mut self, ctx: &Context, packed: &PackedStacks) -> Result<(&StackIndex, &Image)> {
        self.channel_layers(ctx, packed)?;
        self.stack_index(ctx, packed)?;
        Ok((self.stack_index.as_ref().expect("just made"), &self.channel_layers.as_ref().expect("just made").1))
    }
}

/// Texels a row of the visibility image (`VISIBILITY_ROW` in relight.comp).
pub const VISIBILITY_ROW: u32 = 4096;

/// The rows the visibility image of `pixels` pixels on `grid` takes ([`upload_visibility`]).
pub fn visibility_rows(pixels: usize, grid: crate::visibility::Grid) -> u64 {
    (pixels as u64 * grid.words().div_ceil(4) as u64).div_ceil(VISIBILITY_ROW as u64)
}

/// The g-buffer's visibility as relight.comp reads it: every pixel's words in turn, row-major,
/// four a texel (a pixel's last texel padded with zeros), [`VISIBILITY_ROW`] texels a row, with
/// the grid's side; a 1×1 placeholder and side 0 without.
fn upload_visibility(ctx: &Context, gbuffer: &GBuffer) -> Result<(Image, u32)> {
    let Some(visibility) = &gbuffer.visibility else {
        return Ok((Image::new(ctx, vk::Format::R32G32B32A32_UINT, 1, 1, 1, false)?, 0));
    };
    let words = visibility.grid.words();
    let per_pixel = words.div_ceil(4);
    let rows = visibility_rows(gbuffer.pixel_count(), visibility.grid) as u32;
    let format = vk::Format::R32G32B32A32_UINT;
    let image = Image::filled_rows(ctx, format, VISIBILITY_ROW, rows, |first_row, out: &mut [[u32; 4]]| {
        let first = first_row as usize * VISIBILITY_ROW as usize;
        for (texel, out) in (first..).zip(out.iter_mut()) {
            let (pixel, k) = (texel / per_pixel, texel % per_pixel);
            let bits = visibility.words.get(pixel * words..(pixel + 1) * words).unwrap_or_default();
            let chunk = bits.get(4 * k..(4 * k + 4).min(bits.len())).unwrap_or_default();
            *out = [0; 4];
            out[..chunk.len()].copy_from_slice(chunk);
        }
    })?;
    Ok((image, visibility.grid.side()))
}
