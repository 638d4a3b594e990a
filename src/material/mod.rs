//! Materials: the eleven BRDF parameters, presets, looks and layer stacks.

pub mod params;

pub use params::{Param, Params, Value};
