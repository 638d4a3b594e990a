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
    ids: Vec<u32>,
    /// The masks and maps by full channel name (`mask.stripes`, `map.baseColor.R`).
    channels: BTreeMap<String, Vec<f32>>,
    /// The channels the current stacks read, one layer each, with their names: kept while
    /// edits leave the list alone, so that changing a value uploads no channel again.
    channel_layers: Option<(Vec<String>, Image)>,
}

impl GpuGBuffer {
    pub fn upload(ctx: &Context, gbuffer: &GBuffer) -> Result<GpuGBuffer> {
        let (width, height) = (gbuffer.width, gbuffer.height);
        let mut surface_data = Vec::with_capacity(3 * gbuffer.pixel_count());
        surface_data.extend(gbuffer.normal.iter().zip(&gbuffer.coverage).map(|(n, a)| [n[0], n[1], n[2], *a]));
        surface_data.extend(gbuffer.view.iter().map(|v| [v[0], v[1], v[2], 0.0]));
        surface_data.extend(gbuffer.tangent.iter().map(|t| [t[0], t[1], t[2], 0.0]));
        let surface = Image::new(ctx, vk::Format::R32G32B32A32_SFLOAT, width, height, 3, true)?;
        surface.upload(ctx, bytemuck::cast_slice(&surface_data))?;
        let object_ids = Image::new(ctx, vk::Format::R32_UINT, width, height, 1, false)?;
        object_ids.upload(ctx, bytemuck::cast_slice(&gbuffer.object_id))?;
        let masks = gbuffer.masks.iter().map(|(name, values)| (format!("{MASK_PREFIX}{name}"), values.clone()));
        let maps = gbuffer.maps.iter().map(|(name, values)| (format!("{MAP_PREFIX}{name}"), values.clone()));
        Ok(GpuGBuffer {
            width,
            height,
            surface,
            object_ids,
            ids: gbuffer.object_id.clone(),
            channels: masks.chain(maps).collect(),
            channel_layers: None,
        })
    }

    /// Each pixel's index into `packed`'s stacks, as an R32_UINT image.
    pub fn stack_index(&self, ctx: &Context, packed: &PackedStacks) -> Result<Image> {
        // Uncovered pixels may carry ids the stacks leave out; they shade nothing, so stack 0 does.
        let index: Vec<u32> = self.ids.iter().map(|id| packed.stack_of_object.get(id).copied().unwrap_or(0)).collect();
        let image = Image::new(ctx, vk::Format::R32_UINT, self.width, self.height, 1, false)?;
        image.upload(ctx, bytemuck::cast_slice(&index))?;
        Ok(image)
    }

    /// The mask and map channels `packed` reads, one layer each in its order (at least one
    /// layer, so the binding is always valid); uploaded only when the list changes.
    pub fn channel_layers(&mut self, ctx: &Context, packed: &PackedStacks) -> Result<&Image> {
        if self.channel_layers.as_ref().is_none_or(|(names, _)| *names != packed.channels) {
            let pixels = self.ids.len();
            let layers = packed.channels.len().max(1) as u32;
            let mut data = vec![0.0f32; pixels * layers as usize];
            for (i, name) in packed.channels.iter().enumerate() {
                let values = self.channels.get(name).expect("pack() checked the masks and maps");
                data[i * pixels..(i + 1) * pixels].copy_from_slice(values);
            }
            let image = Image::new(ctx, vk::Format::R32_SFLOAT, self.width, self.height, layers, true)?;
            image.upload(ctx, bytemuck::cast_slice(&data))?;
            self.channel_layers = Some((packed.channels.clone(), image));
        }
        Ok(&self.channel_layers.as_ref().expect("just made").1)
    }

    /// [`Self::channel_layers`] with the surface image beside it, for a pass that binds both.
    pub fn surface_and_channel_layers(&mut self, ctx: &Context, packed: &PackedStacks) -> Result<(&Image, &Image)> {
        self.channel_layers(ctx, packed)?;
        Ok((&self.surface, &self.channel_layers.as_ref().expect("just made").1))
    }
}
