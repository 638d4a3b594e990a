//! Materials: the eleven BRDF parameters, presets, looks and layer stacks.

pub mod library;
pub mod look;
pub mod mask;
pub mod params;
pub mod physical;
pub mod preset;
pub mod stack;
pub(crate) mod toml_input;

pub use look::Look;
pub use params::{Param, Params, Value};
pub use preset::Preset;
