//! The GPU BRDF (glsl/include/brdf.glsl, sampling.glsl) against the Rust reference, through the
//! brdf_probe kernel, and both against the independent reference points.

mod common;

use common::random::Random;
use glam::Vec3;
use lookdev::gpu::{shaders, Binding, BindingKind, Buffer, ComputePipeline, Context};
use lookdev::material::{Param, Params};
use lookdev::shading::brdf::{disney_brdf, make_half_vector, make_lobes, make_view};
use lookdev::shading::sampling::{brdf_pdf, choose_lobes};

/// One probe record, laid out as `Record` in brdf_probe.comp.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Record {
    params: [f32; 16],
    l: [f32; 4],
    v: [f32; 4],
}

fn random_params(rng: &mut Random) -> Params {
    let mut p = Params::default();
    for param in Param::ALL {
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
    let pipeline = ComputePipeline::new(
        ctx,
        &shaders::BRDF_PROBE,
        &[&[BindingKind::StorageBuffer, BindingKind::StorageBuffer]],
        0,
    )
    .unwrap();
    let input = Buffer::with_data(ctx, bytemuck::cast_slice(records)).unwrap();
    let output = Buffer::storage(ctx, (records.len() * 16) as u64).unwrap();
    let set = pipeline.bind(0, &[Binding::Buffer(&input), Binding::Buffer(&output)]).unwrap();
    ctx.run(|cmd| {
        pipeline.dispatch(cmd, &[&set], &[], [(records.len() as u32).div_ceil(64), 1, 1]);
        Ok(())
    })
    .unwrap();
    bytemuck::cast_slice(&output.read(ctx).unwrap()).to_vec()
}

fn relative_error(gpu: f32, cpu: f32) -> f32 {
    (gpu - cpu).abs() / cpu.abs()
}

#[test]
fn gpu_brdf_and_pdf_match_the_rust_reference() {
    let ctx = common::gpu::context();
    let mut rng = Random::new(7);
    let mut records = Vec::new();
    let mut params = Vec::new();
    for _ in 0..8192 {
        let p = random_params(&mut rng);
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
        records.push(Record { params: p.to_gpu(), l: l.extend(0.0).to_array(), v: v.extend(0.0).to_array() });
        params.push(p);
    }
    let results = probe(&ctx, &records);
    let (mut compared, mut worst) = (0, 0.0f32);
    for (i, (record, result)) in records.iter().zip(&results).enumerate() {
        let lobes = make_lobes(&params[i]);
        let l = Vec3::from_slice(&record.l[..3]);
        let v = Vec3::from_slice(&record.v[..3]);
        let view = make_view(&lobes, v);
        let hv = make_half_vector(&lobes, l, v);
        let f = disney_brdf(&lobes, &view, l, &hv);
        let pdf = if v.z > 0.0 { brdf_pdf(&choose_lobes(&lobes, &view), &view, l, &hv) } else { 0.0 };
        for (c, (&gpu, cpu)) in result.iter().zip([f.x, f.y, f.z, pdf]).enumerate() {
            assert!(gpu.is_finite(), "record {i} channel {c}: GPU gave {gpu}");
            if cpu > 1e-4 {
                let err = relative_error(gpu, cpu);
                worst = worst.max(err);
                compared += 1;
                assert!(err <= 1e-4, "record {i} channel {c}: GPU {gpu} vs CPU {cpu} ({:?}, l {l}, v {v})", params[i]);
            } else {
                assert!(gpu.abs() <= 2e-4, "record {i} channel {c}: GPU {gpu} vs CPU {cpu}");
            }
        }
    }
    assert!(compared > 20_000, "only {compared} values were large enough to compare");
    eprintln!("{compared} values compared, worst relative error {worst:e}");
    common::gpu::finish(ctx);
}

#[test]
fn gpu_brdf_matches_the_reference_points() {
    let ctx = common::gpu::context();
    let data = common::reference::load();
    let points = data["point"].as_array().unwrap();
    let records: Vec<Record> = points
        .iter()
        .map(|p| Record {
            params: common::reference::params(p).to_gpu(),
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
