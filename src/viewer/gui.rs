//! egui on Vulkan: input from winit, drawing through egui-ash-renderer into the swapchain image,
//! and the rendered view shown as an egui texture.

use super::presenter::Presenter;
use crate::gpu::{Context, Image};
use crate::{Error, Result};
use ash::vk;
use egui_ash_renderer::{DynamicRendering, Options, RenderMode, Renderer};
use winit::window::Window;

/// The egui context and what draws it.
pub struct Gui {
    ctx: Context,
    pub egui: egui::Context,
    state: egui_winit::State,
    renderer: Renderer<egui_ash_renderer::allocator::DefaultAllocator>,
    /// The rendered views: A's, and B's while comparing.
    view_textures: [Option<ViewTexture>; 2],
    /// Key presses a script made, for the next frame's input.
    pressed_keys: Vec<egui::Event>,
}

/// The rendered view as a texture egui can draw: a sampler set over the display image.
struct ViewTexture {
    id: egui::TextureId,
    pool: vk::DescriptorPool,
    layout: vk::DescriptorSetLayout,
    sampler: vk::Sampler,
    image_view: vk::ImageView,
}

fn renderer_error(e: impl std::fmt::Display) -> Error {
    Error::gpu(format!("the user interface renderer failed ({e})"))
}

impl Gui {
    pub fn new(ctx: &Context, window: &Window, presenter: &Presenter) -> Result<Gui> {
        let egui = egui::Context::default();
        let state = egui_winit::State::new(egui.clone(), egui::ViewportId::ROOT, window, None, None, None);
        let renderer = Renderer::with_default_allocator(
            &ctx.shared.instance,
            ctx.shared.physical_device,
            ctx.shared.device.clone(),
            RenderMode::DynamicRendering(DynamicRendering {
                color_attachment_format: presenter.format,
                depth_attachment_format: None,
                stencil_attachment_format: None,
            }),
            Options { in_flight_frames: 1, srgb_framebuffer: true, ..Options::default() },
        )
        .map_err(renderer_error)?;
        Ok(Gui { ctx: ctx.clone(), egui, state, renderer, view_textures: [None, None], pressed_keys: Vec::new() })
    }

    /// Passes a window event to egui; true when egui used it.
    pub fn on_event(&mut self, window: &Window, event: &winit::event::WindowEvent) -> bool {
        self.state.on_window_event(window, event).consumed
    }

    /// The texture id of rendered view `slot` (0: A, 1: B), made (or remade) for `image`.
    pub fn view_texture(&mut self, slot: usize, image: &Image) -> Result<egui::TextureId> {
        if let Some(texture) = &self.view_textures[slot] {
            if texture.image_view == image.srgb_view {
                return Ok(texture.id);
            }
        }
        self.release_view_texture(slot);
        let device = &self.ctx.shared.device;
        let layout = egui_ash_renderer::vulkan::create_vulkan_descriptor_set_layout(device).map_err(renderer_error)?;
        let sizes =
            [vk::DescriptorPoolSize::default().ty(vk::DescriptorType::COMBINED_IMAGE_SAMPLER).descriptor_count(1)];
        let pool = unsafe {
            device.create_descriptor_pool(&vk::DescriptorPoolCreateInfo::default().max_sets(1).pool_sizes(&sizes), None)
        }?;
        // Nearest filtering: zoomed in, an artist inspects pixels, not a blur of them.
        let sampler_info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::NEAREST)
            .min_filter(vk::Filter::LINEAR)
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE);
        let sampler = unsafe { device.create_sampler(&sampler_info, None) }?;
        let layouts = [layout];
        let set = unsafe {
            device.allocate_descriptor_sets(
                &vk::DescriptorSetAllocateInfo::default().descriptor_pool(pool).set_layouts(&layouts),
            )
        }?[0];
        let info = [vk::DescriptorImageInfo::default()
            .sampler(sampler)
            .image_view(image.srgb_view)
            .image_layout(vk::ImageLayout::GENERAL)];
        let write = vk::WriteDescriptorSet::default()
            .dst_set(set)
            .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
            .image_info(&info);
        unsafe { device.update_descriptor_sets(&[write], &[]) };
        let id = self.renderer.add_user_texture(set);
        self.view_textures[slot] = Some(ViewTexture { id, pool, layout, sampler, image_view: image.srgb_view });
        Ok(id)
    }

    /// Lets go of rendered view `slot`'s texture, if it has one.
    pub fn release_view_texture(&mut self, slot: usize) {
        if let Some(texture) = self.view_textures[slot].take() {
            self.renderer.remove_user_texture(texture.id);
            let device = &self.ctx.shared.device;
            unsafe {
                let _ = device.device_wait_idle();
                device.destroy_descriptor_pool(texture.pool, None);
                device.destroy_descriptor_set_layout(texture.layout, None);
                device.destroy_sampler(texture.sampler, None);
            }
        }
    }

    /// Queues a key press (and its release) for the next frame's input, as if typed.
    pub fn press_key(&mut self, key: egui::Key, modifiers: egui::Modifiers) {
        for pressed in [true, false] {
            self.pressed_keys.push(egui::Event::Key { key, physical_key: None, pressed, repeat: false, modifiers });
        }
    }

    /// Runs the interface for one frame: input in, shapes out, nothing drawn yet.
    pub fn run(&mut self, window: &Window, ui: impl FnMut(&mut egui::Ui)) -> egui::FullOutput {
        let mut input = self.state.take_egui_input(window);
        input.events.append(&mut self.pressed_keys);
        let output = self.egui.run_ui(input, ui);
        self.state.handle_platform_output(window, output.platform_output.clone());
        output
    }

    /// How soon the interface wants another frame (animations, tooltips), if at all.
    pub fn repaint_delay(output: &egui::FullOutput) -> Option<std::time::Duration> {
        output
            .viewport_output
            .get(&egui::ViewportId::ROOT)
            .map(|v| v.repaint_delay)
            .filter(|d| *d != std::time::Duration::MAX)
    }

    /// Draws a frame's interface into the window. Returns the window's pixels when `capture` is
    /// set (see [`Presenter::frame`]).
    pub fn draw(
        &mut self,
        presenter: &mut Presenter,
        output: egui::FullOutput,
        capture: bool,
    ) -> Result<Option<image::RgbaImage>> {
        let primitives = self.egui.tessellate(output.shapes, output.pixels_per_point);
        for (id, deltas) in &output.textures_delta.set {
            for delta in deltas {
                let _queue = self.ctx.lock_queue();
                self.renderer
                    .set_texture(self.ctx.shared.queue, presenter.pool(), *id, delta)
                    .map_err(renderer_error)?;
            }
        }
        let renderer = &mut self.renderer;
        let device = self.ctx.shared.device.clone();
        let captured = presenter.frame(capture, |cmd, view, extent| {
            let attachments = [vk::RenderingAttachmentInfo::default()
                .image_view(view)
                .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                .load_op(vk::AttachmentLoadOp::CLEAR)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue { color: vk::ClearColorValue { float32: [0.02, 0.02, 0.025, 1.0] } })];
            let info = vk::RenderingInfo::default()
                .render_area(vk::Rect2D { offset: vk::Offset2D::default(), extent })
                .layer_count(1)
                .color_attachments(&attachments);
            unsafe { device.cmd_begin_rendering(cmd, &info) };
            renderer.cmd_draw(cmd, extent, output.pixels_per_point, &primitives).map_err(renderer_error)?;
            unsafe { device.cmd_end_rendering(cmd) };
            Ok(())
        })?;
        if !output.textures_delta.free.is_empty() {
            unsafe { self.ctx.shared.device.device_wait_idle() }?;
            for id in &output.textures_delta.free {
                self.renderer.free_texture(*id).map_err(renderer_error)?;
            }
        }
        Ok(captured)
    }
}

impl Drop for Gui {
    fn drop(&mut self) {
        unsafe {
            let _ = self.ctx.shared.device.device_wait_idle();
        }
        self.release_view_texture(0);
        self.release_view_texture(1);
    }
}
