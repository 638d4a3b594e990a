//! Reading a g-buffer file: OpenEXR decoding (`source::raw`), the source's translation into
//! lookdev's channels (`source`), then validation (`validate`).

use std::path::Path;

use super::source::occluders::Occluders;
use super::source::{self, Detected, SourceOptions, Surfaces};
use super::validate;
use super::GBuffer;
use crate::input::{self, Kind};
use crate::visibility::{default_side, Grid};
use crate::{Error, Result};

/// A g-buffer as read: the validated buffer, what its file was detected as, and the fix-up and
/// translation warnings (one line each, naming the file).
pub struct Read {
    pub gbuffer: GBuffer,
    pub detected: Detected,
    pub warnings: Vec<String>,
}

impl GBuffer {
    /// Reads and validates a g-buffer file of any source, detected from its channels, printing
    /// the warnings to stderr.
    pub fn read(path: &Path) -> Result<GBuffer> {
        let read = GBuffer::read_with(path, &SourceOptions::default())?;
        read.warnings.into_iter().for_each(crate::warn);
        Ok(read.gbuffer)
    }

    /// Like [`GBuffer::read`], but returns the warnings instead of printing them.
    pub fn read_with_warnings(path: &Path) -> Result<(GBuffer, Vec<String>)> {
        GBuffer::read_with(path, &SourceOptions::default()).map(|read| (read.gbuffer, read.warnings))
    }

    /// Reads a g-buffer file as `options` say, returning the warnings rather than printing them.
    /// See the module documentation for the format, the sources, the errors and the fix-ups.
    /// A production render with world positions and occluders (`options.occluders`, else the
    /// file the header's note names) and no stored visibility gets one traced through them
    /// ([`crate::visibility::occluders`]).
    pub fn read_with(path: &Path, options: &SourceOptions) -> Result<Read> {
        GBuffer::read_reporting(path, options, &|_, _| {})
    }

    /// [`GBuffer::read_with`], calling `progress(done, total)` while it traces visibility.
    pub fn read_reporting(
        path: &Path,
        options: &SourceOptions,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<Read> {
        let (mut read, surfaces) = decode(&input::read(path, Kind::GBuffer)?, path, options)?;
        if options.no_visibility {
            read.gbuffer.visibility = None;
            return Ok(read);
        }
        let occluders = match &options.occluders {
            Some(file) => Some(Occluders { file: file.clone(), side: None, from: "--occluders".into() }),
            None => surfaces.occluders,
        };
        let Some(occluders) = occluders else { return Ok(read) };
        if read.gbuffer.visibility.is_some() {
            read.warnings.push(format!(
                "{}: it stores its visibility, so the occluders from {} are not traced",
                path.display(),
                occluders.from
            ));
            return Ok(read);
        }
        let Some(positions) = surfaces.positions else {
            return Err(Error::input_file(
                path,
                format!(
                    "occluders from {} need world positions to trace from, and the file has no P or Position layer",
                    occluders.from
                ),
            ));
        };
        let side = occluders.side.unwrap_or_else(|| default_side(read.gbuffer.pixel_count()));
        let grid = Grid::new(side).map_err(Error::input)?;
        let traced =
            crate::visibility::occluders::trace_positions(&read.gbuffer, path, &positions, &occluders, grid, progress)?;
        read.gbuffer.visibility = Some(traced.visibility);
        read.detected.from.push(("visibility".into(), traced.how));
        read.warnings.extend(traced.warnings);
        Ok(read)
    }

    /// Decodes and validates the bytes of a g-buffer file; `path` names it in messages. Needs
    /// no GPU and touches no file.
    pub fn decode(bytes: &[u8], path: &Path) -> Result<(GBuffer, Vec<String>)> {
        GBuffer::decode_with(bytes, path, &SourceOptions::default()).map(|read| (read.gbuffer, read.warnings))
    }

    /// [`GBuffer::decode`], as `options` say.
    pub fn decode_with(bytes: &[u8], path: &Path, options: &SourceOptions) -> Result<Read> {
        decode(bytes, path, options).map(|(read, _)| read)
    }
}

/// A g-buffer decoded and validated, with what its file offers for tracing visibility.
fn decode(bytes: &[u8], path: &Path, options: &SourceOptions) -> Result<(Read, Surfaces)> {
    let file = source::raw::decode(bytes, path)?;
    let (mut raw, detected, mut warnings) = source::translate(file, options, path)?;
    let surfaces = std::mem::take(&mut raw.surfaces);
    let (gbuffer, fixes) = validate::build(path, raw)?;
    warnings.extend(fixes);
    Ok((Read { gbuffer, detected, warnings }, surfaces))
}
