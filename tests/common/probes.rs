//! The test kernels' interfaces: `brdf_probe.comp` and `sample_probe.comp`, with the records
//! they read.

use lookdev::environment;
use lookdev::gpu::{shaders, BindingKind, GlslLayout, Interface};

/// One probe record, laid out as `Record` in brdf_probe.comp.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Record {
    pub params: [f32; 16],
    pub l: [f32; 4],
    pub v: [f32; 4],
}

lookdev::glsl_struct!(Record as "Record", 96 bytes { params @ 0, l @ 64, v @ 80 });

/// brdf_probe.comp: the records, the results and the energy table.
pub const BRDF_PROBE: Interface = Interface {
    structs: &[Record::GLSL],
    ..Interface::compute(&shaders::BRDF_PROBE, &[&[BindingKind::StorageBuffer; 3]], None)
};

/// `Setup` of sample_probe.comp: the material, the view, the routine and its seed.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Setup {
    pub params: [f32; 16],
    pub view: [f32; 4],
    pub routine: u32,
    pub seed: u32,
    pub pad: [u32; 2],
}

lookdev::glsl_struct!(Setup as "Setup", 96 bytes { params @ 0, view @ 64, routine @ 80, seed @ 84, pad @ 88 });

/// sample_probe.comp: setup, uniforms, samples and the energy table, then the environment.
pub const SAMPLE_PROBE: Interface = Interface {
    structs: &[Setup::GLSL],
    ..Interface::compute(
        &shaders::SAMPLE_PROBE,
        &[&[BindingKind::StorageBuffer; 4], &environment::gpu::SET_LAYOUT],
        None,
    )
};

/// Environment samples drawn on the GPU by sample_probe.comp's routine `routine` (with `seed`
/// and the view's w as it reads them) from the uniform points `u`, under `env` as uploaded:
/// (direction, pdf the sampler reports, or −1 where the pdf looked up from the direction
/// disagrees).
pub fn environment_samples(
    ctx: &lookdev::gpu::Context,
    env: &environment::GpuEnvironment,
    routine: u32,
    seed: u32,
    view_w: f32,
    u: &[glam::Vec2],
) -> Vec<(glam::Vec3, f32)> {
    use lookdev::gpu::{Binding, Buffer, ComputePipeline};
    let model = lookdev::shading::model::Model::default();
    let pipeline = ComputePipeline::specialized(
        ctx,
        &shaders::SAMPLE_PROBE,
        SAMPLE_PROBE.sets,
        SAMPLE_PROBE.push_size(),
        &model.specialization(),
    )
    .unwrap();
    let (energy, _) = super::gpu::model_shading(ctx, &model);
    let params = lookdev::material::Params::default().brdf_gpu();
    let setup = Setup { params, view: [0.0, 0.0, 1.0, view_w], routine, seed, pad: [0; 2] };
    let setup = Buffer::with_data(ctx, bytemuck::bytes_of(&setup)).unwrap();
    let flat: Vec<f32> = u.iter().flat_map(|u| [u.x, u.y]).collect();
    let uniforms = Buffer::with_data(ctx, bytemuck::cast_slice(&flat)).unwrap();
    let output = Buffer::storage(ctx, u.len() as u64 * 16).unwrap();
    let set0 = pipeline
        .bind(
            0,
            &[Binding::Buffer(&setup), Binding::Buffer(&uniforms), Binding::Buffer(&output), Binding::Buffer(&energy)],
        )
        .unwrap();
    let set1 = pipeline.bind(1, &env.bindings()).unwrap();
    ctx.run(|cmd| {
        pipeline.dispatch(cmd, &[&set0, &set1], &[], [(u.len() as u32).div_ceil(64), 1, 1]);
        Ok(())
    })
    .unwrap();
    let values: Vec<[f32; 4]> = bytemuck::cast_slice(&output.read(ctx).unwrap()).to_vec();
    values.iter().map(|v| (glam::Vec3::new(v[0], v[1], v[2]), v[3])).collect()
}
