//! The CPU reference of the shading code: each file mirrors one GLSL include, function by
//! function, so the two can be compared by eye and by the probe tests.
//!
//! | Rust                     | GLSL                                   |
//! |--------------------------|----------------------------------------|
//! | `common.rs`              | `glsl/include/common.glsl`             |
//! | `model.rs`               | `glsl/include/model.glsl`              |
//! | `material.rs`            | `glsl/include/material.glsl`           |
//! | `brdf.rs`                | `glsl/include/brdf.glsl` (the energy table and its lookup included) |
//! | `sampling.rs`            | `glsl/include/sampling.glsl`           |
//! | `sobol.rs`               | `glsl/include/sobol.glsl`              |
//! | `tonemap.rs`             | `glsl/include/tonemap.glsl`            |
//! | `frame.rs`               | the frame set-up in `glsl/relight.comp` |
//! | `energy.rs`              | `glsl/energy_table.comp` (the table's builder) |
//! | `crate::environment::sampling` | `glsl/include/environment.glsl`  |
//! | `crate::asset::bake`'s `DrawConstants`, `GpuMaterial` | `glsl/include/bake_draw.glsl`, `bake_material.glsl` |
//!
//! Imports run one way: `brdf` takes `common`, `model` and `material`; `sampling` takes
//! `common`, `model` and `brdf`; `energy`, the table's builder, takes `brdf` and `sampling`.
//! Nothing here imports `crate::material`, `crate::render` or any module above them: parameters
//! arrive as a [`material::Material`], converted by `crate::material` (`From<&Params>`).
//! `tests/layering.rs` holds these rules.

pub mod brdf;
pub mod common;
pub mod energy;
pub mod frame;
pub mod material;
pub mod model;
pub mod sampling;
pub mod sobol;
pub mod tonemap;
