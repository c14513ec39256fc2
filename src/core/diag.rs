//! Located errors for every input file the crate reads (model files, scenario files,
//! planning inputs): one error type naming the file, the line, the key or element and the
//! problem; the line arithmetic ([`line_at`], [`line_of_key`]); the mapping of `toml`
//! errors onto it ([`LocatedError::from_toml`]); one error builder bound to a file's text
//! ([`Source`]); and the range checks the parsers share ([`finite_positive`],
//! [`finite_non_negative`], [`all_finite`], [`Source::optional`]).
//!
//! This is a leaf module: it imports nothing from the rest of the crate, so the model
//! loaders and the scenario runners can both use it without pointing at each other.

use std::fmt;
use std::ops::Range;

/// An error (or warning) in an input file: where it is and what is wrong.
///
/// Displayed as `file:line: key: message` (or `file: key: message` when the line is not
/// known). [`crate::model::ModelError`] and [`crate::scenarios::ScenarioError`] are this
/// type.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct LocatedError {
    /// The file being read (as the user named it).
    pub file: String,
    /// 1-based line, where known.
    pub line: Option<usize>,
    /// The key or element, e.g. `links.AB`, `[excitation]`, `joint 'j3'`, `DH row 4`.
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl LocatedError {
    /// Builds an error.
    pub fn new(
        file: impl Into<String>,
        line: Option<usize>,
        key: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Self {
            file: file.into(),
            line,
            key: key.into(),
            message: message.into(),
        }
    }

    /// The key or element (model loaders call it the element).
    pub fn element(&self) -> &str {
        &self.key
    }

    /// From a `toml` deserialisation error of `text` (line from its span; the key from
    /// the message (`unknown field`, `missing field`) or the line, prefixed with the
    /// enclosing `[table]`).
    pub fn from_toml(file: &str, text: &str, e: &toml::de::Error) -> Self {
        let line = e.span().map(|s| line_at(text, s.start));
        let line_text = line.and_then(|l| text.lines().nth(l - 1)).unwrap_or("");
        let key = toml_error_key(text, line, line_text, e.message());
        let message = e
            .message()
            .lines()
            .map(str::trim)
            .collect::<Vec<_>>()
            .join(" ");
        Self::new(file, line, key, message)
    }
}

/// The key a `toml` error message names: the quoted field of `unknown field`/`missing
/// field`, else the key assigned on the error's line, prefixed with the enclosing table.
fn toml_error_key(text: &str, line: Option<usize>, line_text: &str, msg: &str) -> String {
    let quoted = |what: &str| {
        let i = msg.find(what)? + what.len();
        let rest = msg[i..].strip_prefix('`')?;
        Some(rest[..rest.find('`')?].to_string())
    };
    let from_line = line_text
        .split('=')
        .next()
        .map(|k| k.trim().to_string())
        .filter(|k| !k.is_empty() && !k.starts_with('#') && !k.starts_with('['));
    let table = line.and_then(|l| enclosing_table(text, l));
    let on_header = line_text.trim_start().starts_with('[');
    match quoted("unknown field ")
        .or_else(|| quoted("missing field "))
        .or(from_line)
    {
        Some(k) => match &table {
            Some(t) if on_header || !k.starts_with(t.as_str()) => {
                if on_header && msg.contains("missing field") {
                    format!("{t}.{k}")
                } else if on_header {
                    t.clone()
                } else {
                    format!("{t}.{k}")
                }
            }
            _ => k,
        },
        None => table.unwrap_or_else(|| "file".into()),
    }
}

/// The `[table]` or `[[array]]` header in force at 1-based `line` (inclusive).
fn enclosing_table(text: &str, line: usize) -> Option<String> {
    text.lines()
        .take(line)
        .collect::<Vec<_>>()
        .iter()
        .rev()
        .find_map(|t| {
            let t = t.trim();
            let inner = t.strip_prefix("[[").and_then(|x| x.strip_suffix("]]"));
            let inner = inner.or_else(|| t.strip_prefix('[').and_then(|x| x.strip_suffix(']')));
            inner.map(|x| x.trim().to_string())
        })
}

impl fmt::Display for LocatedError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(l) => write!(f, "{}:{}: {}: {}", self.file, l, self.key, self.message),
            None => write!(f, "{}: {}: {}", self.file, self.key, self.message),
        }
    }
}

/// 1-based line of byte offset `pos` in `text`.
pub fn line_at(text: &str, pos: usize) -> usize {
    text.as_bytes()[..pos.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// 1-based line where top-level or dotted `key` is first assigned (`key =`), if any.
pub fn line_of_key(text: &str, key: &str) -> Option<usize> {
    text.lines().position(|l| assigns(l, key)).map(|i| i + 1)
}

/// Whether line `l` assigns `key` (`key =`, leading blanks allowed).
fn assigns(l: &str, key: &str) -> bool {
    l.trim_start()
        .strip_prefix(key)
        .is_some_and(|rest| rest.trim_start().starts_with('='))
}

/// `x > 0` and finite (false for NaN).
pub fn finite_positive(x: f64) -> bool {
    x > 0.0 && x.is_finite()
}

/// `x >= 0` and finite (false for NaN).
pub fn finite_non_negative(x: f64) -> bool {
    x >= 0.0 && x.is_finite()
}

/// Every value is finite.
pub fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

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
    use crate::core::diag::*;

    #[test]
    fn line_at_counts_newlines_before_the_offset() {
        let t = "a\nbb\nccc";
        assert_eq!(line_at(t, 0), 1);
        assert_eq!(line_at(t, 2), 2);
        assert_eq!(line_at(t, 5), 3);
        assert_eq!(line_at(t, 999), 3);
    }

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
    fn toml_errors_name_the_table_and_the_key() {
        #[derive(serde::Deserialize, Debug)]
        #[serde(deny_unknown_fields)]
        #[allow(dead_code)]
        struct S {
            t: T,
        }
        #[derive(serde::Deserialize, Debug)]
        #[serde(deny_unknown_fields)]
        #[allow(dead_code)]
        struct T {
            a: f64,
        }
        let text = "[t]\na = 1.0\nb = 2\n";
        let e = toml::from_str::<S>(text).unwrap_err();
        let e = LocatedError::from_toml("f.toml", text, &e);
        assert_eq!((e.line, e.key.as_str()), (Some(3), "t.b"), "{e}");
        assert!(
            e.to_string().starts_with("f.toml:3: t.b: unknown field"),
            "{e}"
        );
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
