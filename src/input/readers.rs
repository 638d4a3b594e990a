//! Every reader of hostile input, as one function of bytes: what the fuzz suite
//! (`tests/fuzz.rs`) and the `cargo fuzz` targets (`fuzz/`) drive. Each reads the bytes as the
//! file at `path` would be read, as far as it goes without a GPU, and touches no other file
//! (a look's preset names resolve to the built-in presets when `path`'s folder has none).

use crate::asset::{camera, geometry, import::Import, Asset, Texels};
use crate::environment::load::{from_exr_bytes, from_hdr_bytes, LoadOptions};
use crate::gbuffer::GBuffer;
use crate::material::{Look, Preset};
use crate::Result;
use std::path::Path;

/// The kinds of input lookdev reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reader {
    Look,
    Preset,
    GBuffer,
    /// An OpenEXR environment.
    ExrEnvironment,
    /// A Radiance `.hdr` environment.
    HdrEnvironment,
    /// A glTF asset: reading and checking, its world-space triangles, the camera and the
    /// material mapping, everything the bake and the import do on the CPU.
    Gltf,
    /// A command line, one argument per line.
    CommandLine,
}

impl Reader {
    pub const ALL: [Reader; 7] = [
        Reader::Look,
        Reader::Preset,
        Reader::GBuffer,
        Reader::ExrEnvironment,
        Reader::HdrEnvironment,
        Reader::Gltf,
        Reader::CommandLine,
    ];

    /// Reads `bytes` as this kind of input, named `path` in messages.
    pub fn read(self, bytes: &[u8], path: &Path) -> Result<()> {
        let name = path.display().to_string();
        match self {
            Reader::Look => Look::parse(&String::from_utf8_lossy(bytes), path).map(drop),
            Reader::Preset => Preset::parse(&String::from_utf8_lossy(bytes), path).map(drop),
            Reader::GBuffer => GBuffer::decode(bytes, path).map(drop),
            Reader::ExrEnvironment => {
                from_exr_bytes(bytes, &name, &LoadOptions { any_aspect: true, ..Default::default() }).map(drop)
            }
            Reader::HdrEnvironment => {
                from_hdr_bytes(bytes, &name, &LoadOptions { any_aspect: true, ..Default::default() }).map(drop)
            }
            Reader::Gltf => {
                let asset = Asset::from_bytes(bytes, path, Texels::Decode)?;
                let geometry = geometry::flatten(&asset, |_, _| {})?;
                camera::choose(&asset, &camera::CameraChoice::Default, geometry.bounds, 64, 48)?;
                Import::new(&asset).map(drop)
            }
            Reader::CommandLine => {
                let args = std::iter::once("lookdev".into()).chain(bytes.split(|&b| b == b'\n').map(os_string));
                crate::cli::parse(args).map(drop)
            }
        }
    }
}

#[cfg(unix)]
fn os_string(bytes: &[u8]) -> std::ffi::OsString {
    use std::os::unix::ffi::OsStrExt;
    std::ffi::OsStr::from_bytes(bytes).to_os_string()
}

#[cfg(not(unix))]
fn os_string(bytes: &[u8]) -> std::ffi::OsString {
    String::from_utf8_lossy(bytes).into_owned().into()
}
