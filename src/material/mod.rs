//! Materials: the eleven BRDF parameters, presets, looks and layer stacks.

pub mod library;
pub mod look;
pub mod params;
pub mod preset;
pub mod stack;
mod toml_input;

pub(crate) use toml_input::{near_miss, unknown as unknown_key};

pub use look::Look;
pub use params::{Param, Params, Value};
pub use preset::Preset;
