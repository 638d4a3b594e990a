//! Rendering: parameter resolve, progressive relighting, accumulation and display transforms.

pub mod tonemap;
