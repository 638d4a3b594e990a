//! Many renders of one g-buffer under one environment, each with its own look: contact sheets,
//! wedges and turntables. The renderer, g-buffer and environment are set up once.

use super::downsample;
use super::progressive;
use super::renderer::KernelSource;
use super::sampling::Sampling;
use super::scene::covered_object_ids;
use super::settings::Settings;
use super::Renderer;
use crate::environment::backdrop::Prepared;
use crate::environment::Environment;
use crate::gbuffer::GBuffer;
use crate::gpu::Context;
use crate::material::look::{Layer, ObjectStack};
use crate::material::stack::PackedStacks;
use crate::material::{Look, Params};
use crate::Result;
use std::path::Path;

/// A renderer kept across renders of different looks and settings.
pub struct Batch<'a> {
    renderer: Renderer,
    gbuffer: &'a GBuffer,
    gbuffer_name: &'a Path,
    environment: &'a Environment,
}

impl<'a> Batch<'a> {
    pub fn new(
        ctx: &Context,
        gbuffer: &'a GBuffer,
        gbuffer_name: &'a Path,
        environment: &'a Environment,
    ) -> Result<Batch<'a>> {
        Batch::with_kernels(ctx, gbuffer, gbuffer_name, environment, Sampling::default(), KernelSource::default())
    }

    /// A batch whose renderer starts with `kernels` and the estimator `sampling`
    /// ([`Renderer::with_kernels`]): those of the first render, so that it compiles nothing.
    pub fn with_kernels(
        ctx: &Context,
        gbuffer: &'a GBuffer,
        gbuffer_name: &'a Path,
        environment: &'a Environment,
        sampling: Sampling,
        kernels: KernelSource,
    ) -> Result<Batch<'a>> {
        let renderer = Renderer::with_kernels(ctx, gbuffer, environment, sampling, kernels)?;
        Ok(Batch { renderer, gbuffer, gbuffer_name, environment })
    }

    /// What a shown background is in the renders that follow ([`Renderer::set_backdrop`]):
    /// the environment until set.
    pub fn set_backdrop(&mut self, backdrop: &Prepared) -> Result<()> {
        self.renderer.set_backdrop(backdrop)
    }

    /// The renders' width: the g-buffer's, over its supersampling factor.
    pub fn width(&self) -> u32 {
        self.gbuffer.width / self.gbuffer.supersample
    }

    /// The renders' height: the g-buffer's, over its supersampling factor.
    pub fn height(&self) -> u32 {
        self.gbuffer.height / self.gbuffer.supersample
    }

    /// Renders `look` with `settings` (environment file excepted: the batch's is fixed) to
    /// `settings.spp`, calling `progress(samples)` after each pass.
    pub fn render(&mut self, look: &Look, settings: &Settings, progress: impl FnMut(u32)) -> Result<()> {
        let stacks = PackedStacks::pack(look, covered_object_ids(self.gbuffer), self.gbuffer, self.gbuffer_name)?;
        // The noise threshold before the AOVs and the model: with them it gives the kernels'
        // specialisation, which then changes at most once.
        self.renderer.set_noise_threshold(settings.noise)?;
        self.renderer.set_accumulate(super::aov::accumulate(&settings.aovs))?;
        self.renderer.set_stacks(&stacks)?;
        self.renderer.set_model(&settings.model)?;
        self.renderer.set_lighting(settings.lighting);
        self.renderer.set_seed(settings.seed);
        self.renderer.set_sampling(settings.sampling, self.environment)?;
        progressive::accumulate(&mut self.renderer, settings.spp, progress)?;
        Ok(())
    }

    /// The last render as display pixels (RGBA8), filtered down by the g-buffer's supersampling
    /// factor (the display pixels then made from the filtered radiance).
    pub fn display(&self, settings: &Settings) -> Result<Vec<u8>> {
        match self.gbuffer.supersample {
            1 => self.renderer.read_display(settings.exposure, settings.tonemap),
            _ => {
                let (exposure, tonemap, background) =
                    (settings.exposure, settings.tonemap, settings.lighting.background);
                Ok(downsample::display(&self.radiance()?, exposure, tonemap, background))
            }
        }
    }

    /// The last render as linear radiance, filtered down by the g-buffer's supersampling factor.
    pub fn radiance(&self) -> Result<Vec<[f32; 4]>> {
        let radiance = self.renderer.read_radiance()?;
        Ok(match self.gbuffer.supersample {
            1 => radiance,
            factor => downsample::box_filter(&radiance, self.gbuffer.width, factor),
        })
    }

    /// The last render's AOVs (`settings.aovs`), of `look`, filtered down likewise.
    pub fn aovs(&self, look: &Look, settings: &Settings) -> Result<Vec<super::aov::Layer>> {
        let sources = super::aov::Sources { gbuffer: self.gbuffer, look, renderer: &self.renderer };
        let layers = super::aov::layers(&settings.aovs, &sources)?;
        let (width, factor) = (self.gbuffer.width, self.gbuffer.supersample);
        Ok(layers.into_iter().map(|layer| downsample::layer(layer, width, factor)).collect())
    }
}

/// The look of a preset's catalogue picture (a contact-sheet cell, a viewer thumbnail): the
/// preset on the ball, a neutral mid-grey pedestal.
pub fn preset_on_ball(params: &Params) -> Look {
    let pedestal = Params { base_color: [0.18; 3], roughness: 0.6, ..Params::default() };
    let mut look = Look::default_material();
    look.objects = vec![
        ObjectStack::new(None, vec![Layer::filling(pedestal)]),
        ObjectStack::new(Some(crate::gbuffer::BALL_ID), vec![Layer::filling(*params)]),
    ];
    look
}
