//! Product sampling (`--sampling product`, docs/shading.md#sampling): the GPU's samples of each
//! cluster's mixture against the Rust pdf (chi-square), the GPU sampler against its Rust mirror,
//! and the estimator's determinism and AOV twin. Its unbiasedness is tested with the other
//! estimators' in tests/estimator.rs, which iterates `Sampling::ALL`.

mod common;

use common::probes::environment_samples;
use common::random::Random;
use common::scenes::{one_material, orthographic_sphere, renderer};
use common::stats::chi_square;
use glam::{Vec2, Vec3};
use lookdev::environment::product::{cluster_of, Product, GRID};
use lookdev::environment::{sampling, Builtin, Distribution, Environment, GpuEnvironment, Samplers};
use lookdev::gpu::Context;
use lookdev::material::Params;
use lookdev::render::renderer::Accumulate;
use lookdev::render::sampling::Sampling;
use lookdev::render::Lighting;

/// sample_probe.comp's product routine.
const PRODUCT: u32 = 7;

/// Samples of `cluster`'s mixture with share `q`, drawn on the GPU from the uniform points `u`:
/// (direction, pdf the sampler reports, or −1 where the pdf looked up from the direction
/// disagrees).
fn gpu_product_samples(
    ctx: &Context,
    env: &Environment,
    d: &Distribution,
    product: &Product,
    cluster: u32,
    q: f32,
    u: &[Vec2],
) -> Vec<(Vec3, f32)> {
    // The cluster's sampler alone (q = 1) runs without the global bucket entries.
    let samplers = if q == 1.0 { Samplers::Product(product) } else { Samplers::Mixture(product) };
    let gpu_env = GpuEnvironment::upload_with(ctx, env, d, samplers).unwrap();
    environment_samples(ctx, &gpu_env, PRODUCT, cluster, q, u)
}

/// A dim sky over dark ground with a small, very bright sun.
fn sun_and_sky() -> Environment {
    let (w, h) = (300u32, 150u32);
    let texels = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let sky = if y < h / 2 { 0.3 + (h / 2 - y) as f32 / h as f32 } else { 0.05 };
            if (x as i32 - 90).abs() < 3 && (y as i32 - 30).abs() < 3 {
                [4000.0; 3]
            } else {
                [sky, sky, 1.3 * sky]
            }
        })
        .collect();
    Environment::new(w, h, texels, "sun and sky")
}

/// The GPU samples each cluster's mixture as the Rust pdf says, grouped into 16 × 8 blocks of
/// cells; never where that pdf is 0; reports the pdf the Rust reference gives; and draws the
/// same directions as the Rust mirror from the same points. On real HDRIs and a synthetic sun,
/// for clusters facing up, sideways and down, and for pure and mixed shares.
#[test]
fn gpu_product_samples_follow_the_rust_pdf() {
    let ctx = common::gpu::context();
    let envs = [Builtin::find("studio").unwrap().load(), Builtin::find("sunrise").unwrap().load(), sun_and_sky()];
    let count = 200_000;
    let normals = [Vec3::Y, Vec3::new(0.3, 0.1, -0.9).normalize(), Vec3::new(-0.5, -0.7, 0.2).normalize()];
    for env in &envs {
        let d = Distribution::compensated_with_max_cells(env, 4096);
        let product = Product::build(&d);
        for (k, normal) in normals.iter().enumerate() {
            let cluster = cluster_of(*normal, GRID);
            let q = if k == 1 { 0.6 } else { 1.0 };
            let what = format!("{}, cluster {cluster}, q = {q}", env.source);
            let mut rng = Random::new(7 + k as u32);
            let u: Vec<Vec2> = (0..count).map(|_| Vec2::new(rng.uniform(), rng.uniform())).collect();
            let samples = gpu_product_samples(&ctx, env, &d, &product, cluster, q, &u);
            let (cols, rows) = (d.columns, d.rows);
            let (bx, by) = (cols.div_ceil(16), rows.div_ceil(8));
            let nx = cols.div_ceil(bx) as usize;
            let mut expected = vec![0.0; nx * rows.div_ceil(by) as usize];
            for r in 0..rows {
                for c in 0..cols {
                    let t = glam::UVec2::new(c * d.block_x, r * d.block_y);
                    let p = product.mixture_pdf(&d, cluster, q, t) as f64 * d.cell_solid_angle(r, c);
                    expected[(r / by) as usize * nx + (c / bx) as usize] += p * count as f64;
                }
            }
            let mut observed = vec![0.0; expected.len()];
            let (mut mismatched, mut in_zero_cells, mut astray) = (0, 0, 0);
            for ((dir, pdf), u) in samples.iter().zip(&u) {
                let uv = sampling::direction_to_uv(*dir);
                let t = sampling::texel_of(d.width, d.height, uv);
                observed[(t.y / d.block_y / by) as usize * nx + (t.x / d.block_x / bx) as usize] += 1.0;
                let reference = product.mixture_pdf(&d, cluster, q, t);
                in_zero_cells += (reference == 0.0) as usize;
                mismatched += (*pdf < 0.0 || (pdf - reference).abs() > 1e-3 * reference) as usize;
                let (mirror, _) = product.sample_mixture(&d, cluster, q, *u);
                astray += (mirror.dot(*dir) < 1.0 - 1e-5) as usize;
            }
            // Only where the direction's round trip crosses a cell boundary, a sliver of each cell.
            assert!(mismatched * 1000 < count, "{what}: {mismatched} samples' pdf disagrees with the reference");
            assert!(in_zero_cells * 1000 < count, "{what}: {in_zero_cells} samples where the pdf is 0");
            assert!(astray * 1000 < count, "{what}: {astray} samples differ from the Rust mirror's");
            let result = chi_square(&observed, &expected).unwrap_or_else(|e| panic!("{what}: {e}"));
            assert!(result.p_value > 1e-3, "{what}: {result:?}");
            // The cluster's own table leaves the far side of the sphere to the global tables.
            if q == 1.0 {
                let below = samples.iter().filter(|(dir, _)| dir.dot(*normal) < -0.5).count();
                assert!(below * 100 < count, "{what}: {below} samples far below the horizon");
            }
        }
    }
    common::gpu::finish(ctx);
}

/// Product sampling gives the same bits for the same seed however the samples are split into
/// passes and bands, a different image for another seed, and the same total with the lobe AOVs
/// on (estimate_lobes is estimate's twin), whose lobes sum to it.
#[test]
fn product_sampling_is_deterministic_and_its_aov_twin_agrees() {
    let ctx = common::gpu::context();
    let gbuffer = orthographic_sphere(24);
    let env = Builtin::find("interior").unwrap().load();
    let look =
        one_material(Params { base_color: [0.7, 0.5, 0.3], roughness: 0.6, clearcoat: 0.5, ..Params::default() });
    let lighting = Lighting { rotation_degrees: 70.0, intensity: 1.0, background: false };
    let render = |splits: &[u32], seed: u32, accumulate: Accumulate| {
        let mut r = renderer(&ctx, &gbuffer, &env, &look, lighting);
        r.set_sampling(Sampling::Product, &env).unwrap();
        r.set_accumulate(accumulate).unwrap();
        r.set_seed(seed);
        for &n in splits {
            r.render_samples(n).unwrap();
        }
        let lobes = if accumulate.lobes { Some(r.read_lobes(&gbuffer.coverage).unwrap()) } else { None };
        (r.read_radiance().unwrap(), lobes)
    };
    let (a, _) = render(&[12], 5, Accumulate::default());
    assert_eq!(a, render(&[12], 5, Accumulate::default()).0);
    assert_eq!(a, render(&[1, 4, 7], 5, Accumulate::default()).0);
    assert_ne!(a, render(&[12], 6, Accumulate::default()).0);
    let (with_lobes, lobes) = render(&[5, 7], 5, Accumulate { lobes: true, variance: true });
    assert_eq!(a, with_lobes, "the lobe AOVs changed the beauty");
    let lobes = lobes.unwrap();
    for (i, total) in a.iter().enumerate().filter(|(i, _)| gbuffer.coverage[*i] == 1.0) {
        let sum: f32 = lobes.iter().map(|layer| layer[i][1]).sum();
        assert!((sum - total[1]).abs() <= 1e-4 * total[1].abs().max(1.0), "pixel {i}: lobes {sum} vs {}", total[1]);
    }
    // Bands of rows at their own pace.
    let mut r = renderer(&ctx, &gbuffer, &env, &look, lighting);
    r.set_sampling(Sampling::Product, &env).unwrap();
    r.set_seed(5);
    r.render_rows(0, 10, 12).unwrap();
    r.render_rows(10, 14, 5).unwrap();
    r.render_rows(10, 14, 7).unwrap();
    assert_eq!(a, r.read_radiance().unwrap());
    // And it is another estimator than the compensated one, on the same seed.
    r.set_sampling(Sampling::Compensated, &env).unwrap();
    r.set_seed(5);
    r.render_samples(12).unwrap();
    assert_ne!(a, r.read_radiance().unwrap());
    drop(r);
    common::gpu::finish(ctx);
}

/// Each estimator has its own specialisation of the relight kernel: a renderer switched from
/// one to another, or handed kernels compiled for the other, renders the bits of one built for
/// it (a kernel left with the other's sampler would sample tables that are not there, or not
/// the ones uploaded).
#[test]
fn switching_the_estimator_switches_the_kernel() {
    use lookdev::render::renderer::{KernelSource, Renderer, Specialization};
    let ctx = common::gpu::context();
    let gbuffer = orthographic_sphere(16);
    let env = Builtin::find("studio").unwrap().load();
    let look = one_material(Params { base_color: [0.8, 0.3, 0.1], roughness: 0.7, ..Params::default() });
    let stacks = lookdev::material::stack::PackedStacks::pack(
        &look,
        lookdev::render::scene::covered_object_ids(&gbuffer),
        &gbuffer,
        std::path::Path::new("sphere"),
    )
    .unwrap();
    let render = |r: &mut Renderer| {
        r.set_stacks(&stacks).unwrap();
        r.set_seed(3);
        r.render_samples(6).unwrap();
        r.read_radiance().unwrap()
    };
    let built_for = |sampling: Sampling, product_kernel: bool| {
        let kernels = KernelSource::Compile(Specialization { product: product_kernel, ..Specialization::default() });
        Renderer::with_kernels(&ctx, &gbuffer, &env, sampling, kernels).unwrap()
    };
    let compensated = render(&mut built_for(Sampling::Compensated, false));
    let product = render(&mut built_for(Sampling::Product, true));
    assert_ne!(compensated, product);
    // Kernels compiled for the other estimator are replaced.
    assert_eq!(render(&mut built_for(Sampling::Compensated, true)), compensated);
    assert_eq!(render(&mut built_for(Sampling::Product, false)), product);
    // And so are they when the estimator changes.
    let mut r = built_for(Sampling::Product, true);
    r.set_sampling(Sampling::Compensated, &env).unwrap();
    assert_eq!(render(&mut r), compensated);
    r.set_sampling(Sampling::Product, &env).unwrap();
    assert_eq!(render(&mut r), product);
    drop(r);
    common::gpu::finish(ctx);
}
