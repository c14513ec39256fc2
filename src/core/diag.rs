//! Located errors for every input file the crate reads (model files, scenario files,
//! planning inputs): one error type naming the file, the line, the key or element and the
//! problem; the line arithmetic ([`line_at`], [`line_of_key`]); the range checks the
//! parsers share ([`finite_positive`], [`finite_non_negative`], [`all_finite`]); and the
//! number format of messages ([`fmt_num`]). The mapping of `toml` errors onto it lives
//! with the TOML readers (`LocatedError::from_toml`, in `model/parse/toml_error.rs`); the
//! error builder bound to a scenario file's text is `scenarios::source::Source`.
//!
//! This is a leaf module: it imports nothing from the rest of the crate, so the model
//! loaders and the scenario runners can both use it without pointing at each other.

use std::fmt;

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
pub fn assigns(l: &str, key: &str) -> bool {
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

/// `x` for a message: Rust's shortest form for ordinary magnitudes (`0.25`, `1500`),
/// `e` notation for very large or very small ones (`1e308`, not 309 digits; `1e-300`),
/// and `NaN`, `inf`, `-inf` as such.
pub fn fmt_num(x: f64) -> String {
    let a = x.abs();
    if !x.is_finite() || a == 0.0 || (1e-4..1e7).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
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
}
