//! A CPU mirror of `glsl/relight.comp`: the same per-pixel set-up, Sobol points, environment
//! sample, BRDF sample and MIS weights, written with the Rust mirrors of the GLSL includes. It
//! is slow and exact to float rounding, for comparing the GPU kernel pixel by pixel.

use glam::{Vec2, Vec3, Vec4};
use lookdev::environment::product::{cluster_of, Product};
use lookdev::environment::sampling::{background, direction_to_uv, texel_of};
use lookdev::environment::{Distribution, Environment};
use lookdev::gbuffer::GBuffer;
use lookdev::material::Params;
use lookdev::render::sampling::Sampling;
use lookdev::render::Lighting;
use lookdev::shading::brdf::{disney_brdf, make_half_vector, make_lobes, make_view};
use lookdev::shading::frame::{environment_from_world, Frame};
use lookdev::shading::sampling::{brdf_pdf, choose_lobes, mis_weight_over_pdf, sample_brdf};
use lookdev::shading::sobol::{hash_combine, hash_u32, sobol_owen_2d};

pub struct Reference<'a> {
    pub gbuffer: &'a GBuffer,
    pub env: &'a Environment,
    pub distribution: Distribution,
    /// The product tables, when the estimator samples by them.
    pub product: Option<Product>,
    pub lighting: Lighting,
    pub seed: u32,
}

impl<'a> Reference<'a> {
    /// The mirror of a render of `gbuffer` under `env` with the estimator `sampling`.
    pub fn new(gbuffer: &'a GBuffer, env: &'a Environment, sampling: Sampling, lighting: Lighting, seed: u32) -> Self {
        let distribution = sampling.distribution(env, u32::MAX);
        let product = sampling.product(&distribution);
        Reference { gbuffer, env, distribution, product, lighting, seed }
    }

    /// The final linear radiance of pixel (x, y) after `spp` samples, as `read_radiance` gives
    /// it, for a pixel whose resolved material is `params`: the mean of the summed estimates,
    /// composited over the background by coverage (finalize.comp).
    pub fn pixel(&self, x: u32, y: u32, params: &Params, spp: u32) -> Vec4 {
        let i = (y * self.gbuffer.width + x) as usize;
        let coverage = self.gbuffer.coverage[i];
        let mean = if coverage > 0.0 { self.sums(x, y, params, spp).0 / spp as f32 } else { Vec3::ZERO };
        if self.lighting.background {
            (coverage * mean + (1.0 - coverage) * self.background(x, y, false)).extend(1.0)
        } else {
            (coverage * mean).extend(coverage)
        }
    }

    /// The same for a covered pixel of an object that catches shadows: the background darkened
    /// by the share of light that reaches it (its sum over its unshadowed sum, per channel), or,
    /// without the background, a black shadow whose alpha is 1 minus that share's mean.
    pub fn catcher_pixel(&self, x: u32, y: u32, params: &Params, spp: u32) -> Vec4 {
        let i = (y * self.gbuffer.width + x) as usize;
        let coverage = self.gbuffer.coverage[i];
        let share = self.shadow(x, y, params, spp);
        if self.lighting.background {
            let behind = self.background(x, y, true);
            (coverage * share * behind + (1.0 - coverage) * behind).extend(1.0)
        } else {
            Vec4::new(0.0, 0.0, 0.0, coverage * (1.0 - (share.x + share.y + share.z) / 3.0))
        }
    }

    /// The share of a catcher's light that reaches it, per channel: the `shadow` AOV.
    pub fn shadow(&self, x: u32, y: u32, params: &Params, spp: u32) -> Vec3 {
        let (sum, open) = self.sums(x, y, params, spp);
        let share = |s: f32, o: f32| if o != 0.0 { s / o } else { 1.0 };
        Vec3::new(share(sum.x, open.x), share(sum.y, open.y), share(sum.z, open.z))
    }

    /// What the first pass stores as the environment behind pixel (x, y).
    fn background(&self, x: u32, y: u32, catcher: bool) -> Vec3 {
        let g = self.gbuffer;
        let i = (y * g.width + x) as usize;
        let rotation = self.lighting.rotation_degrees.to_radians();
        let to_env = |d: Vec3| environment_from_world(d, rotation.cos(), rotation.sin());
        if g.coverage[i] < 1.0 || catcher {
            self.lighting.intensity * background(self.env, direction_to_uv(to_env(-Vec3::from(g.view[i]))))
        } else {
            Vec3::ZERO
        }
    }

    /// The accumulation image's running sum of estimates for a covered pixel, and the sum of
    /// the same estimates with every direction seen (a shadow catcher's unshadowed sum).
    fn sums(&self, x: u32, y: u32, params: &Params, spp: u32) -> (Vec3, Vec3) {
        let g = self.gbuffer;
        let i = (y * g.width + x) as usize;
        let view = Vec3::from(g.view[i]);
        let rotation = self.lighting.rotation_degrees.to_radians();
        let (cos_r, sin_r) = (rotation.cos(), rotation.sin());
        let (mut sum, mut open) = (Vec3::ZERO, Vec3::ZERO);
        let n = Vec3::from(g.normal[i]);
        let frame = Frame::new(n, Vec3::from(g.tangent[i]));
        let v = frame.to_local(view);
        let lobes = make_lobes(params);
        let view_terms = make_view(&lobes, v);
        let choice = choose_lobes(&lobes, &view_terms);
        let env_frame = frame.rotated_into_environment(cos_r, sin_r);
        let pixel_seed = hash_combine(hash_u32(self.seed), y * g.width + x);
        let env_seed = hash_combine(pixel_seed, 0x454e56);
        let brdf_seed = hash_combine(pixel_seed, 0x425244);
        // choose_environment: the normal's cluster's table alone (q = 1) with product tables.
        let cluster = self.product.as_ref().map(|p| cluster_of(env_frame.n, p.grid));
        let pdf_env = |t| match (&self.product, cluster) {
            (Some(p), Some(c)) => p.mixture_pdf(&self.distribution, c, 1.0, t),
            _ => self.distribution.texel_cell_pdf(t),
        };
        let sample_env = |u| match (&self.product, cluster) {
            (Some(p), Some(c)) => p.sample_mixture(&self.distribution, c, 1.0, u),
            _ => self.distribution.sample(u),
        };
        let texel = |d: Vec3| {
            let t = texel_of(self.env.width, self.env.height, direction_to_uv(d));
            (Vec3::from(self.env.texel(t.x, t.y)), pdf_env(t))
        };
        // relight.comp's seen(): the g-buffer's bit for the direction, turned back into the world.
        let seen = |d: Vec3| {
            let world = Vec3::new(d.x * cos_r + d.z * sin_r, d.y, -d.x * sin_r + d.z * cos_r);
            g.visibility.as_ref().is_none_or(|visibility| visibility.seen(i, world))
        };
        let emission = Vec3::from(params.emission);
        if v.z <= 0.0 {
            let sum = (0..spp).fold(sum, |sum, _| sum + emission);
            return (sum, sum);
        }
        for s in 0..spp {
            let (mut radiance, mut unshadowed) = (Vec3::ZERO, Vec3::ZERO);
            let (u_env, u_brdf): (Vec2, Vec2) = (sobol_owen_2d(s, env_seed), sobol_owen_2d(s, brdf_seed));
            let (d, t) = sample_env(u_env);
            let (le, pdf_env) = (Vec3::from(self.env.texel(t.x, t.y)), pdf_env(t));
            let l = env_frame.to_local(d);
            if l.z > 0.0 && pdf_env > 0.0 {
                let hv = make_half_vector(&lobes, l, v);
                let f = disney_brdf(&lobes, &view_terms, l, &hv);
                let pdf_brdf = brdf_pdf(&choice, &view_terms, l, &hv);
                let light = f * (l.z * mis_weight_over_pdf(pdf_env, pdf_brdf)) * le;
                radiance += if seen(d) { light } else { Vec3::ZERO };
                unshadowed += light;
            }
            let l = sample_brdf(&lobes, &choice, &view_terms, u_brdf);
            if l.z > 0.0 {
                let hv = make_half_vector(&lobes, l, v);
                let pdf_brdf = brdf_pdf(&choice, &view_terms, l, &hv);
                let d = env_frame.to_world(l).normalize();
                if pdf_brdf > 0.0 {
                    let (le, pdf_env) = texel(d);
                    let f = disney_brdf(&lobes, &view_terms, l, &hv);
                    let light = f * (l.z * mis_weight_over_pdf(pdf_brdf, pdf_env)) * le;
                    radiance += if seen(d) { light } else { Vec3::ZERO };
                    unshadowed += light;
                }
            }
            sum += emission + radiance * self.lighting.intensity;
            open += emission + unshadowed * self.lighting.intensity;
        }
        (sum, open)
    }
}
