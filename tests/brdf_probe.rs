//! The GPU BRDF (glsl/include/brdf.glsl, sampling.glsl) against the Rust reference, through the
//! brdf_probe kernel, and both against the independent reference points.

mod common;

use common::probes::{self, Record};
use common::random::Random;
use glam::Vec3;
use lookdev::gpu::{shaders, Binding, Buffer, ComputePipeline, Context};
use lookdev::material::{Param, Params};
use lookdev::shading::brdf::{disney_brdf, make_half_vector, make_lobes_with, make_view, Shading};
use lookdev::shading::model::{Diffuse, Model};
use lookdev::shading::sampling::{brdf_pdf, choose_lobes};

fn random_params(rng: &mut Random) -> Params {
    let mut p = Params::default();
    // Emission is no part of the BRDF, which is all the probe evaluates.
    for param in Param::ALL.into_iter().filter(|&p| p != Param::Emission) {
        // A quarter of the draws sit exactly on the ends of the range, where edge cases live.
        let draw = |rng: &mut Random| match rng.next_u32() % 8 {
            0 => 0.0,
            1 => param.max(),
            _ => rng.uniform() * param.max(),
        };
        let value = if param.is_color() {
            lookdev::material::Value::Color([draw(rng), draw(rng), draw(rng)])
        } else {
            lookdev::material::Value::Scalar(draw(rng))
        };
        p.set(param, value).unwrap();
    }
    p
}

fn probe(ctx: &Context, records: &[Record]) -> Vec<[f32; 4]> {
    probe_model(ctx, &Model::default(), records).0
}

/// Runs the probe specialized for `model`; also gives the shading the Rust reference needs.
fn probe_model(ctx: &Context, model: &Model, records: &[Record]) -> (Vec<[f32; 4]>, Shading) {
    let pipeline = ComputePipeline::specialized(
        ctx,
        &shaders::BRDF_PROBE,
        probes::BRDF_PROBE.sets,
        probes::BRDF_PROBE.push_size(),
        &model.specialization(),
    )
    .unwrap();
    let (energy, shading) = common::gpu::model_shading(ctx, model);
    let input = Buffer::with_data(ctx, bytemuck::cast_slice(records)).unwrap();
    let output = Buffer::storage(ctx, (records.len() * 16) as u64).unwrap();
    let set = pipeline.bind(0, &[Binding::Buffer(&input), Binding::Buffer(&output), Binding::Buffer(&energy)]).unwrap();
    ctx.run(|cmd| {
        pipeline.dispatch(cmd, &[&set], &[], [(records.len() as u32).div_ceil(64), 1, 1]);
        Ok(())
    })
    .unwrap();
    (bytemuck::cast_slice(&output.read(ctx).unwrap()).to_vec(), shading)
}

fn relative_error(gpu: f32, cpu: f32) -> f32 {
    (gpu - cpu).abs() / cpu.abs()
}

/// Every model variant the probe checks: the default, each diffuse model, each D, G and F, and
/// energy compensation with two distributions.
fn models() -> Vec<Model> {
    let mut out = vec![Model::default()];
    for text in [
        "diffuse=lambert",
        "diffuse=frostbite",
        "diffuse=oren-nayar",
        "diffuse=oren-nayar-qualitative",
        "diffuse=oren-nayar-fujii",
        "diffuse=gotanda",
        "diffuse=hammon",
        "specular_d=beckmann",
        "specular_d=gtr,gtr_gamma=1.5",
        "specular_d=gtr,gtr_gamma=3",
        "specular_g=smith-height-correlated",
        "specular_g=burley2012",
        "specular_d=beckmann,specular_g=smith-height-correlated",
        "fresnel=dielectric",
        "fresnel=conductor",
        "energy_compensation=true",
        "energy_compensation=true,specular_d=beckmann,specular_g=smith-height-correlated,fresnel=conductor",
    ] {
        let mut model = Model::default();
        for part in text.split(',') {
            model.set_from_text(part).unwrap();
        }
        out.push(model);
    }
    out
}

#[test]
fn gpu_brdf_and_pdf_match_the_rust_reference() {
    let ctx = common::gpu::context();
    for model in models() {
        check_model(&ctx, &model);
    }
    common::gpu::finish(ctx);
}

fn check_model(ctx: &Context, model: &Model) {
    let mut rng = Random::new(7);
    let mut records = Vec::new();
    let mut params = Vec::new();
    for _ in 0..8192 {
        let mut p = random_params(&mut rng);
        if rng.next_u32() % 2 == 0 {
            p.ior_edge = [rng.uniform(), rng.uniform(), rng.uniform()];
        }
        // Mostly the upper hemisphere; some below it to check the zero branch and the pdf of
        // directions below the horizon.
        let mut l = rng.direction();
        let mut v = rng.direction();
        if rng.next_u32() % 8 != 0 {
            l.z = l.z.abs();
        }
        if rng.next_u32() % 16 != 0 {
            v.z = v.z.abs();
        }
        records.push(Record { params: p.brdf_gpu(), l: l.extend(0.0).to_array(), v: v.extend(0.0).to_array() });
        params.push(p);
    }
    let (results, shading) = probe_model(ctx, model, &records);
    // lavapipe's acos is good to about 1e-4 relative, and the full Oren–Nayar model needs the
    // angles themselves; the energy table's bilinear lookup at grazing amplifies rounding of its
    // √μ coordinate. Everything else is within the default model's tolerance.
    // Near roughness 0 the compensation is a ratio of differences 1 − E of values E close to 1, so
    // it is compared to an absolute 1e-5 as well.
    let tolerance = if model.diffuse == Diffuse::OrenNayar || model.energy_compensation { 1e-3 } else { 1e-4 };
    let absolute = if model.energy_compensation { 1e-5 } else { 0.0 };
    let (mut compared, mut worst) = (0, 0.0f32);
    for (i, (record, result)) in records.iter().zip(&results).enumerate() {
        let lobes = make_lobes_with(&params[i], &shading);
        let l = Vec3::from_slice(&record.l[..3]);
        let v = Vec3::from_slice(&record.v[..3]);
        let view = make_view(&lobes, v);
        let hv = make_half_vector(&lobes, l, v);
        let f = disney_brdf(&lobes, &view, l, &hv);
        let pdf = if v.z > 0.0 { brdf_pdf(&choose_lobes(&lobes, &view), &view, l, &hv) } else { 0.0 };
        for (c, (&gpu, cpu)) in result.iter().zip([f.x, f.y, f.z, pdf]).enumerate() {
            assert!(gpu.is_finite(), "{model}: record {i} channel {c}: GPU gave {gpu}");
            if cpu > 1e-4 {
                let err = relative_error(gpu, cpu);
                compared += 1;
                if (gpu - cpu).abs() <= absolute {
                    continue;
                }
                // At grazing, 1 − E(μ) of a nearly smooth surface is a small difference of table
                // values, and the GPU's rounding of √μ shows in it.
                let grazing = model.energy_compensation && l.z.min(v.z) < 1e-2;
                worst = worst.max(err);
                assert!(
                    err <= if grazing { 1e-2 } else { tolerance },
                    "{model}: record {i} channel {c}: GPU {gpu} vs CPU {cpu} ({:?}, l {l}, v {v})",
                    params[i]
                );
            } else {
                assert!(gpu.abs() <= 2e-4, "{model}: record {i} channel {c}: GPU {gpu} vs CPU {cpu}");
            }
        }
    }
    assert!(compared > 20_000, "{model}: only {compared} values were large enough to compare");
    eprintln!("{model}: {compared} values compared, worst relative error {worst:e}");
}

#[test]
fn gpu_brdf_matches_the_reference_points() {
    let ctx = common::gpu::context();
    let data = common::reference::load();
    let points = data["point"].as_array().unwrap();
    let records: Vec<Record> = points
        .iter()
        .map(|p| Record {
            params: common::reference::params(p).brdf_gpu(),
            l: common::reference::direction(&p["light"]).extend(0.0).to_array(),
            v: common::reference::direction(&p["view"]).extend(0.0).to_array(),
        })
        .collect();
    let results = probe(&ctx, &records);
    for (point, result) in points.iter().zip(&results) {
        let expected = common::reference::vec3(&point["f"]);
        for c in 0..3 {
            assert!(
                relative_error(result[c], expected[c]) < 1e-4,
                "{}: {} vs {}",
                point["name"],
                result[c],
                expected[c]
            );
        }
    }
    common::gpu::finish(ctx);
}
