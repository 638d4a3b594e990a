//! Every sampling routine the renderer uses, run on the GPU through the sample_probe kernel:
//! chi-square tests of the sampled directions against the integrated pdf, checks that each pdf
//! integrates to 1, that the pdf the GPU reports matches the Rust reference, and that the GPU's
//! Owen-scrambled Sobol sequence is the reference's, bit for bit.

mod common;

use common::probes::{self, Setup};
use common::random::Random;
use common::stats::chi_square;
use glam::{Vec2, Vec3};
use lookdev::environment::distribution::row_cos;
use lookdev::environment::{self, Distribution, Environment, GpuEnvironment};
use lookdev::gpu::{shaders, Binding, Buffer, ComputePipeline, Context};
use lookdev::material::Params;
use lookdev::shading::brdf::{make_half_vector, make_lobes, make_lobes_with, make_view, Lobes, Shading};
use lookdev::shading::model::Model;
use lookdev::shading::{sampling, sobol};

const COSINE: u32 = 0;
const GGX: u32 = 1;
const GTR1: u32 = 2;
const BRDF: u32 = 3;
const ENVIRONMENT: u32 = 4;
const SOBOL: u32 = 5;
const UV_ROUND_TRIP: u32 = 6;

struct Probe {
    ctx: Context,
    pipeline: ComputePipeline,
    energy: Buffer,
    shading: Shading,
}

impl Probe {
    fn new() -> Probe {
        Probe::with_model(common::gpu::context(), &Model::default())
    }

    /// The probe specialized for a BRDF model, on `ctx`.
    fn with_model(ctx: Context, model: &Model) -> Probe {
        let pipeline = ComputePipeline::specialized(
            &ctx,
            &shaders::SAMPLE_PROBE,
            probes::SAMPLE_PROBE.sets,
            probes::SAMPLE_PROBE.push_size(),
            &model.specialization(),
        )
        .unwrap();
        let (energy, shading) = common::gpu::model_shading(&ctx, model);
        Probe { ctx, pipeline, energy, shading }
    }

    /// The Rust reference's per-pixel state for a material, under the probe's model.
    fn lobes(&self, params: &Params) -> Lobes {
        make_lobes_with(params, &self.shading)
    }

    /// Gives the context back, for the next model's probe.
    fn into_context(self) -> Context {
        drop(self.pipeline);
        drop(self.energy);
        self.ctx
    }

    /// Runs `routine` on `uniforms`, returning (direction or point, pdf) per sample.
    fn run(
        &self,
        routine: u32,
        params: &Params,
        view: Vec3,
        seed: u32,
        uniforms: &[Vec2],
        env: &Environment,
    ) -> Vec<(Vec3, f32)> {
        self.run_with(routine, params, view, seed, uniforms, env, &Distribution::build(env))
    }

    /// As `run`, with the environment's sampling tables given.
    #[allow(clippy::too_many_arguments)]
    fn run_with(
        &self,
        routine: u32,
        params: &Params,
        view: Vec3,
        seed: u32,
        uniforms: &[Vec2],
        env: &Environment,
        distribution: &Distribution,
    ) -> Vec<(Vec3, f32)> {
        let ctx = &self.ctx;
        let setup = Setup { params: params.brdf_gpu(), view: view.extend(0.0).to_array(), routine, seed, pad: [0; 2] };
        let setup = Buffer::with_data(ctx, bytemuck::bytes_of(&setup)).unwrap();
        let flat: Vec<f32> = uniforms.iter().flat_map(|u| [u.x, u.y]).collect();
        let uniforms_buffer = Buffer::with_data(ctx, bytemuck::cast_slice(&flat)).unwrap();
        let output = Buffer::storage(ctx, uniforms.len() as u64 * 16).unwrap();
        let gpu_env = GpuEnvironment::upload(ctx, env, distribution).unwrap();
        let set0 = self
            .pipeline
            .bind(
                0,
                &[
                    Binding::Buffer(&setup),
                    Binding::Buffer(&uniforms_buffer),
                    Binding::Buffer(&output),
                    Binding::Buffer(&self.energy),
                ],
            )
            .unwrap();
        let set1 = self.pipeline.bind(1, &gpu_env.bindings()).unwrap();
        ctx.run(|cmd| {
            self.pipeline.dispatch(cmd, &[&set0, &set1], &[], [(uniforms.len() as u32).div_ceil(64), 1, 1]);
            Ok(())
        })
        .unwrap();
        let values: Vec<[f32; 4]> = bytemuck::cast_slice(&output.read(ctx).unwrap()).to_vec();
        values.iter().map(|v| (Vec3::new(v[0], v[1], v[2]), v[3])).collect()
    }

    fn finish(self) {
        common::gpu::finish(self.into_context());
    }
}

fn uniforms(count: usize, stream: u32) -> Vec<Vec2> {
    let mut rng = Random::new(stream);
    (0..count).map(|_| Vec2::new(rng.uniform(), rng.uniform())).collect()
}

/// Bins over the whole sphere, uniform in cosθ and φ (so every bin has the same solid angle).
struct SphereBins {
    theta: usize,
    phi: usize,
}

impl SphereBins {
    fn index(&self, d: Vec3) -> usize {
        let d = d.normalize();
        let t = (((1.0 - d.z) * 0.5 * self.theta as f32) as usize).min(self.theta - 1);
        let mut phi = d.y.atan2(d.x);
        if phi < 0.0 {
            phi += 2.0 * std::f32::consts::PI;
        }
        let p = ((phi / (2.0 * std::f32::consts::PI) * self.phi as f32) as usize).min(self.phi - 1);
        t * self.phi + p
    }

    /// ∫ pdf over each bin, by a midpoint rule on a `sub`×`sub` grid inside each bin.
    fn integrate(&self, pdf: &dyn Fn(Vec3) -> f64, sub: usize) -> Vec<f64> {
        let bin_area = 4.0 * std::f64::consts::PI / (self.theta * self.phi) as f64;
        let mut out = vec![0.0; self.theta * self.phi];
        for t in 0..self.theta {
            for p in 0..self.phi {
                let mut sum = 0.0;
                for i in 0..sub {
                    let z = 1.0 - 2.0 * (t as f64 + (i as f64 + 0.5) / sub as f64) / self.theta as f64;
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    for j in 0..sub {
                        let phi =
                            2.0 * std::f64::consts::PI * (p as f64 + (j as f64 + 0.5) / sub as f64) / self.phi as f64;
                        let d = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
                        sum += pdf(d);
                    }
                }
                out[t * self.phi + p] = sum / (sub * sub) as f64 * bin_area;
            }
        }
        out
    }
}

/// The chi-square test and the pdf checks for one routine and one material.
fn check_routine(
    name: &str,
    samples: &[(Vec3, f32)],
    reference_pdf: &dyn Fn(Vec3) -> f64,
    well_conditioned: &dyn Fn(Vec3) -> bool,
    bins: &SphereBins,
) {
    // The GPU's pdf for each sample is the reference's.
    for (i, (d, pdf)) in samples.iter().enumerate().step_by(97) {
        assert!(d.is_finite() && pdf.is_finite(), "{name}: sample {i} is not finite: {d} {pdf}");
        if !well_conditioned(*d) {
            continue;
        }
        let expected = reference_pdf(*d) as f32;
        assert!(
            (pdf - expected).abs() <= 2e-3 * expected.max(1e-3),
            "{name}: sample {i} direction {d}: GPU pdf {pdf}, reference {expected}"
        );
    }
    let probabilities = bins.integrate(reference_pdf, 64);
    let total: f64 = probabilities.iter().sum();
    assert!((total - 1.0).abs() < 2e-3, "{name}: the pdf integrates to {total}, not 1");
    let n = samples.len() as f64;
    let expected: Vec<f64> = probabilities.iter().map(|p| p * n).collect();
    let mut observed = vec![0.0; expected.len()];
    for (d, _) in samples {
        observed[bins.index(*d)] += 1.0;
    }
    assert_chi_square(name, &observed, &expected);
}

fn assert_chi_square(name: &str, observed: &[f64], expected: &[f64]) {
    let result = chi_square(observed, expected).unwrap_or_else(|e| panic!("{name}: {e}"));
    eprintln!("{name}: chi2 {:.1} dof {} p {:.3}", result.statistic, result.dof, result.p_value);
    assert!(result.p_value > 1e-3, "{name}: chi-square rejects the sampler ({result:?})");
}

fn material(roughness: f32, anisotropic: f32, metallic: f32, clearcoat: f32, gloss: f32) -> Params {
    Params { roughness, anisotropic, metallic, clearcoat, clearcoat_gloss: gloss, ..Params::default() }
}

fn view(theta_degrees: f32, phi_degrees: f32) -> Vec3 {
    let (t, p) = (theta_degrees.to_radians(), phi_degrees.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

const SAMPLES: usize = 1 << 20;

#[test]
fn brdf_samplers_match_their_pdfs() {
    let probe = Probe::new();
    let env = Environment::uniform([1.0; 3], 8, 4);
    let bins = SphereBins { theta: 24, phi: 48 };
    let cases = [
        ("cosine", COSINE, material(0.5, 0.0, 0.0, 0.0, 1.0), view(30.0, 0.0)),
        ("ggx rough", GGX, material(0.8, 0.0, 1.0, 0.0, 1.0), view(50.0, 20.0)),
        ("ggx medium anisotropic", GGX, material(0.55, 0.8, 1.0, 0.0, 1.0), view(40.0, 70.0)),
        ("ggx grazing", GGX, material(0.6, 0.3, 1.0, 0.0, 1.0), view(80.0, 200.0)),
        ("gtr1 gloss 0", GTR1, material(0.5, 0.0, 0.0, 1.0, 0.0), view(35.0, 0.0)),
        ("gtr1 gloss 0.6", GTR1, material(0.5, 0.0, 0.0, 1.0, 0.6), view(60.0, 120.0)),
        ("mixture plastic", BRDF, material(0.45, 0.0, 0.0, 0.0, 1.0), view(45.0, 10.0)),
        ("mixture clearcoat", BRDF, material(0.7, 0.5, 0.0, 1.0, 0.3), view(65.0, 300.0)),
        ("mixture metal", BRDF, material(0.6, 0.0, 1.0, 0.5, 0.2), view(20.0, 90.0)),
    ];
    for (index, (name, routine, params, v)) in cases.iter().enumerate() {
        let samples = probe.run(*routine, params, *v, 0, &uniforms(SAMPLES, index as u32), &env);
        let lobes = make_lobes(params);
        let view = make_view(&lobes, *v);
        let choice = sampling::choose_lobes(&lobes, &view);
        let pdf = |l: Vec3| -> f64 {
            let hv = make_half_vector(&lobes, l, *v);
            (match *routine {
                COSINE => sampling::pdf_cosine(l),
                GGX => sampling::pdf_ggx_reflection(&view, &hv),
                GTR1 => sampling::pdf_gtr1_reflection(&view, &hv),
                _ => sampling::brdf_pdf(&choice, &view, l, &hv),
            }) as f64
        };
        // Near l = −v the half vector, and so the reference pdf, is ill-conditioned.
        let well_conditioned = |l: Vec3| (l + *v).length() > 1e-2;
        check_routine(name, &samples, &pdf, &well_conditioned, &bins);
    }
    probe.finish();
}

/// The samplers each model adds (Beckmann and GTR-γ normals, and the lobe mixture with the
/// energy-compensation lobe) against their pdfs, run on the GPU specialized for the model.
#[test]
fn model_samplers_match_their_pdfs() {
    let env = Environment::uniform([1.0; 3], 8, 4);
    let bins = SphereBins { theta: 24, phi: 48 };
    let cases = [
        ("beckmann rough", "specular_d=beckmann", GGX, material(0.8, 0.0, 1.0, 0.0, 1.0), view(50.0, 20.0)),
        ("beckmann anisotropic", "specular_d=beckmann", GGX, material(0.55, 0.8, 1.0, 0.0, 1.0), view(40.0, 70.0)),
        ("beckmann grazing", "specular_d=beckmann", GGX, material(0.6, 0.3, 1.0, 0.0, 1.0), view(80.0, 200.0)),
        ("gtr gamma 1", "specular_d=gtr gtr_gamma=1", GGX, material(0.7, 0.0, 1.0, 0.0, 1.0), view(30.0, 0.0)),
        ("gtr gamma 1.5", "specular_d=gtr gtr_gamma=1.5", GGX, material(0.6, 0.0, 1.0, 0.0, 1.0), view(45.0, 0.0)),
        ("gtr gamma 3", "specular_d=gtr gtr_gamma=3", GGX, material(0.7, 0.5, 1.0, 0.0, 1.0), view(70.0, 100.0)),
        (
            "mixture beckmann height-correlated",
            "specular_d=beckmann specular_g=smith-height-correlated",
            BRDF,
            material(0.5, 0.0, 0.0, 0.5, 0.5),
            view(45.0, 10.0),
        ),
        (
            "mixture gtr oren-nayar conductor",
            "specular_d=gtr gtr_gamma=2.5 diffuse=oren-nayar fresnel=conductor",
            BRDF,
            material(0.6, 0.0, 0.3, 0.0, 1.0),
            view(55.0, 40.0),
        ),
        (
            "mixture energy compensation metal",
            "energy_compensation=true",
            BRDF,
            material(0.8, 0.0, 1.0, 0.0, 1.0),
            view(60.0, 30.0),
        ),
        (
            "mixture energy compensation beckmann",
            "energy_compensation=true specular_d=beckmann",
            BRDF,
            material(0.9, 0.2, 0.5, 0.0, 1.0),
            view(75.0, 150.0),
        ),
    ];
    let mut ctx = Some(common::gpu::context());
    for (index, (name, text, routine, params, v)) in cases.iter().enumerate() {
        let mut model = Model::default();
        for part in text.split(' ') {
            model.set_from_text(part).unwrap();
        }
        let probe = Probe::with_model(ctx.take().unwrap(), &model);
        let samples = probe.run(*routine, params, *v, 0, &uniforms(SAMPLES, 500 + index as u32), &env);
        let lobes = probe.lobes(params);
        let view = make_view(&lobes, *v);
        let choice = sampling::choose_lobes(&lobes, &view);
        if *routine == BRDF && model.energy_compensation {
            assert!(choice.diffuse > 0.0, "{name}: the compensation lobe must be sampled");
        }
        let pdf = |l: Vec3| -> f64 {
            let hv = make_half_vector(&lobes, l, *v);
            (match *routine {
                GGX => sampling::pdf_specular_reflection(&view, &hv),
                _ => sampling::brdf_pdf(&choice, &view, l, &hv),
            }) as f64
        };
        let well_conditioned = |l: Vec3| (l + *v).length() > 1e-2;
        check_routine(name, &samples, &pdf, &well_conditioned, &bins);
        ctx = Some(probe.into_context());
    }
    common::gpu::finish(ctx.unwrap());
}

/// A synthetic environment with a small hot sun, a sky gradient and an entirely black lower
/// half, at a size that is neither a power of two nor a multiple of the bin grid.
fn sun_and_sky(width: u32, height: u32) -> Environment {
    synthetic(width, height, 5000.0)
}

/// The same sky and a broad glow instead of a sun: smooth enough for sphere bins.
fn smooth_sky(width: u32, height: u32) -> Environment {
    synthetic(width, height, 0.0)
}

fn synthetic(width: u32, height: u32, sun: f32) -> Environment {
    let mut texels = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let (u, v) = ((x as f32 + 0.5) / width as f32, (y as f32 + 0.5) / height as f32);
            let sky = if v < 0.5 { 0.2 + 0.8 * (0.5 - v) } else { 0.02 * (1.0 - v) };
            let distance2 = ((u - 0.3) / 0.01).powi(2) + ((v - 0.2) / 0.02).powi(2);
            let glow = 3.0 * (-(((u - 0.7) / 0.1).powi(2) + ((v - 0.35) / 0.1).powi(2))).exp();
            let hot = if distance2 < 1.0 { sun } else { 0.0 };
            texels.push([sky + hot + glow, sky * 1.2 + hot + glow, sky * 1.5 + hot]);
        }
    }
    Environment::new(width, height, texels, format!("synthetic {width}x{height} sun {sun}"))
}

/// Environment samples binned by the distribution's own cells (exact expected counts), and by
/// their position inside a cell (which must be uniform).
fn check_environment_cells(env: &Environment, distribution: &Distribution, samples: &[(Vec3, f32)]) {
    let name = &env.source;
    let mismatched = samples.iter().filter(|(_, pdf)| *pdf < 0.0).count();
    // The sampler's own pdf and the pdf looked up from its direction differ only where the
    // direction-to-uv round trip (accurate to about 1e-6 in uv, see the round-trip test) crosses
    // a cell boundary: a sliver of each cell, so it must be rare.
    assert!(mismatched * 1000 < samples.len(), "{name}: {mismatched} samples' looked-up pdf disagrees");

    let (cols, rows) = (distribution.columns, distribution.rows);
    let (bx, by) = (cols.div_ceil(16), rows.div_ceil(8));
    let (nx, ny) = (cols.div_ceil(bx) as usize, rows.div_ceil(by) as usize);
    let mut expected = vec![0.0; nx * ny];
    for row in 0..rows {
        for column in 0..cols {
            let p = distribution.cell_pdf[(row * cols + column) as usize] as f64
                * distribution.cell_solid_angle(row, column);
            expected[(row / by) as usize * nx + (column / bx) as usize] += p * samples.len() as f64;
        }
    }
    let mut observed = vec![0.0; nx * ny];
    let mut inside = vec![0.0; 64];
    for (d, _) in samples {
        let uv = environment::sampling::direction_to_uv(*d);
        let texel = environment::sampling::texel_of(distribution.width, distribution.height, uv);
        let (cx, cy) = (texel.x / distribution.block_x, texel.y / distribution.block_y);
        observed[(cy / by) as usize * nx + (cx / bx) as usize] += 1.0;
        // Where the sample lies inside its cell, uniform in azimuth and in cos θ: [0, 1)².
        let (x0, x1) = Distribution::span(cx, distribution.block_x, distribution.width);
        let (y0, y1) = Distribution::span(cy, distribution.block_y, distribution.height);
        let fx = (uv.x * distribution.width as f32 - x0 as f32) / (x1 - x0) as f32;
        let (z0, z1) = (row_cos(y0, distribution.height), row_cos(y1, distribution.height));
        let fy = ((d.y as f64 - z0) / (z1 - z0)) as f32;
        inside[((fy * 8.0).max(0.0) as usize).min(7) * 8 + ((fx * 8.0).max(0.0) as usize).min(7)] += 1.0;
    }
    assert_chi_square(&format!("{name}, cells"), &observed, &expected);
    let uniform = vec![samples.len() as f64 / 64.0; 64];
    assert_chi_square(&format!("{name}, inside cells"), &inside, &uniform);
}

#[test]
fn environment_sampling_matches_its_pdf() {
    let probe = Probe::new();
    let envs = [Environment::studio(), sun_and_sky(300, 150), sun_and_sky(97, 61), smooth_sky(200, 100)];
    for (index, env) in envs.iter().enumerate() {
        let distribution = Distribution::build(env);
        let samples =
            probe.run(ENVIRONMENT, &Params::default(), Vec3::Z, 0, &uniforms(SAMPLES, 100 + index as u32), env);
        check_environment_cells(env, &distribution, &samples);
    }
    // Maps wider than the cell grid use blocks of texels, with smaller blocks at the edges.
    let env = sun_and_sky(301, 150);
    let blocked = Distribution::with_max_cells(&env, 64);
    assert_eq!((blocked.block_x, blocked.block_y, blocked.columns, blocked.rows), (5, 3, 61, 50));
    let samples = probe.run_with(ENVIRONMENT, &Params::default(), Vec3::Z, 0, &uniforms(SAMPLES, 300), &env, &blocked);
    check_environment_cells(&env, &blocked, &samples);

    // pdf_ω integrates to 1 over the sphere, by a quadrature that knows nothing of the cells
    // (so only for maps without a sun too small for it to resolve).
    for env in [&envs[0], &envs[3]] {
        let distribution = Distribution::build(env);
        let total = sphere_integral(&|d| pdf_of(&distribution, d));
        assert!((total - 1.0).abs() < 2e-3, "{}: pdf over solid angle integrates to {total}", env.source);
    }
    // A smooth map also goes through the sphere-bin test, which checks the direction mapping and
    // its sinθ Jacobian independently of the cells.
    let env = &envs[3];
    let distribution = Distribution::build(env);
    let samples = probe.run(ENVIRONMENT, &Params::default(), Vec3::Z, 0, &uniforms(SAMPLES, 200), env);
    // Bin with the poles of the environment (±Y) on the bins' axis.
    let to_bins = |d: Vec3| Vec3::new(d.x, -d.z, d.y);
    let from_bins = |d: Vec3| Vec3::new(d.x, d.z, -d.y);
    let binned: Vec<(Vec3, f32)> = samples.iter().map(|(d, p)| (to_bins(*d), *p)).collect();
    let pdf = |d: Vec3| pdf_of(&distribution, from_bins(d));
    check_routine("environment, sphere bins", &binned, &pdf, &|_| true, &SphereBins { theta: 24, phi: 48 });
    probe.finish();
}

fn pdf_of(distribution: &Distribution, d: Vec3) -> f64 {
    distribution.pdf(environment::sampling::direction_to_uv(d.normalize())) as f64
}

/// ∫ f over the sphere by a fine midpoint rule, uniform in cosθ and φ about +Y.
fn sphere_integral(f: &dyn Fn(Vec3) -> f64) -> f64 {
    let (nt, np) = (1500, 3000);
    let mut sum = 0.0;
    for i in 0..nt {
        let y = 1.0 - 2.0 * (i as f64 + 0.5) / nt as f64;
        let r = (1.0 - y * y).sqrt();
        for j in 0..np {
            let phi = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / np as f64;
            sum += f(Vec3::new((r * phi.cos()) as f32, y as f32, (r * phi.sin()) as f32));
        }
    }
    sum * 4.0 * std::f64::consts::PI / (nt * np) as f64
}

#[test]
fn the_reference_samplers_match_their_pdfs_too() {
    // The Rust mirror is used by the CPU reference renderer, so it must be right as well.
    let params = material(0.6, 0.4, 0.0, 1.0, 0.4);
    let v = view(50.0, 30.0);
    let lobes = make_lobes(&params);
    let view = make_view(&lobes, v);
    let choice = sampling::choose_lobes(&lobes, &view);
    let samples: Vec<(Vec3, f32)> = uniforms(1 << 18, 77)
        .into_iter()
        .map(|u| {
            let l = sampling::sample_brdf(&lobes, &choice, &view, u);
            (l, sampling::brdf_pdf(&choice, &view, l, &make_half_vector(&lobes, l, v)))
        })
        .collect();
    let pdf = |l: Vec3| sampling::brdf_pdf(&choice, &view, l, &make_half_vector(&lobes, l, v)) as f64;
    check_routine("reference mixture", &samples, &pdf, &|_| true, &SphereBins { theta: 16, phi: 32 });

    let env = sun_and_sky(120, 60);
    let distribution = Distribution::build(&env);
    let samples: Vec<(Vec3, f32)> = uniforms(1 << 18, 78)
        .into_iter()
        .map(|u| {
            let (d, texel) = distribution.sample(u);
            let pdf = distribution.texel_cell_pdf(texel);
            let looked_up = distribution.pdf(environment::sampling::direction_to_uv(d));
            (d, if (looked_up - pdf).abs() <= 1e-3 * pdf { pdf } else { -1.0 })
        })
        .collect();
    check_environment_cells(&env, &distribution, &samples);
}

#[test]
fn gpu_sobol_is_the_reference_sequence() {
    let probe = Probe::new();
    let env = Environment::uniform([1.0; 3], 8, 4);
    for seed in [0u32, 1, 0x1234_5678, u32::MAX] {
        let count = 4096;
        let points = probe.run(SOBOL, &Params::default(), Vec3::Z, seed, &vec![Vec2::ZERO; count], &env);
        for (i, (p, _)) in points.iter().enumerate() {
            let expected = sobol::sobol_owen_2d(i as u32, seed);
            assert_eq!((p.x, p.y), (expected.x, expected.y), "seed {seed} index {i}");
        }
    }
    probe.finish();
}

/// The GPU's uv → direction → uv round trip is accurate to a few parts in 1e6, so lookups land
/// in the texel and cell they should.
#[test]
fn gpu_direction_mapping_round_trips() {
    let probe = Probe::new();
    let env = Environment::uniform([1.0; 3], 8, 4);
    let us = uniforms(1 << 16, 5);
    let results = probe.run(UV_ROUND_TRIP, &Params::default(), Vec3::Z, 0, &us, &env);
    for (u, (r, _)) in us.iter().zip(&results) {
        let back = Vec2::new(r.x, r.y);
        let mut error = (back - *u).abs();
        error.x = error.x.min(1.0 - error.x); // u wraps
        assert!(error.max_element() < 1e-5, "uv {u} came back as {back}");
        // The convention itself: the direction's y is cos(πv).
        assert!((r.z - (std::f32::consts::PI * u.y).cos()).abs() < 1e-5);
    }
    probe.finish();
}
