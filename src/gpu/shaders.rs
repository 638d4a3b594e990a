//! The compute kernels and the bake's graphics shaders, compiled from `glsl/` and committed in
//! `spirv/`, so that a clean checkout builds without a shader compiler. `tests/spirv.rs` checks
//! that the committed SPIR-V is current.

/// One compute kernel's SPIR-V.
pub struct Kernel {
    pub name: &'static str,
    /// `<name>.comp`, in `glsl/`.
    pub file: &'static str,
    pub spirv: &'static [u8],
}

macro_rules! kernel {
    ($name:literal) => {
        Kernel {
            name: $name,
            file: concat!($name, ".comp"),
            spirv: include_bytes!(concat!("../../spirv/", $name, ".comp.spv")),
        }
    };
}

/// Resolves layer stacks into one material per pixel.
pub const RESOLVE: Kernel = kernel!("resolve");
/// One progressive pass of MIS image-based lighting.
pub const RELIGHT: Kernel = kernel!("relight");
/// `relight.comp` specialised to write backgrounds only (`BACKGROUND_ONLY`), under a name of its
/// own in timings and errors, so that a compile of the relight kernel proper counts as one.
pub const RELIGHT_BACKGROUND: Kernel = Kernel { name: "relight-background", ..RELIGHT };
/// Mean, composite over the background, and display pixels (exposure, tone map, sRGB).
pub const FINALIZE: Kernel = kernel!("finalize");
/// BRDF and pdf evaluation for the GPU-against-CPU tests.
pub const BRDF_PROBE: Kernel = kernel!("brdf_probe");
/// Sampling routines and the Sobol sequence, for the chi-square and sequence tests.
pub const SAMPLE_PROBE: Kernel = kernel!("sample_probe");

/// The energy-compensation table of a BRDF model.
pub const ENERGY_TABLE: Kernel = kernel!("energy_table");

/// The viewer's display filter: one iteration of an edge-avoiding à-trous wavelet filter.
pub const DENOISE: Kernel = kernel!("denoise");

/// Every kernel, with the GLSL file it is compiled from (`glsl/<name>.comp`).
pub const ALL: [&Kernel; 7] = [&RESOLVE, &RELIGHT, &FINALIZE, &BRDF_PROBE, &SAMPLE_PROBE, &ENERGY_TABLE, &DENOISE];

/// One graphics shader stage's SPIR-V, compiled from `glsl/<file>`.
pub struct Stage {
    pub file: &'static str,
    pub spirv: &'static [u8],
}

macro_rules! stage {
    ($file:literal) => {
        Stage { file: $file, spirv: include_bytes!(concat!("../../spirv/", $file, ".spv")) }
    };
}

/// The bake's vertex stage: world-space vertices to clip space.
pub const BAKE_VERTEX: Stage = stage!("bake.vert");
/// The bake's geometry pass: one g-buffer sample of the nearest surface.
pub const BAKE_FRAGMENT: Stage = stage!("bake.frag");
/// The bake's maps pass: the same surfaces' textures as parameter maps.
pub const BAKE_MAPS_FRAGMENT: Stage = stage!("bake_maps.frag");

/// Every graphics stage.
pub const STAGES: [&Stage; 3] = [&BAKE_VERTEX, &BAKE_FRAGMENT, &BAKE_MAPS_FRAGMENT];
