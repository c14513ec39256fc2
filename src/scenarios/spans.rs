//! Locating errors in the machine scenario files: a [`Ctx`] bound to one file turns a
//! span (of a `Spanned` value or table) into `file:line: key: message`, and finds the
//! line of a field inside a table's span.

use crate::core::diag::{line_at, LocatedError as ScenarioError};
use std::ops::Range;

/// Error builder bound to one file.
pub struct Ctx<'a> {
    /// File name for messages.
    pub file: String,
    /// Its text.
    pub text: &'a str,
}

impl<'a> Ctx<'a> {
    /// Binds `file` and its `text`.
    pub fn new(file: &str, text: &'a str) -> Self {
        Self {
            file: file.to_string(),
            text,
        }
    }

    /// An error at the start of `span`.
    pub fn at(
        &self,
        span: Range<usize>,
        key: impl Into<String>,
        msg: impl Into<String>,
    ) -> ScenarioError {
        ScenarioError::new(&self.file, Some(line_at(self.text, span.start)), key, msg)
    }

    /// An error at the line where `field` is assigned inside the table `span` (or at the
    /// table's start when the field is not written there).
    pub fn field(
        &self,
        span: Range<usize>,
        field: &str,
        key: impl Into<String>,
        msg: impl Into<String>,
    ) -> ScenarioError {
        let start = span.start.min(self.text.len());
        let end = span.end.min(self.text.len()).max(start);
        let body = &self.text[start..end];
        let mut off = 0;
        let mut at = start;
        for l in body.split_inclusive('\n') {
            let t = l.trim_start().trim_start_matches('{').trim_start();
            let hit = t
                .strip_prefix(field)
                .is_some_and(|r| r.trim_start().starts_with('='))
                || l.contains(&format!(", {field} ="))
                || l.contains(&format!("{{ {field} ="));
            if hit {
                at = start + off;
                break;
            }
            off += l.len();
        }
        ScenarioError::new(&self.file, Some(line_at(self.text, at)), key, msg)
    }

    /// An error at the line of a top-level `key = …` (or no line).
    pub fn top(&self, key: &str, msg: impl Into<String>) -> ScenarioError {
        ScenarioError::new(
            &self.file,
            crate::core::diag::line_of_key(self.text, key),
            key,
            msg,
        )
    }

    /// A deserialisation error of the whole file.
    pub fn toml(&self, e: &toml::de::Error) -> ScenarioError {
        ScenarioError::from_toml(&self.file, self.text, e)
    }
}

/// Checks that `x` is finite and within `[lo, hi]`.
pub fn in_range(x: f64, lo: f64, hi: f64) -> bool {
    x.is_finite() && x >= lo && x <= hi
}
