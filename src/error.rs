//! The one error type of lookdev.
//!
//! Every failure is a single line that names the file (where there is one) and the problem. Bad
//! input exits with code 2, everything else (a GPU or driver failure, an I/O failure while writing)
//! with code 1.

use std::fmt;
use std::path::Path;

/// What went wrong, which decides the exit code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorKind {
    /// A file, flag or value given by the user is wrong. Exit code 2.
    Input,
    /// The Vulkan driver, device or a kernel failed. Exit code 1.
    Gpu,
    /// Reading or writing failed for a reason that is not the input's fault. Exit code 1.
    Io,
    /// `lookdev lint` found implausible values (already printed). Exit code 1.
    Lint,
    /// A defect of lookdev itself: a panic, caught and reported on one line. Exit code 1.
    Internal,
}

/// A one-line, user-facing error.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Error {
    pub kind: ErrorKind,
    pub message: String,
}

pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// Bad input in `file`: the message becomes `FILE: problem`.
    pub fn input_file(file: impl AsRef<Path>, problem: impl fmt::Display) -> Self {
        Error { kind: ErrorKind::Input, message: format!("{}: {}", file.as_ref().display(), problem) }
    }

    /// Bad input that is not tied to a file, such as a command-line flag.
    pub fn input(problem: impl fmt::Display) -> Self {
        Error { kind: ErrorKind::Input, message: problem.to_string() }
    }

    pub fn gpu(problem: impl fmt::Display) -> Self {
        Error { kind: ErrorKind::Gpu, message: problem.to_string() }
    }

    pub fn internal(problem: impl fmt::Display) -> Self {
        Error {
            kind: ErrorKind::Internal,
            message: format!("internal error ({problem}); this is a defect of lookdev, please report it"),
        }
    }

    pub fn lint(summary: impl fmt::Display) -> Self {
        Error { kind: ErrorKind::Lint, message: summary.to_string() }
    }

    pub fn io(file: impl AsRef<Path>, problem: impl fmt::Display) -> Self {
        Error { kind: ErrorKind::Io, message: format!("{}: {}", file.as_ref().display(), problem) }
    }

    /// The process exit code for this error.
    pub fn exit_code(&self) -> i32 {
        match self.kind {
            ErrorKind::Input => 2,
            ErrorKind::Gpu | ErrorKind::Io | ErrorKind::Lint | ErrorKind::Internal => 1,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Keep it to one line, whatever the underlying library printed.
        let one_line: Vec<&str> = self.message.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
        f.write_str(&printable(&one_line.join(" ")))
    }
}

/// A number as messages show it: plainly, or in scientific notation when very large or very
/// small, so that `1e38` is not written out as 39 digits.
pub fn number_text<T: Into<f64> + Copy + fmt::Display + fmt::LowerExp>(x: T) -> String {
    let magnitude = x.into().abs();
    if magnitude != 0.0 && magnitude.is_finite() && !(1e-4..1e6).contains(&magnitude) {
        format!("{x:e}")
    } else {
        x.to_string()
    }
}

/// `text` with every control character escaped (`\x1b`, `\0`, `\u{9b}`), so that names read
/// from files can neither break a message's one line nor send escape sequences to a terminal;
/// and the bidirectional controls too (`\u{202e}`), which would show a name reversed.
pub fn printable(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '\0' => out.push_str("\\0"),
            c if c.is_control() && (c as u32) < 0x80 => out.push_str(&format!("\\x{:02x}", c as u32)),
            c if c.is_control() || is_bidi_control(c) => out.push_str(&format!("\\u{{{:x}}}", c as u32)),
            c => out.push(c),
        }
    }
    out
}

/// The Unicode bidirectional formatting characters: marks, embeddings, overrides and isolates.
fn is_bidi_control(c: char) -> bool {
    matches!(c, '\u{061c}' | '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
}

impl std::error::Error for Error {}

impl From<ash::vk::Result> for Error {
    fn from(result: ash::vk::Result) -> Self {
        Error::gpu(format!("Vulkan call failed: {result}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_as_written() {
        assert_eq!(number_text(1e38), "1e38");
        assert_eq!(number_text(3e38f32), "3e38");
        assert_eq!(number_text(0.25), "0.25");
        assert_eq!(number_text(-100.0f32), "-100");
        assert_eq!(number_text(1e-6), "1e-6");
    }

    #[test]
    fn messages_are_one_line_with_control_characters_escaped() {
        let error = Error::input_file("look.toml", "no preset named '\u{1b}[31mred\0'\nsecond line\u{9b}");
        assert_eq!(error.to_string(), "look.toml: no preset named '\\x1b[31mred\\0' second line\\u{9b}");
        // A right-to-left override would show what follows it reversed.
        assert_eq!(printable("gold\u{202e}lmt.exe"), "gold\\u{202e}lmt.exe");
        assert_eq!(printable("a\u{2066}b\u{200f}"), "a\\u{2066}b\\u{200f}");
        assert_eq!(printable("Käse · 金"), "Käse · 金");
    }
}
