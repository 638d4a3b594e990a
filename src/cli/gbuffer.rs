//! `lookdev gbuffer`.

use crate::gbuffer::GBuffer;
use crate::{Error, Result};
use clap::{Args, ValueEnum};
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum Builtin {
    /// A shader ball on a pedestal, with stripe, grunge and gradient masks.
    Shaderball,
    /// A unit sphere under an orthographic camera, filling most of the frame.
    Sphere,
}

#[derive(Args, Debug)]
pub struct GbufferArgs {
    /// Which built-in scene to write.
    #[arg(long, value_enum)]
    pub builtin: Builtin,
    /// Width and height in pixels.
    #[arg(long, num_args = 2, value_names = ["W", "H"], default_values_t = [1024, 1024])]
    pub size: Vec<u32>,
    #[arg(long, value_name = "FILE.exr")]
    pub out: PathBuf,
}

/// The largest side accepted: beyond every device's image limit, and a 2 GiB g-buffer.
const MAX_SIDE: u32 = 16384;

pub fn run(args: GbufferArgs) -> Result<()> {
    let (width, height) = (args.size[0], args.size[1]);
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(Error::input(format!("--size {width} {height}: each side must be 1 to {MAX_SIDE} pixels")));
    }
    if !args.out.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) {
        return Err(Error::input_file(&args.out, "a g-buffer is written as an .exr file"));
    }
    let gbuffer = match args.builtin {
        Builtin::Shaderball => GBuffer::shaderball(width, height),
        Builtin::Sphere => GBuffer::sphere(width, height),
    };
    gbuffer.write(&args.out)
}
