//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod albedo;
pub mod blender;
pub mod cli;
pub mod display;
pub mod gltf;
pub mod golden;
pub mod gpu;
pub mod probes;
pub mod random;
pub mod reference;
pub mod reference_render;
pub mod scenes;
pub mod stats;
pub mod viewer;
