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
