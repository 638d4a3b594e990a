//! Buffers and images, each with its own dedicated allocation.
//!
//! lookdev makes a few dozen long-lived, mostly large resources, far below any driver's
//! allocation-count limit, so one allocation per resource is the simplest correct scheme.
//! Images live in the GENERAL layout for their whole life, whatever they are used for (compute
//! kernels, transfers, sampling, or as the bake's render targets), so no pass ever has to track
//! layouts.

use super::context::{Context, Shared};
use crate::{Error, Result};
use ash::vk;
use std::sync::Arc;

fn find_memory_type(shared: &Shared, type_bits: u32, wanted: vk::MemoryPropertyFlags) -> Option<u32> {
    let props = &shared.memory_properties;
    (0..props.memory_type_count)
        .find(|&i| type_bits & (1 << i) != 0 && props.memory_types[i as usize].property_flags.contains(wanted))
}

/// Allocates memory for one resource and counts it in [`Shared::memory`]; the resource gives it
/// back with [`free`].
fn allocate(shared: &Shared, requirements: vk::MemoryRequirements, host_visible: bool) -> Result<vk::DeviceMemory> {
    let preferred = if host_visible {
        vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT
    } else {
        vk::MemoryPropertyFlags::DEVICE_LOCAL
    };
    let type_index = find_memory_type(shared, requirements.memory_type_bits, preferred)
        .or_else(|| {
            (!host_visible)
                .then(|| find_memory_type(shared, requirements.memory_type_bits, vk::MemoryPropertyFlags::empty()))
                .flatten()
        })
        .ok_or_else(|| Error::gpu("no suitable Vulkan memory type"))?;
    let info = vk::MemoryAllocateInfo::default().allocation_size(requirements.size).memory_type_index(type_index);
    let memory = unsafe { shared.device.allocate_memory(&info, None) }
        .map_err(|e| Error::gpu(format!("cannot allocate {} MiB of GPU memory ({e})", requirements.size >> 20)))?;
    shared.memory.add(requirements.size);
    Ok(memory)
}

/// Frees what [`allocate`] gave, `size` bytes (a null handle, from a resource half made, is
/// nothing to free).
fn free(shared: &Shared, memory: vk::DeviceMemory, size: u64) {
    if memory != vk::DeviceMemory::null() {
        unsafe { shared.device.free_memory(memory, None) };
        shared.memory.remove(size);
    }
}

/// The device memory a context holds, now and at its most, for `LOOKDEV_TIMINGS=1` and the
/// memory benchmark.
#[derive(Debug, Default)]
pub struct MemoryUse {
    current: std::sync::atomic::AtomicU64,
    peak: std::sync::atomic::AtomicU64,
}

impl MemoryUse {
    fn add(&self, bytes: u64) {
        use std::sync::atomic::Ordering::Relaxed;
        let now = self.current.fetch_add(bytes, Relaxed) + bytes;
        self.peak.fetch_max(now, Relaxed);
    }

    fn remove(&self, bytes: u64) {
        self.current.fetch_sub(bytes, std::sync::atomic::Ordering::Relaxed);
    }

    /// The bytes allocated now.
    pub fn current(&self) -> u64 {
        self.current.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// The most bytes allocated at once so far.
    pub fn peak(&self) -> u64 {
        self.peak.load(std::sync::atomic::Ordering::Relaxed)
    }
}

/// A storage, staging or vertex buffer.
pub struct Buffer {
    shared: Arc<Shared>,
    pub buffer: vk::Buffer,
    memory: vk::DeviceMemory,
    /// The bytes `memory` holds, as allocated.
    allocated: u64,
    pub size: u64,
    mapped: Option<*mut u8>,
}

impl Buffer {
    /// A device-local storage buffer that transfers can fill and read.
    pub fn storage(ctx: &Context, size: u64) -> Result<Buffer> {
        Buffer::new(
            ctx,
            size,
            vk::BufferUsageFlags::STORAGE_BUFFER
                | vk::BufferUsageFlags::TRANSFER_DST
                | vk::BufferUsageFlags::TRANSFER_SRC,
            false,
        )
    }

    /// A host-visible, mapped buffer for uploads and read-backs.
    pub fn staging(ctx: &Context, size: u64) -> Result<Buffer> {
        Buffer::new(
            ctx,
            size,
            vk::BufferUsageFlags::TRANSFER_SRC
                | vk::BufferUsageFlags::TRANSFER_DST
                | vk::BufferUsageFlags::STORAGE_BUFFER,
            true,
        )
    }

    fn new(ctx: &Context, size: u64, usage: vk::BufferUsageFlags, host_visible: bool) -> Result<Buffer> {
        let size = size.max(16);
        let info = vk::BufferCreateInfo::default().size(size).usage(usage).sharing_mode(vk::SharingMode::EXCLUSIVE);
        let buffer = unsafe { ctx.shared.device.create_buffer(&info, None) }?;
        // From here on, Drop releases whatever has been created if a later step fails.
        let mut result = Buffer {
            shared: ctx.shared.clone(),
            buffer,
            memory: vk::DeviceMemory::null(),
            allocated: 0,
            size,
            mapped: None,
        };
        let device = &result.shared.device;
        let requirements = unsafe { device.get_buffer_memory_requirements(buffer) };
        result.memory = allocate(&result.shared, requirements, host_visible)?;
        result.allocated = requirements.size;
        unsafe { device.bind_buffer_memory(buffer, result.memory, 0) }?;
        if host_visible {
            let pointer = unsafe { device.map_memory(result.memory, 0, vk::WHOLE_SIZE, vk::MemoryMapFlags::empty()) }?;
            result.mapped = Some(pointer as *mut u8);
        }
        Ok(result)
    }

    /// The mapped bytes of a staging buffer.
    pub fn bytes(&self) -> &[u8] {
        let ptr = self.mapped.expect("only staging buffers are mapped");
        unsafe { std::slice::from_raw_parts(ptr, self.size as usize) }
    }

    pub fn bytes_mut(&mut self) -> &mut [u8] {
        let ptr = self.mapped.expect("only staging buffers are mapped");
        unsafe { std::slice::from_raw_parts_mut(ptr, self.size as usize) }
    }

    /// A device-local storage buffer holding `data`.
    pub fn with_data(ctx: &Context, data: &[u8]) -> Result<Buffer> {
        Buffer::storage(ctx, data.len() as u64)?.fill(ctx, data)
    }

    /// A device-local uniform buffer holding `data`.
    pub fn uniform(ctx: &Context, data: &[u8]) -> Result<Buffer> {
        let usage = vk::BufferUsageFlags::UNIFORM_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
        Buffer::new(ctx, data.len() as u64, usage, false)?.fill(ctx, data)
    }

    /// A device-local vertex buffer holding `data`.
    pub fn vertices(ctx: &Context, data: &[u8]) -> Result<Buffer> {
        let usage = vk::BufferUsageFlags::VERTEX_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
        Buffer::new(ctx, data.len() as u64, usage, false)?.fill(ctx, data)
    }

    /// Copies `data` into this device-local buffer through a staging buffer.
    fn fill(self, ctx: &Context, data: &[u8]) -> Result<Buffer> {
        let mut staging = Buffer::staging(ctx, data.len() as u64)?;
        staging.bytes_mut()[..data.len()].copy_from_slice(data);
        ctx.run(|cmd| {
            let region = vk::BufferCopy::default().size(data.len().max(1) as u64);
            unsafe { ctx.shared.device.cmd_copy_buffer(cmd, staging.buffer, self.buffer, &[region]) };
            Ok(())
        })?;
        Ok(self)
    }

    /// Copies the whole buffer back to the host.
    pub fn read(&self, ctx: &Context) -> Result<Vec<u8>> {
        let staging = Buffer::staging(ctx, self.size)?;
        ctx.run(|cmd| {
            let region = vk::BufferCopy::default().size(self.size);
            unsafe { ctx.shared.device.cmd_copy_buffer(cmd, self.buffer, staging.buffer, &[region]) };
            Ok(())
        })?;
        Ok(staging.bytes().to_vec())
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        unsafe {
            if self.mapped.is_some() {
                self.shared.device.unmap_memory(self.memory);
            }
            self.shared.device.destroy_buffer(self.buffer, None);
        }
        free(&self.shared, self.memory, self.allocated);
    }
}

/// What an image is for, which decides its usage flags.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Purpose {
    /// Read and written by kernels, filled and read back by transfers.
    Storage,
    /// Read by kernels, filled by a transfer as soon as it is made.
    Filled,
    /// RGBA8 display pixels that kernels write and the viewer samples as sRGB.
    Display,
    /// A colour target of the bake's render pass, read back by transfers.
    ColorTarget,
    /// The depth buffer of the bake's render pass.
    DepthTarget,
    /// A texture the bake's shaders sample, filled by a transfer.
    Texture,
}

impl Purpose {
    fn usage(self) -> vk::ImageUsageFlags {
        let transfer = vk::ImageUsageFlags::TRANSFER_SRC | vk::ImageUsageFlags::TRANSFER_DST;
        match self {
            Purpose::Storage | Purpose::Filled => vk::ImageUsageFlags::STORAGE | transfer,
            Purpose::Display => vk::ImageUsageFlags::STORAGE | vk::ImageUsageFlags::SAMPLED | transfer,
            Purpose::ColorTarget => vk::ImageUsageFlags::COLOR_ATTACHMENT | transfer,
            Purpose::DepthTarget => vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
            Purpose::Texture => vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST,
        }
    }

    /// Whether a new image is cleared: all but those filled at once and depth buffers (cleared
    /// by their render pass).
    fn cleared_on_creation(self) -> bool {
        matches!(self, Purpose::Storage | Purpose::Display | Purpose::ColorTarget)
    }

    fn aspect(self) -> vk::ImageAspectFlags {
        match self {
            Purpose::DepthTarget => vk::ImageAspectFlags::DEPTH,
            _ => vk::ImageAspectFlags::COLOR,
        }
    }
}

/// A 2D image (optionally an array), always in the GENERAL layout.
pub struct Image {
    shared: Arc<Shared>,
    pub image: vk::Image,
    pub view: vk::ImageView,
    /// For an 8-bit display image: a view that samples it as sRGB (decoding to linear).
    pub srgb_view: vk::ImageView,
    memory: vk::DeviceMemory,
    /// The bytes `memory` holds, as allocated.
    allocated: u64,
    pub format: vk::Format,
    pub width: u32,
    pub height: u32,
    pub layers: u32,
    /// Mip levels: 1 but for textures made with [`Image::texture`].
    levels: u32,
    aspect: vk::ImageAspectFlags,
}

/// The most staging memory one upload holds at once ([`Image::upload_rows`]).
pub const UPLOAD_CHUNK: u64 = 64 << 20;

/// Bytes per texel of the formats lookdev uses.
pub fn texel_size(format: vk::Format) -> u64 {
    match format {
        vk::Format::R32G32B32A32_SFLOAT | vk::Format::R32G32B32A32_UINT => 16,
        vk::Format::R32G32_SFLOAT | vk::Format::R32G32_UINT | vk::Format::R16G16B16A16_SFLOAT => 8,
        vk::Format::R32_SFLOAT
        | vk::Format::R32_UINT
        | vk::Format::R8G8B8A8_UNORM
        | vk::Format::R8G8B8A8_SRGB
        | vk::Format::D32_SFLOAT => 4,
        other => panic!("texel_size: format {other:?} is not used by lookdev"),
    }
}

impl Image {
    /// A storage image of `layers` layers (a 2D array view when `layers` > 1 or `array` is set).
    pub fn new(ctx: &Context, format: vk::Format, width: u32, height: u32, layers: u32, array: bool) -> Result<Image> {
        Image::create(ctx, format, width, height, layers, array, Purpose::Storage, 1)
    }

    /// A storage image of one layer whose texels `fill` writes, row-major, straight into the
    /// memory the transfer copies from: no other copy of them is made on the host.
    /// A one-layer image whose texels `fill(first_row, texels)` writes a band of rows at a time
    /// ([`Image::upload_rows`]).
    pub fn filled_rows<T: bytemuck::Pod>(
        ctx: &Context,
        format: vk::Format,
        width: u32,
        height: u32,
        mut fill: impl FnMut(u32, &mut [T]),
    ) -> Result<Image> {
        let image = Image::create(ctx, format, width, height, 1, false, Purpose::Filled, 1)?;
        image.upload_rows(ctx, |_, first_row, bytes| fill(first_row, bytemuck::cast_slice_mut(bytes)))?;
        Ok(image)
    }

    pub fn filled<T: bytemuck::Pod>(
        ctx: &Context,
        format: vk::Format,
        width: u32,
        height: u32,
        fill: impl FnOnce(&mut [T]),
    ) -> Result<Image> {
        let image = Image::create(ctx, format, width, height, 1, false, Purpose::Filled, 1)?;
        image.upload_with(ctx, |bytes| fill(bytemuck::cast_slice_mut(bytes)))?;
        Ok(image)
    }

    /// An image `per_row` texels wide holding `texels` row by row, the last row padded with
    /// zeros: a table a kernel indexes with a mask and a shift (`per_row` a power of two, or a
    /// multiple of a record's texels).
    pub fn rows_of<T: bytemuck::Pod>(ctx: &Context, format: vk::Format, per_row: u32, texels: &[T]) -> Result<Image> {
        let rows = (texels.len() as u32).div_ceil(per_row).max(1);
        Image::filled(ctx, format, per_row, rows, |out: &mut [T]| {
            out.fill(T::zeroed());
            out[..texels.len()].copy_from_slice(texels);
        })
    }

    /// An RGBA8 storage image holding sRGB-encoded display pixels, which can also be sampled
    /// through [`Image::srgb_view`] (the viewer shows it that way).
    pub fn display(ctx: &Context, width: u32, height: u32) -> Result<Image> {
        Image::create(ctx, vk::Format::R8G8B8A8_UNORM, width, height, 1, false, Purpose::Display, 1)
    }

    /// A colour render target whose pixels transfers can read back.
    pub fn color_target(ctx: &Context, format: vk::Format, width: u32, height: u32) -> Result<Image> {
        Image::create(ctx, format, width, height, 1, false, Purpose::ColorTarget, 1)
    }

    /// A 32-bit float depth buffer.
    pub fn depth_target(ctx: &Context, width: u32, height: u32) -> Result<Image> {
        Image::create(ctx, vk::Format::D32_SFLOAT, width, height, 1, false, Purpose::DepthTarget, 1)
    }

    /// A sampled RGBA8 texture holding `levels`, its mip chain from the full size down, each
    /// level tightly packed. An sRGB texture is decoded to linear by the sampler, before
    /// filtering; any other is sampled as stored.
    pub fn texture(ctx: &Context, levels: &[image::RgbaImage], srgb: bool) -> Result<Image> {
        let format = if srgb { vk::Format::R8G8B8A8_SRGB } else { vk::Format::R8G8B8A8_UNORM };
        let (width, height) = levels[0].dimensions();
        let image = Image::create(ctx, format, width, height, 1, false, Purpose::Texture, levels.len() as u32)?;
        let total: usize = levels.iter().map(|l| l.as_raw().len()).sum();
        let mut staging = Buffer::staging(ctx, total as u64)?;
        let mut regions = Vec::with_capacity(levels.len());
        let mut offset = 0usize;
        for (level, pixels) in levels.iter().enumerate() {
            let bytes = pixels.as_raw();
            staging.bytes_mut()[offset..offset + bytes.len()].copy_from_slice(bytes);
            regions.push(
                vk::BufferImageCopy::default()
                    .buffer_offset(offset as u64)
                    .image_subresource(
                        vk::ImageSubresourceLayers::default()
                            .aspect_mask(vk::ImageAspectFlags::COLOR)
                            .mip_level(level as u32)
                            .layer_count(1),
                    )
                    .image_extent(vk::Extent3D { width: pixels.width(), height: pixels.height(), depth: 1 }),
            );
            offset += bytes.len();
        }
        image.copy_from(ctx, &staging, &regions)?;
        Ok(image)
    }

    /// An image of `levels` mip levels (1 for all but textures).
    #[allow(clippy::too_many_arguments)]
    fn create(
        ctx: &Context,
        format: vk::Format,
        width: u32,
        height: u32,
        layers: u32,
        array: bool,
        purpose: Purpose,
        levels: u32,
    ) -> Result<Image> {
        let sampled_as_srgb = purpose == Purpose::Display;
        let max = ctx.info().max_image_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(Error::gpu(format!(
                "a {width}x{height} image is outside what this device supports (1 to {max} pixels a side)"
            )));
        }
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(format)
            .extent(vk::Extent3D { width, height, depth: 1 })
            .mip_levels(levels)
            .array_layers(layers)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(purpose.usage())
            .flags(if sampled_as_srgb { vk::ImageCreateFlags::MUTABLE_FORMAT } else { vk::ImageCreateFlags::empty() })
            .sharing_mode(vk::SharingMode::EXCLUSIVE)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        let image = unsafe { ctx.shared.device.create_image(&info, None) }?;
        // From here on, Drop releases whatever has been created if a later step fails.
        let mut result = Image {
            shared: ctx.shared.clone(),
            image,
            view: vk::ImageView::null(),
            srgb_view: vk::ImageView::null(),
            memory: vk::DeviceMemory::null(),
            allocated: 0,
            format,
            width,
            height,
            layers,
            levels,
            aspect: purpose.aspect(),
        };
        let device = &result.shared.device;
        let requirements = unsafe { device.get_image_memory_requirements(image) };
        result.memory = allocate(&result.shared, requirements, false)?;
        result.allocated = requirements.size;
        unsafe { device.bind_image_memory(image, result.memory, 0) }?;
        let view_type = if array || layers > 1 { vk::ImageViewType::TYPE_2D_ARRAY } else { vk::ImageViewType::TYPE_2D };
        let view_info = vk::ImageViewCreateInfo::default()
            .image(image)
            .view_type(view_type)
            .format(format)
            .subresource_range(result.range());
        result.view = unsafe { device.create_image_view(&view_info, None) }?;
        if sampled_as_srgb {
            // sRGB formats cannot be storage images: this view is for sampling only.
            let mut sampled_only = vk::ImageViewUsageCreateInfo::default().usage(vk::ImageUsageFlags::SAMPLED);
            let srgb_info = view_info.format(vk::Format::R8G8B8A8_SRGB).push_next(&mut sampled_only);
            result.srgb_view = unsafe { device.create_image_view(&srgb_info, None) }?;
        }
        ctx.run(|cmd| {
            result.transition_to_general(cmd);
            // New memory holds whatever was there before (on a CPU driver, often an image just
            // freed): an image that kernels write or the viewer shows starts as zeros, so no
            // read and no frame ever sees that. Textures are filled right after.
            if purpose.cleared_on_creation() {
                result.record_clear(cmd);
            }
            Ok(())
        })?;
        Ok(result)
    }

    fn range(&self) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange::default().aspect_mask(self.aspect).level_count(self.levels).layer_count(self.layers)
    }

    fn transition_to_general(&self, cmd: vk::CommandBuffer) {
        let barrier = vk::ImageMemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::empty())
            .dst_access_mask(vk::AccessFlags::MEMORY_READ | vk::AccessFlags::MEMORY_WRITE)
            .old_layout(vk::ImageLayout::UNDEFINED)
            .new_layout(vk::ImageLayout::GENERAL)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(self.image)
            .subresource_range(self.range());
        unsafe {
            self.shared.device.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::TOP_OF_PIPE,
                vk::PipelineStageFlags::ALL_COMMANDS,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &[barrier],
            );
        }
    }

    /// Records filling every layer with zeros.
    pub fn record_clear(&self, cmd: vk::CommandBuffer) {
        unsafe {
            self.shared.device.cmd_clear_color_image(
                cmd,
                self.image,
                vk::ImageLayout::GENERAL,
                &vk::ClearColorValue::default(),
                &[self.range()],
            )
        };
    }

    pub fn byte_size(&self) -> u64 {
        self.width as u64 * self.height as u64 * self.layers as u64 * texel_size(self.format)
    }

    fn copy_region(&self) -> vk::BufferImageCopy {
        vk::BufferImageCopy::default()
            .image_subresource(vk::ImageSubresourceLayers::default().aspect_mask(self.aspect).layer_count(self.layers))
            .image_extent(vk::Extent3D { width: self.width, height: self.height, depth: 1 })
    }

    /// Fills every layer from tightly packed texels, layer after layer, rows top to bottom.
    pub fn upload(&self, ctx: &Context, data: &[u8]) -> Result<()> {
        assert_eq!(data.len() as u64, self.byte_size(), "upload size must match the image");
        let row_bytes = (self.width as u64 * texel_size(self.format)) as usize;
        let layer_bytes = row_bytes * self.height as usize;
        self.upload_rows(ctx, |layer, first_row, bytes| {
            let start = layer as usize * layer_bytes + first_row as usize * row_bytes;
            bytes.copy_from_slice(&data[start..start + bytes.len()]);
        })
    }

    /// Fills the image a band of rows at a time through one staging buffer of at most
    /// [`UPLOAD_CHUNK`] bytes (a row at the least), so that a large image never has a whole
    /// second copy in staging memory: `fill(layer, first_row, bytes)` writes that layer's rows
    /// from `first_row` on, as many as `bytes` holds, tightly packed.
    pub fn upload_rows(&self, ctx: &Context, fill: impl FnMut(u32, u32, &mut [u8])) -> Result<()> {
        self.upload_rows_within(ctx, UPLOAD_CHUNK, fill)
    }

    /// [`Image::upload_rows`] through at most `chunk` bytes of staging (a row at the least).
    pub fn upload_rows_within(
        &self,
        ctx: &Context,
        chunk: u64,
        mut fill: impl FnMut(u32, u32, &mut [u8]),
    ) -> Result<()> {
        let row_bytes = self.width as u64 * texel_size(self.format);
        let band = (chunk / row_bytes).clamp(1, self.height as u64) as u32;
        let mut staging = Buffer::staging(ctx, band as u64 * row_bytes)?;
        for layer in 0..self.layers {
            for first_row in (0..self.height).step_by(band as usize) {
                let rows = band.min(self.height - first_row);
                fill(layer, first_row, &mut staging.bytes_mut()[..(rows as u64 * row_bytes) as usize]);
                let region = vk::BufferImageCopy::default()
                    .image_subresource(
                        vk::ImageSubresourceLayers::default()
                            .aspect_mask(self.aspect)
                            .base_array_layer(layer)
                            .layer_count(1),
                    )
                    .image_offset(vk::Offset3D { x: 0, y: first_row as i32, z: 0 })
                    .image_extent(vk::Extent3D { width: self.width, height: rows, depth: 1 });
                self.copy_from(ctx, &staging, &[region])?;
            }
        }
        Ok(())
    }

    /// Fills every layer with the texels `fill` writes into the staging memory, laid out as
    /// for [`Image::upload`].
    pub fn upload_with(&self, ctx: &Context, fill: impl FnOnce(&mut [u8])) -> Result<()> {
        let mut staging = Buffer::staging(ctx, self.byte_size())?;
        fill(&mut staging.bytes_mut()[..self.byte_size() as usize]);
        self.copy_from(ctx, &staging, &[self.copy_region()])
    }

    /// Copies `regions` of `staging` into the image, in one submission.
    fn copy_from(&self, ctx: &Context, staging: &Buffer, regions: &[vk::BufferImageCopy]) -> Result<()> {
        ctx.run(|cmd| {
            unsafe {
                ctx.shared.device.cmd_copy_buffer_to_image(
                    cmd,
                    staging.buffer,
                    self.image,
                    vk::ImageLayout::GENERAL,
                    regions,
                )
            };
            Ok(())
        })
    }

    /// Records a copy of the whole image into `staging` (which must be large enough).
    pub fn record_read(&self, cmd: vk::CommandBuffer, staging: &Buffer) {
        self.record_read_at(cmd, staging, 0);
    }

    /// Records a copy of the whole image into `staging` from byte `offset` on.
    pub fn record_read_at(&self, cmd: vk::CommandBuffer, staging: &Buffer, offset: u64) {
        let region = self.copy_region().buffer_offset(offset);
        unsafe {
            self.shared.device.cmd_copy_image_to_buffer(
                cmd,
                self.image,
                vk::ImageLayout::GENERAL,
                staging.buffer,
                &[region],
            )
        };
    }

    /// Records a copy of one texel of layer 0 into the start of `staging`.
    pub fn record_read_texel(&self, cmd: vk::CommandBuffer, staging: &Buffer, x: u32, y: u32) {
        let region = vk::BufferImageCopy::default()
            .image_subresource(
                vk::ImageSubresourceLayers::default().aspect_mask(vk::ImageAspectFlags::COLOR).layer_count(1),
            )
            .image_offset(vk::Offset3D { x: x as i32, y: y as i32, z: 0 })
            .image_extent(vk::Extent3D { width: 1, height: 1, depth: 1 });
        unsafe {
            self.shared.device.cmd_copy_image_to_buffer(
                cmd,
                self.image,
                vk::ImageLayout::GENERAL,
                staging.buffer,
                &[region],
            )
        };
    }

    /// Copies every layer back to the host, tightly packed.
    pub fn read(&self, ctx: &Context) -> Result<Vec<u8>> {
        let staging = Buffer::staging(ctx, self.byte_size())?;
        ctx.run(|cmd| {
            self.record_read(cmd, &staging);
            Ok(())
        })?;
        Ok(staging.bytes()[..self.byte_size() as usize].to_vec())
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        unsafe {
            self.shared.device.destroy_image_view(self.srgb_view, None);
            self.shared.device.destroy_image_view(self.view, None);
            self.shared.device.destroy_image(self.image, None);
        }
        free(&self.shared, self.memory, self.allocated);
    }
}
