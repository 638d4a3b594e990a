//! lookdev: a Vulkan compute look-dev relighter.
//!
//! Data flows one way: files are read into validated Rust types ([`gbuffer`], [`environment`],
//! [`material`]), uploaded to the GPU ([`gpu`]), relit by compute kernels ([`render`]) and written
//! out as images. [`viewer_state`] is the document the interactive viewer edits, with undo and
//! saving; it needs no GPU. `viewer` (the default `viewer` feature) is the window around it.

pub mod asset;
pub mod atomic_file;
pub mod cache;
pub mod cli;
pub mod config;
pub mod environment;
pub mod error;
pub mod gbuffer;
pub mod gpu;
pub mod input;
pub mod lab;
pub mod material;
pub mod render;
pub mod shading;
pub mod suggest;
pub mod timings;
#[cfg(feature = "viewer")]
pub mod viewer;
pub mod viewer_state;
pub mod visibility;

pub use error::{number_text, printable, Error, ErrorKind, Result};

/// Prints a non-fatal warning to stderr, in the same one-line style as errors.
pub fn warn(message: impl std::fmt::Display) {
    eprintln!("lookdev: warning: {}", printable(&message.to_string()));
}
