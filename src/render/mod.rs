//! Rendering: parameter resolve, progressive relighting, accumulation and display transforms.

pub mod aov;
pub mod batch;
pub mod compare;
pub mod downsample;
pub mod energy;
pub mod output;
pub mod passes;
pub mod progressive;
pub mod provenance;
pub mod renderer;
pub mod sampling;
pub mod scene;
pub mod settings;
pub mod sheet;
pub mod startup;

pub use renderer::{Lighting, Renderer};
