//! The CPU reference of the shading code: each file mirrors one GLSL include, function by
//! function, so the two can be compared by eye and by the probe tests.
//!
//! | Rust            | GLSL                          |
//! |-----------------|-------------------------------|
//! | `common.rs`     | `glsl/include/common.glsl`    |
//! | `model.rs`      | `glsl/include/model.glsl`     |
//! | `brdf.rs`       | `glsl/include/brdf.glsl`      |
//! | `sampling.rs`   | `glsl/include/sampling.glsl`  |
//! | `sobol.rs`      | `glsl/include/sobol.glsl`     |
//! | `frame.rs`      | the frame set-up in `glsl/relight.comp` |
//! | `energy.rs`     | `glsl/energy_table.comp`      |

pub mod brdf;
pub mod common;
pub mod energy;
pub mod frame;
pub mod model;
pub mod sampling;
pub mod sobol;
