//! [`Source`]: the error builder bound to one scenario file and its text, which turns the
//! byte spans of `toml::Spanned` values into lines.

use crate::core::diag::{assigns, line_at, LocatedError};
use std::ops::Range;

/// Error builder bound to one file and its text: turns byte spans (from
/// `toml::Spanned`) into lines.
#[derive(Clone, Copy, Debug)]
pub struct Source<'a> {
    /// The file, as the user named it.
    pub file: &'a str,
    /// Its text.
    pub text: &'a str,
}

impl<'a> Source<'a> {
    /// Binds `file` and its `text`.
    pub fn new(file: &'a str, text: &'a str) -> Self {
        Source { file, text }
    }

    /// An error at `span` (byte range).
    pub fn at(
        &self,
        span: Range<usize>,
        key: impl Into<String>,
        msg: impl Into<String>,
    ) -> LocatedError {
        LocatedError::new(self.file, Some(self.line(&span)), key, msg)
    }

    /// An error at a known 1-based line.
    pub fn err(&self, line: usize, key: impl Into<String>, msg: impl Into<String>) -> LocatedError {
        LocatedError::new(self.file, Some(line), key, msg)
    }

    /// 1-based line where `span` starts.
    pub fn line(&self, span: &Range<usize>) -> usize {
        line_at(self.text, span.start)
    }

    /// Line of `key =` inside `span` (falling back to the span's first line).
    pub fn key_line(&self, span: &Range<usize>, key: &str) -> usize {
        let start = self.line(span);
        let end = line_at(self.text, span.end);
        self.text
            .lines()
            .enumerate()
            .skip(start - 1)
            .take(end + 1 - start)
            .find(|(_, l)| assigns(l, key))
            .map(|(i, _)| i + 1)
            .unwrap_or(start)
    }

    /// An error on the line of the `[name]` section header (no line if there is none).
    pub fn section(&self, name: &str, msg: impl Into<String>) -> LocatedError {
        let header = format!("[{name}]");
        let line = self
            .text
            .lines()
            .position(|l| l.trim_start().starts_with(&header))
            .map(|i| i + 1);
        LocatedError::new(self.file, line, name, msg)
    }

    /// An optional value: `default` when absent, the value when `ok` accepts it, else an
    /// error at its span with `msg` (the shared range check of the scenario parsers).
    pub fn optional<T: Copy>(
        &self,
        v: Option<&toml::Spanned<T>>,
        key: &str,
        default: T,
        ok: impl Fn(T) -> bool,
        msg: &str,
    ) -> Result<T, LocatedError> {
        match v {
            None => Ok(default),
            Some(s) if ok(*s.get_ref()) => Ok(*s.get_ref()),
            Some(s) => Err(self.at(s.span(), key, msg)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::diag::{finite_non_negative, finite_positive, line_of_key};

    #[test]
    fn key_line_finds_the_assignment_inside_the_span() {
        let t = "[a]\nx = 1\n[b]\ny = 2\nx = 3\n";
        let cx = Source::new("f.toml", t);
        let b = t.find("[b]").unwrap();
        assert_eq!(cx.key_line(&(b..t.len()), "x"), 5);
        assert_eq!(cx.key_line(&(b..t.len()), "z"), 3);
        assert_eq!(line_of_key(t, "y"), Some(4));
        assert_eq!(cx.section("b", "m").line, Some(3));
    }

    #[test]
    fn optional_checks_the_range_and_keeps_the_default() {
        let text = "x = -1.0\n";
        #[derive(serde::Deserialize)]
        struct S {
            x: toml::Spanned<f64>,
        }
        let s: S = toml::from_str(text).unwrap();
        let cx = Source::new("f.toml", text);
        assert_eq!(cx.optional(None, "x", 2.0, finite_positive, "m"), Ok(2.0));
        let e = cx
            .optional(Some(&s.x), "x", 2.0, finite_positive, "must be positive")
            .unwrap_err();
        assert_eq!(e.to_string(), "f.toml:1: x: must be positive");
        assert!(!finite_positive(f64::NAN) && !finite_non_negative(f64::INFINITY));
        assert!(finite_non_negative(0.0) && !finite_positive(0.0));
    }
}
