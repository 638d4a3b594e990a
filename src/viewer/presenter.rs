//! Presenting frames to the window: the swapchain, one frame in flight, and capturing the
//! window's contents for screenshots.

use crate::gpu::context::{full_barrier, host_barrier};
use crate::gpu::inject::{self, Step};
use crate::gpu::{Buffer, Context, Surface};
use crate::{Error, Result};
use ash::vk;

/// The swapchain and what a frame needs to reach the screen. Every handle is null until made, and
/// Drop destroys the ones made, so a presenter that fails part-way through `new` drops cleanly.
pub struct Presenter {
    ctx: Context,
    swapchain_loader: ash::khr::swapchain::Device,
    /// Dropped after [`Presenter::drop`] has destroyed the swapchain made on it.
    surface: Surface,
    swapchain: vk::SwapchainKHR,
    images: Vec<vk::Image>,
    views: Vec<vk::ImageView>,
    pub format: vk::Format,
    pub extent: vk::Extent2D,
    /// Whether swapchain images can be copied out (for screenshots).
    capturable: bool,
    pool: vk::CommandPool,
    command_buffer: vk::CommandBuffer,
    image_available: vk::Semaphore,
    /// One per swapchain image: presenting waits on the one of the image it shows.
    render_finished: Vec<vk::Semaphore>,
    in_flight: vk::Fence,
    /// The window changed size (or the swapchain went stale): rebuild before the next frame.
    stale: bool,
}

/// sRGB formats first: egui then outputs linear colour and the hardware encodes it.
const PREFERRED_FORMATS: [vk::Format; 2] = [vk::Format::B8G8R8A8_SRGB, vk::Format::R8G8B8A8_SRGB];

impl Presenter {
    /// Presents on `surface`, which must belong to `ctx`'s instance.
    pub fn new(ctx: &Context, surface: Surface, width: u32, height: u32) -> Result<Presenter> {
        let device = &ctx.shared.device;
        // From here on, Drop releases whatever has been created if a later step fails.
        let mut presenter = Presenter {
            ctx: ctx.clone(),
            swapchain_loader: ash::khr::swapchain::Device::new(&ctx.shared.instance, device),
            surface,
            swapchain: vk::SwapchainKHR::null(),
            images: Vec::new(),
            views: Vec::new(),
            format: vk::Format::UNDEFINED,
            extent: vk::Extent2D { width, height },
            capturable: false,
            pool: vk::CommandPool::null(),
            command_buffer: vk::CommandBuffer::null(),
            image_available: vk::Semaphore::null(),
            render_finished: Vec::new(),
            in_flight: vk::Fence::null(),
            stale: true,
        };
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(ctx.shared.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        presenter.pool = unsafe { device.create_command_pool(&pool_info, None) }?;
        let alloc = vk::CommandBufferAllocateInfo::default().command_pool(presenter.pool).command_buffer_count(1);
        // Freed with the pool.
        presenter.command_buffer = unsafe { device.allocate_command_buffers(&alloc) }?[0];
        presenter.image_available = unsafe { device.create_semaphore(&vk::SemaphoreCreateInfo::default(), None) }?;
        inject::check(Step::PresenterFence)?;
        presenter.in_flight = unsafe {
            device.create_fence(&vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED), None)
        }?;
        presenter.rebuild(width, height)?;
        Ok(presenter)
    }

    /// The command pool frames record from, also lent to egui's texture uploads.
    pub fn pool(&self) -> vk::CommandPool {
        self.pool
    }

    /// Whether the window's images can be copied out, for screenshots.
    pub fn capturable(&self) -> bool {
        self.capturable
    }

    /// Marks the swapchain for rebuilding at `width`×`height` before the next frame.
    pub fn resize(&mut self, width: u32, height: u32) {
        self.extent = vk::Extent2D { width, height };
        self.stale = true;
    }

    fn rebuild(&mut self, width: u32, height: u32) -> Result<()> {
        let device = self.ctx.shared.device.clone();
        unsafe { device.device_wait_idle() }?;
        let pd = self.ctx.shared.physical_device;
        let surface = &self.surface;
        let caps = unsafe { surface.loader.get_physical_device_surface_capabilities(pd, surface.handle) }?;
        let formats = unsafe { surface.loader.get_physical_device_surface_formats(pd, surface.handle) }?;
        let format = PREFERRED_FORMATS
            .iter()
            .find_map(|wanted| formats.iter().find(|f| f.format == *wanted))
            .or(formats.first())
            .copied()
            .ok_or_else(|| Error::gpu("the window's surface offers no formats"))?;
        let extent = if caps.current_extent.width != u32::MAX {
            caps.current_extent
        } else {
            vk::Extent2D {
                width: width.clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: height.clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        };
        if extent.width == 0 || extent.height == 0 {
            // A minimised window: nothing to draw into until it comes back.
            self.extent = extent;
            return Ok(());
        }
        self.capturable = caps.supported_usage_flags.contains(vk::ImageUsageFlags::TRANSFER_SRC);
        let usage = if self.capturable {
            vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC
        } else {
            vk::ImageUsageFlags::COLOR_ATTACHMENT
        };
        let count =
            (caps.min_image_count + 1).min(if caps.max_image_count > 0 { caps.max_image_count } else { u32::MAX });
        let old = self.swapchain;
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(surface.handle)
            .min_image_count(count)
            .image_format(format.format)
            .image_color_space(format.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(usage)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(vk::CompositeAlphaFlagsKHR::OPAQUE)
            .present_mode(vk::PresentModeKHR::FIFO)
            .clipped(true)
            .old_swapchain(old);
        let swapchain = unsafe { self.swapchain_loader.create_swapchain(&info, None) }?;
        self.destroy_swapchain_parts();
        if old != vk::SwapchainKHR::null() {
            unsafe { self.swapchain_loader.destroy_swapchain(old, None) };
        }
        self.swapchain = swapchain;
        self.images = unsafe { self.swapchain_loader.get_swapchain_images(swapchain) }?;
        for &image in &self.images {
            let view_info = vk::ImageViewCreateInfo::default()
                .image(image)
                .view_type(vk::ImageViewType::TYPE_2D)
                .format(format.format)
                .subresource_range(color_range());
            if self.views.is_empty() {
                inject::check(Step::SwapchainView)?;
            }
            self.views.push(unsafe { device.create_image_view(&view_info, None) }?);
            self.render_finished.push(unsafe { device.create_semaphore(&vk::SemaphoreCreateInfo::default(), None) }?);
        }
        self.format = format.format;
        self.extent = extent;
        self.stale = false;
        Ok(())
    }

    fn destroy_swapchain_parts(&mut self) {
        let device = &self.ctx.shared.device;
        unsafe {
            for view in self.views.drain(..) {
                device.destroy_image_view(view, None);
            }
            for semaphore in self.render_finished.drain(..) {
                device.destroy_semaphore(semaphore, None);
            }
        }
        self.images.clear();
    }

    /// Draws one frame: `record` renders into the swapchain image's view (already in the colour
    /// attachment layout, after a barrier that makes earlier compute results visible). With
    /// `capture`, the frame is also copied back and returned as RGBA8 pixels. Returns None for
    /// the image when the window is minimised or the swapchain had to be rebuilt.
    pub fn frame(
        &mut self,
        capture: bool,
        record: impl FnOnce(vk::CommandBuffer, vk::ImageView, vk::Extent2D) -> Result<()>,
    ) -> Result<Option<image::RgbaImage>> {
        if self.stale {
            self.rebuild(self.extent.width, self.extent.height)?;
        }
        if self.extent.width == 0 || self.extent.height == 0 {
            return Ok(None);
        }
        let device = self.ctx.shared.device.clone();
        unsafe { device.wait_for_fences(&[self.in_flight], true, u64::MAX) }?;
        let acquired = unsafe {
            self.swapchain_loader.acquire_next_image(self.swapchain, u64::MAX, self.image_available, vk::Fence::null())
        };
        let index = match acquired {
            Ok((index, _suboptimal)) => index,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => {
                self.stale = true;
                return Ok(None);
            }
            Err(e) => return Err(e.into()),
        };
        unsafe { device.reset_fences(&[self.in_flight]) }?;
        let (image, view, extent) = (self.images[index as usize], self.views[index as usize], self.extent);
        let capture = capture && self.capturable;
        let readback = if capture {
            Some(Buffer::staging(&self.ctx, extent.width as u64 * extent.height as u64 * 4)?)
        } else {
            None
        };
        let cmd = self.command_buffer;
        unsafe {
            device.reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty())?;
            device.begin_command_buffer(
                cmd,
                &vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
            )?;
            full_barrier(&device, cmd);
            transition(&device, cmd, image, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
        }
        record(cmd, view, extent)?;
        unsafe {
            match &readback {
                Some(buffer) => {
                    transition(
                        &device,
                        cmd,
                        image,
                        vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    );
                    let region = vk::BufferImageCopy::default()
                        .image_subresource(
                            vk::ImageSubresourceLayers::default()
                                .aspect_mask(vk::ImageAspectFlags::COLOR)
                                .layer_count(1),
                        )
                        .image_extent(vk::Extent3D { width: extent.width, height: extent.height, depth: 1 });
                    device.cmd_copy_image_to_buffer(
                        cmd,
                        image,
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                        buffer.buffer,
                        &[region],
                    );
                    full_barrier(&device, cmd);
                    transition(
                        &device,
                        cmd,
                        image,
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                        vk::ImageLayout::PRESENT_SRC_KHR,
                    );
                }
                None => transition(
                    &device,
                    cmd,
                    image,
                    vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                    vk::ImageLayout::PRESENT_SRC_KHR,
                ),
            }
            host_barrier(&device, cmd);
            device.end_command_buffer(cmd)?;
        }
        let waits = [self.image_available];
        let stages = [vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT | vk::PipelineStageFlags::TRANSFER];
        let signals = [self.render_finished[index as usize]];
        let cmds = [cmd];
        let submit = vk::SubmitInfo::default()
            .wait_semaphores(&waits)
            .wait_dst_stage_mask(&stages)
            .command_buffers(&cmds)
            .signal_semaphores(&signals);
        let presented = {
            let _queue = self.ctx.lock_queue();
            unsafe { device.queue_submit(self.ctx.shared.queue, &[submit], self.in_flight) }?;
            let swapchains = [self.swapchain];
            let indices = [index];
            let present =
                vk::PresentInfoKHR::default().wait_semaphores(&signals).swapchains(&swapchains).image_indices(&indices);
            unsafe { self.swapchain_loader.queue_present(self.ctx.shared.queue, &present) }
        };
        match presented {
            Ok(false) => {}
            Ok(true) | Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => self.stale = true,
            Err(e) => return Err(e.into()),
        }
        let Some(buffer) = readback else {
            return Ok(None);
        };
        unsafe { device.wait_for_fences(&[self.in_flight], true, u64::MAX) }?;
        let mut pixels = buffer.bytes()[..(extent.width * extent.height * 4) as usize].to_vec();
        if matches!(self.format, vk::Format::B8G8R8A8_SRGB | vk::Format::B8G8R8A8_UNORM) {
            pixels.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
        }
        pixels.chunks_exact_mut(4).for_each(|p| p[3] = 255);
        Ok(image::RgbaImage::from_raw(extent.width, extent.height, pixels))
    }
}

fn color_range() -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange::default().aspect_mask(vk::ImageAspectFlags::COLOR).level_count(1).layer_count(1)
}

fn transition(
    device: &ash::Device,
    cmd: vk::CommandBuffer,
    image: vk::Image,
    from: vk::ImageLayout,
    to: vk::ImageLayout,
) {
    let barrier = vk::ImageMemoryBarrier::default()
        .src_access_mask(vk::AccessFlags::MEMORY_WRITE)
        .dst_access_mask(vk::AccessFlags::MEMORY_READ | vk::AccessFlags::MEMORY_WRITE)
        .old_layout(from)
        .new_layout(to)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image)
        .subresource_range(color_range());
    unsafe {
        device.cmd_pipeline_barrier(
            cmd,
            vk::PipelineStageFlags::ALL_COMMANDS,
            vk::PipelineStageFlags::ALL_COMMANDS,
            vk::DependencyFlags::empty(),
            &[],
            &[],
            &[barrier],
        )
    };
}

impl Drop for Presenter {
    fn drop(&mut self) {
        // Destroying a null handle does nothing; the surface drops after this, with the fields.
        let device = self.ctx.shared.device.clone();
        unsafe {
            let _ = device.device_wait_idle();
            self.destroy_swapchain_parts();
            self.swapchain_loader.destroy_swapchain(self.swapchain, None);
            device.destroy_semaphore(self.image_available, None);
            device.destroy_fence(self.in_flight, None);
            device.destroy_command_pool(self.pool, None);
        }
    }
}
