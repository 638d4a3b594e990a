//! Reading the user's TOML files (looks and presets) with errors that point at a line.
//!
//! Every error is one line, `FILE:LINE: problem`, and names the key. The `toml` crate parses the
//! text and `serde` maps it onto structs that deny unknown keys. Leaf values arrive as
//! `Spanned<toml::Value>` and are converted here rather than by serde, for two reasons: serde's
//! type errors do not name the key, and `toml` happily accepts `nan` and `inf`, which no lookdev
//! value may be.

use std::fmt::Display;
use std::ops::Range;
use std::path::Path;

use serde::de::DeserializeOwned;
use toml::Spanned;

use crate::material::params::{Param, Params, Value};
use crate::Error;

/// A value as the file wrote it, with the byte range it came from.
pub(crate) type Field<T = toml::Value> = Spanned<T>;

/// One TOML file's text and the path its errors name.
#[derive(Clone, Copy)]
pub(crate) struct Source<'a> {
    pub file: &'a Path,
    pub text: &'a str,
}

impl Source<'_> {
    /// The 1-based line on which a byte offset lies.
    pub fn line(&self, offset: usize) -> usize {
        let end = offset.min(self.text.len());
        1 + self.text.as_bytes()[..end].iter().filter(|&&b| b == b'\n').count()
    }

    /// A bad-input error at the line where `span` starts: `FILE:LINE: problem`.
    pub fn error(&self, span: Range<usize>, problem: impl Display) -> Error {
        Error::input_file(format!("{}:{}", self.file.display(), self.line(span.start)), problem)
    }

    /// Parses the text and deserialises it into `T`.
    pub fn decode<T: DeserializeOwned>(&self) -> crate::Result<T> {
        // Parse the syntax on its own first, so that a malformed file is reported as malformed
        // rather than as whatever schema error the half-read document happens to produce.
        if let Err(e) = self.text.parse::<toml::Table>() {
            return Err(self.syntax_error(&e));
        }
        toml::from_str(self.text).map_err(|e| self.schema_error(&e))
    }

    /// Converts an optional field, turning a conversion failure into an error at its line.
    pub fn read<T>(
        &self,
        key: &str,
        field: &Option<Field>,
        convert: impl FnOnce(&str, &toml::Value) -> Result<T, String>,
    ) -> crate::Result<Option<T>> {
        field.as_ref().map(|f| convert(key, f.get_ref()).map_err(|problem| self.error(f.span(), problem))).transpose()
    }

    fn located(&self, span: Option<Range<usize>>, problem: String) -> Error {
        match span {
            Some(span) => self.error(span, problem),
            None => Error::input_file(self.file, problem),
        }
    }

    fn syntax_error(&self, e: &toml::de::Error) -> Error {
        let message = one_line(e.message());
        let problem = match (message.as_str(), e.span()) {
            // The parser's span is the repeated key; quote it so the message names it.
            ("duplicate key", Some(span)) => format!("duplicate key '{}'", self.snippet(span)),
            _ => format!("TOML syntax error: {message}"),
        };
        self.located(e.span(), problem)
    }

    fn schema_error(&self, e: &toml::de::Error) -> Error {
        let message = one_line(e.message());
        let problem = match (unknown_field(&message), e.span()) {
            (Some((key, expected)), Some(span)) => {
                let expected: Vec<&str> = expected.iter().map(String::as_str).collect();
                crate::suggest::unknown("key", &key, &self.table_at(span.start), &expected)
            }
            // Anything else is a value or table of the wrong shape: name what is wrong.
            _ => {
                let what = e.span().and_then(|span| self.key_or_header_at(span.start));
                let hint = if message.ends_with("expected a sequence") {
                    " (a list of tables is written [[name]])"
                } else {
                    ""
                };
                match what {
                    Some(what) => format!("{what}: {message}{hint}"),
                    None => format!("{message}{hint}"),
                }
            }
        };
        self.located(e.span(), problem)
    }

    fn snippet(&self, span: Range<usize>) -> &str {
        self.text.get(span).unwrap_or("").trim()
    }

    /// The table header in force at `offset`, as the user would name it: `in [render]`,
    /// `in [[object.layer]]`, or `at the top level`.
    fn table_at(&self, offset: usize) -> String {
        let before = self.text.get(..offset).unwrap_or(self.text);
        before
            .lines()
            .rev()
            .map(str::trim)
            .find(|line| is_table_header(line))
            .map(|header| format!("in {}", header_text(header)))
            .unwrap_or_else(|| "at the top level".to_string())
    }

    /// For an error whose span is a value or a table: the key written before `=` on the line
    /// holding `offset`, or that line's table header.
    fn key_or_header_at(&self, offset: usize) -> Option<String> {
        let before = self.text.get(..offset)?;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let line = self.text[line_start..].lines().next().unwrap_or("").trim();
        if is_table_header(line) {
            return Some(header_text(line).to_string());
        }
        let (key, _) = before[line_start..].split_once('=')?;
        let key = key.trim();
        (!key.is_empty()).then(|| key.to_string())
    }
}

/// Whether a trimmed line is a table header such as `[render]` or `[[object.layer]]`, and not
/// the continuation of a multi-line array such as `[0.1, 0.2, 0.3],`.
fn is_table_header(line: &str) -> bool {
    let header = header_text(line);
    let name = header.trim_start_matches('[').trim_end_matches(']');
    header.starts_with('[')
        && header.ends_with(']')
        && !name.trim().is_empty()
        && name.chars().all(|c| c.is_alphanumeric() || "_-. \"'".contains(c))
}

/// A header line without its trailing comment.
fn header_text(line: &str) -> &str {
    line.split('#').next().unwrap_or("").trim()
}

/// Joins a possibly multi-line library message into one line.
fn one_line(message: &str) -> String {
    let lines: Vec<&str> = message.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
    lines.join("; ")
}

/// Splits serde's "unknown field `x`, expected one of `a`, `b`" into `x` and `[a, b]`.
fn unknown_field(message: &str) -> Option<(String, Vec<String>)> {
    let rest = message.strip_prefix("unknown field `")?;
    let (key, rest) = rest.split_once('`')?;
    // Every other piece between backticks is an expected name.
    let expected = rest.split('`').skip(1).step_by(2).map(String::from).collect();
    Some((key.to_string(), expected))
}

/// Reads a whole look or preset file, through the checked open of [`crate::input`].
pub(crate) fn read_text(path: &Path) -> crate::Result<String> {
    crate::input::read_text(path, crate::input::Kind::Toml)
}

// ---- Value conversions. Each names the key in its message; the caller adds FILE:LINE. ----

/// How a value reads in a message: `the string "4"`, `the integer 3`, `an array`.
pub(crate) fn describe(value: &toml::Value) -> String {
    match value {
        toml::Value::String(s) => format!("the string {s:?}"),
        toml::Value::Integer(i) => format!("the integer {i}"),
        toml::Value::Float(f) => format!("the number {f}"),
        toml::Value::Boolean(b) => format!("the boolean {b}"),
        toml::Value::Datetime(d) => format!("the date {d}"),
        toml::Value::Array(_) => "an array".to_string(),
        toml::Value::Table(_) => "a table".to_string(),
    }
}

/// A finite number; TOML integers are accepted, since `1` and `1.0` mean the same to an artist.
pub(crate) fn number(key: &str, value: &toml::Value) -> Result<f32, String> {
    let x = match value {
        toml::Value::Integer(i) => *i as f64,
        toml::Value::Float(f) => *f,
        other => return Err(format!("{key} must be a number, not {}", describe(other))),
    };
    // Checked after narrowing, so that 1e300 is caught as well as inf and nan.
    let narrowed = x as f32;
    if narrowed.is_finite() {
        Ok(narrowed)
    } else {
        Err(format!("{key} = {} is not a finite number", crate::number_text(x)))
    }
}

/// An integer in `min..=u32::MAX`.
pub(crate) fn unsigned(key: &str, value: &toml::Value, min: u32) -> Result<u32, String> {
    let toml::Value::Integer(i) = value else {
        return Err(format!("{key} must be a whole number, not {}", describe(value)));
    };
    u32::try_from(*i)
        .ok()
        .filter(|&v| v >= min)
        .ok_or_else(|| format!("{key} = {i} is out of range [{min}, {}]", u32::MAX))
}

pub(crate) fn boolean(key: &str, value: &toml::Value) -> Result<bool, String> {
    match value {
        toml::Value::Boolean(b) => Ok(*b),
        other => Err(format!("{key} must be true or false, not {}", describe(other))),
    }
}

/// A string that is not empty.
pub(crate) fn text(key: &str, value: &toml::Value) -> Result<String, String> {
    match value {
        toml::Value::String(s) if !s.trim().is_empty() => Ok(s.clone()),
        toml::Value::String(_) => Err(format!("{key} must not be empty")),
        other => Err(format!("{key} must be a string, not {}", describe(other))),
    }
}

/// A string that may be empty (descriptions).
pub(crate) fn any_text(key: &str, value: &toml::Value) -> Result<String, String> {
    match value {
        toml::Value::String(s) => Ok(s.clone()),
        other => Err(format!("{key} must be a string, not {}", describe(other))),
    }
}

pub(crate) fn text_list(key: &str, value: &toml::Value) -> Result<Vec<String>, String> {
    let toml::Value::Array(items) = value else {
        return Err(format!("{key} must be an array of strings, not {}", describe(value)));
    };
    items.iter().enumerate().map(|(i, item)| text(&format!("{key}[{i}]"), item)).collect()
}

/// Sets one of the eleven BRDF parameters from a TOML value, checking its kind and range.
pub(crate) fn set_param(params: &mut Params, param: Param, value: &toml::Value) -> Result<(), String> {
    let value = if param.is_color() {
        Value::Color(color(param.name(), value)?)
    } else {
        Value::Scalar(number(param.name(), value)?)
    };
    params.set(param, value)
}

pub(crate) fn color(key: &str, value: &toml::Value) -> Result<[f32; 3], String> {
    match value {
        toml::Value::Array(items) if items.len() == 3 => {
            let mut rgb = [0.0; 3];
            for (i, item) in items.iter().enumerate() {
                rgb[i] = number(&format!("{key}[{i}]"), item)?;
            }
            Ok(rgb)
        }
        toml::Value::Array(items) => Err(format!("{key} needs three numbers [r, g, b], not {}", items.len())),
        other => Err(format!("{key} must be a linear colour [r, g, b], not {}", describe(other))),
    }
}

// ---- Writing values back, in the form the readers above accept. ----

/// A float that reads back as the same `f32`, always with a decimal point.
pub(crate) fn float(x: f32) -> String {
    let s = x.to_string();
    if s.contains('.') {
        s
    } else {
        format!("{s}.0")
    }
}

pub(crate) fn quoted(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

pub(crate) fn value(value: Value) -> String {
    match value {
        Value::Scalar(x) => float(x),
        Value::Color([r, g, b]) => format!("[{}, {}, {}]", float(r), float(g), float(b)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_are_one_based() {
        let src = Source { file: Path::new("a.toml"), text: "a = 1\nb = 2\n\nc = 3" };
        assert_eq!(src.line(0), 1);
        assert_eq!(src.line(6), 2);
        assert_eq!(src.line(13), 4);
        assert_eq!(src.line(1000), 4);
    }

    #[test]
    fn table_headers_are_told_from_arrays() {
        assert!(is_table_header("[render]"));
        assert!(is_table_header("[[object.layer]]  # the top layer"));
        assert!(!is_table_header("[0.1, 0.2, 0.3],"));
        assert!(!is_table_header("[]"));
    }

    #[test]
    fn floats_read_back_exactly() {
        for x in [0.0f32, 1.0, 0.1, 0.25, 1e-7, 123456.78, -3.5] {
            let text = format!("x = {}", float(x));
            let table: toml::Table = text.parse().unwrap();
            assert_eq!(number("x", &table["x"]), Ok(x), "{text}");
        }
    }
}
