//! Reading a g-buffer file: OpenEXR decoding (`source::raw`), the source's translation into
//! lookdev's channels (`source`), then validation (`validate`).

use std::path::Path;

use super::source::{self, Detected, SourceOptions};
use super::validate;
use super::GBuffer;
use crate::input::{self, Kind};
use crate::Result;

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
    pub fn read_with(path: &Path, options: &SourceOptions) -> Result<Read> {
        GBuffer::decode_with(&input::read(path, Kind::GBuffer)?, path, options)
    }

    /// Decodes and validates the bytes of a g-buffer file; `path` names it in messages. Needs
    /// no GPU and touches no file.
    pub fn decode(bytes: &[u8], path: &Path) -> Result<(GBuffer, Vec<String>)> {
        GBuffer::decode_with(bytes, path, &SourceOptions::default()).map(|read| (read.gbuffer, read.warnings))
    }

    /// [`GBuffer::decode`], as `options` say.
    pub fn decode_with(bytes: &[u8], path: &Path, options: &SourceOptions) -> Result<Read> {
        let file = source::raw::decode(bytes, path)?;
        let (raw, detected, mut warnings) = source::translate(file, options, path)?;
        let (gbuffer, fixes) = validate::build(path, raw)?;
        warnings.extend(fixes);
        Ok(Read { gbuffer, detected, warnings })
    }
}
