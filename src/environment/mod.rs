//! Environments: equirectangular radiance maps (docs/formats.md#environments), their importance-sampling tables,
//! and their GPU form.
//!
//! Convention: row 0 is the zenith (+Y). A unit direction d maps to
//! `u = 0.5 + atan2(d.x, −d.z)/2π` (wrapped into [0, 1)) and `v = acos(d.y)/π`, so the image
//! centre is −Z and u = 0.75 is +X. A rotation of `r` degrees turns the environment about +Y:
//! lookups use `R_y(−r)·d`.

pub mod backdrop;
pub mod builtin;
pub mod cache;
pub mod distribution;
pub mod gpu;
pub mod library;
pub mod load;
pub mod product;
pub mod sampling;

pub use backdrop::Backdrop;
pub use builtin::{Builtin, EnvironmentRef};
pub use distribution::Distribution;
pub use gpu::{GpuEnvironment, Samplers};
pub use load::LoadOptions;

/// The brightest texel an environment may hold. With [`MAX_INTENSITY`], radiance stays below
/// 1e24: far above any real light (the sun's disc is about 1e9 in the units of a typical HDRI),
/// yet low enough that every sum and ratio the sampler and the accumulation form stays finite in
/// 32-bit floats, so finite inputs never render infinite pixels.
pub const MAX_TEXEL: f32 = 1e18;

/// The largest environment intensity: room for maps stored in any units.
pub const MAX_INTENSITY: f32 = 1e6;

/// Checks an intensity (from a look, a flag or the viewer); the message starts with the value.
pub fn check_intensity(intensity: f32) -> Result<(), String> {
    if intensity.is_finite() && (0.0..=MAX_INTENSITY).contains(&intensity) {
        Ok(())
    } else {
        Err(format!("intensity {} must be a number from 0 to {MAX_INTENSITY:e}", crate::number_text(intensity)))
    }
}

/// A validated equirectangular radiance map: finite, non-negative, at most [`MAX_TEXEL`], linear
/// Rec.709.
#[derive(Clone, Debug)]
pub struct Environment {
    pub width: u32,
    pub height: u32,
    /// RGB radiance, row 0 = zenith.
    pub texels: Vec<[f32; 3]>,
    /// Where it came from, for messages: a path, or "built-in studio".
    pub source: String,
    /// FNV-1a (64-bit) of the file's bytes (of its texels, for one made in memory), recorded in
    /// renders' metadata so that a render names the exact map that lit it. It stands for the
    /// texels: the sampling tables' cache is keyed by it, so texels are never changed after.
    pub content_hash: u64,
}

/// FNV-1a, 64-bit: small, stable across versions and platforms.
pub fn content_hash(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |hash, &b| (hash ^ b as u64).wrapping_mul(0x0100_0000_01b3))
}

impl Environment {
    /// An environment of these texels (already valid), its hash from them.
    pub fn new(width: u32, height: u32, texels: Vec<[f32; 3]>, source: impl Into<String>) -> Environment {
        let content_hash = content_hash(bytemuck::cast_slice(&texels));
        Environment { width, height, texels, source: source.into(), content_hash }
    }

    /// The built-in studio environment.
    pub fn studio() -> Environment {
        Builtin::find("studio").expect("studio is built in").load()
    }

    /// The default environment: the one a look that names none is lit by.
    pub fn default_builtin() -> Environment {
        Builtin::default_one().load()
    }

    /// A constant environment, as used by furnace tests.
    pub fn uniform(radiance: [f32; 3], width: u32, height: u32) -> Environment {
        Environment::new(width, height, vec![radiance; (width * height) as usize], format!("uniform {radiance:?}"))
    }

    pub fn texel(&self, x: u32, y: u32) -> [f32; 3] {
        self.texels[(y * self.width + x) as usize]
    }
}
