//! [`Source`]: the one error context of the scenario readers, bound to a file and its
//! text. It deserialises the whole file (unknown keys, wrong types and missing keys
//! located), turns the byte spans of `toml::Spanned` values and tables into lines
//! (`at`, `field`, `key_line`, `section`, `top`), and checks spanned numbers at their
//! line (`finite`, `positive`, `length`, `ratio`, `count`, …).

use crate::core::diag::{assigns, fmt_num, line_at, LocatedError};
use serde::de::DeserializeOwned;
use std::ops::Range;
use toml::Spanned;

/// The range of a length (any consistent unit).
pub const LENGTHS: (f64, f64) = (1e-100, 1e100);
/// The lengths of one mechanism lie within this factor of each other.
pub const MAX_SCALE_RATIO: f64 = 1e9;
/// The largest time or velocity ratio.
pub const MAX_RATIO: f64 = 1e6;
/// Largest magnitude of an angle given in degrees (ten turns): positions, limits and
/// ranges beyond it are typing errors, and the trackers that step through them would
/// never end.
pub const MAX_ANGLE_DEG: f64 = 3600.0;

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

    /// Line of `key =` inside `span`, also inside an inline table (`{ key =`, `, key =`);
    /// the span's first line when the key is not written there.
    pub fn key_line(&self, span: &Range<usize>, key: &str) -> usize {
        let start = self.line(span);
        let end = line_at(self.text, span.end);
        let (inline_first, inline_next) = (format!("{{ {key} ="), format!(", {key} ="));
        self.text
            .lines()
            .enumerate()
            .skip(start - 1)
            .take(end + 1 - start)
            .find(|(_, l)| {
                assigns(l.trim_start().trim_start_matches('{'), key)
                    || l.contains(&inline_first)
                    || l.contains(&inline_next)
            })
            .map(|(i, _)| i + 1)
            .unwrap_or(start)
    }

    /// An error on the line of the `[name]` or `[[name]]` header (no line when the file
    /// has none).
    pub fn section(&self, name: &str, msg: impl Into<String>) -> LocatedError {
        let (a, b) = (format!("[{name}]"), format!("[[{name}]]"));
        let line = self
            .text
            .lines()
            .position(|l| {
                let t = l.trim_start();
                t.starts_with(&a) || t.starts_with(&b)
            })
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

    /// Exactly one of two alternative keys of `section`: `(true, a)` or `(false, b)`;
    /// both or neither is an error naming them.
    pub fn one_of<'v, T>(
        &self,
        section: &str,
        a: (&str, Option<&'v toml::Spanned<T>>),
        b: (&str, Option<&'v toml::Spanned<T>>),
    ) -> Result<(bool, &'v toml::Spanned<T>), LocatedError> {
        match (a.1, b.1) {
            (Some(x), None) => Ok((true, x)),
            (None, Some(y)) => Ok((false, y)),
            (Some(_), Some(y)) => Err(self.at(
                y.span(),
                format!("{section}.{}", b.0),
                format!("give either `{}` or `{}`, not both", a.0, b.0),
            )),
            (None, None) => {
                Err(self.section(section, format!("missing: give `{}` or `{}`", a.0, b.0)))
            }
        }
    }

    /// Deserialises the whole file (unknown keys, wrong types and missing keys located).
    pub fn parse<T: DeserializeOwned>(&self) -> Result<T, LocatedError> {
        toml::from_str(self.text).map_err(|e| LocatedError::from_toml(self.file, self.text, &e))
    }

    /// `Ok` when at least one of the sections is `present`, else `msg` at line 1 of the
    /// file (a file that asks for nothing).
    pub fn any_section(&self, present: &[bool], msg: &str) -> Result<(), LocatedError> {
        if present.iter().any(|p| *p) {
            Ok(())
        } else {
            Err(LocatedError::new(self.file, Some(1), "file", msg))
        }
    }

    /// A finite number.
    pub fn finite(&self, v: &Spanned<f64>, key: &str) -> Result<f64, LocatedError> {
        let x = *v.get_ref();
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.at(v.span(), key, "must be a finite number"))
        }
    }

    /// A finite number `> 0`.
    pub fn positive(&self, v: &Spanned<f64>, key: &str) -> Result<f64, LocatedError> {
        let x = self.finite(v, key)?;
        if x > 0.0 {
            Ok(x)
        } else {
            Err(self.at(
                v.span(),
                key,
                format!("must be positive, got {}", fmt_num(x)),
            ))
        }
    }

    /// A finite number `≥ 0`.
    pub fn non_negative(&self, v: &Spanned<f64>, key: &str) -> Result<f64, LocatedError> {
        let x = self.finite(v, key)?;
        if x >= 0.0 {
            Ok(x)
        } else {
            Err(self.at(
                v.span(),
                key,
                format!("must not be negative, got {}", fmt_num(x)),
            ))
        }
    }

    /// A finite number in the open interval `(lo, hi)`.
    pub fn between(
        &self,
        v: &Spanned<f64>,
        key: &str,
        lo: f64,
        hi: f64,
    ) -> Result<f64, LocatedError> {
        let x = self.finite(v, key)?;
        if x > lo && x < hi {
            Ok(x)
        } else {
            Err(self.at(
                v.span(),
                key,
                format!(
                    "must lie strictly between {} and {}, got {}",
                    fmt_num(lo),
                    fmt_num(hi),
                    fmt_num(x)
                ),
            ))
        }
    }

    /// An angle in degrees: finite and strictly within ±[`MAX_ANGLE_DEG`].
    pub fn angle_deg(&self, v: &Spanned<f64>, key: &str) -> Result<f64, LocatedError> {
        self.between(v, key, -MAX_ANGLE_DEG, MAX_ANGLE_DEG)
    }

    /// A length: finite, positive and within [`LENGTHS`] (so that the products and squares
    /// of a mechanism's lengths stay finite and normal).
    pub fn length(&self, v: &Spanned<f64>, key: &str) -> Result<f64, LocatedError> {
        let x = self.positive(v, key)?;
        if (LENGTHS.0..=LENGTHS.1).contains(&x) {
            Ok(x)
        } else {
            Err(self.at(
                v.span(),
                key,
                format!(
                    "{} is out of range: a length lies in {}..{}",
                    fmt_num(x),
                    fmt_num(LENGTHS.0),
                    fmt_num(LENGTHS.1)
                ),
            ))
        }
    }

    /// A length `x` (at `v`) of the mechanism whose size is `scale` (named `scale_key`): the
    /// two within [`MAX_SCALE_RATIO`] of each other.
    pub fn same_scale(
        &self,
        v: &Spanned<f64>,
        key: &str,
        (scale, scale_key): (f64, &str),
    ) -> Result<(), LocatedError> {
        let x = *v.get_ref();
        let r = x / scale;
        if (1.0 / MAX_SCALE_RATIO..=MAX_SCALE_RATIO).contains(&r) {
            Ok(())
        } else {
            Err(self.at(
                v.span(),
                key,
                format!(
                    "{} is {} times {scale_key} ({}): the lengths of one mechanism lie within a \
                     factor {} of each other",
                    fmt_num(x),
                    fmt_num(r),
                    fmt_num(scale),
                    fmt_num(MAX_SCALE_RATIO)
                ),
            ))
        }
    }

    /// A time or velocity ratio: finite, above 1 (at least 1 when `or_equal`), and at most
    /// [`MAX_RATIO`] (beyond it the mechanism is a limit position, not a mechanism).
    pub fn ratio(&self, v: &Spanned<f64>, key: &str, or_equal: bool) -> Result<f64, LocatedError> {
        let k = self.finite(v, key)?;
        let low = if or_equal { k < 1.0 } else { k <= 1.0 };
        if low {
            let bound = if or_equal { "be at least" } else { "exceed" };
            return Err(self.at(v.span(), key, format!("must {bound} 1, got {}", fmt_num(k))));
        }
        if k > MAX_RATIO {
            return Err(self.at(
                v.span(),
                key,
                format!(
                    "{} is out of range: at most {:e} (a larger ratio leaves the quick stroke \
                     less than 4e-4° of the crank's turn)",
                    fmt_num(k),
                    MAX_RATIO
                ),
            ));
        }
        Ok(k)
    }

    /// An optional number `> 0` (`None` when absent).
    pub fn positive_opt(
        &self,
        v: Option<&Spanned<f64>>,
        key: &str,
    ) -> Result<Option<f64>, LocatedError> {
        v.map(|v| self.positive(v, key)).transpose()
    }

    /// An optional number `≥ 0`, `default` when absent.
    pub fn non_negative_or(
        &self,
        v: Option<&Spanned<f64>>,
        key: &str,
        default: f64,
    ) -> Result<f64, LocatedError> {
        Ok(v.map(|v| self.non_negative(v, key))
            .transpose()?
            .unwrap_or(default))
    }

    /// An optional count in `range`, `default` when absent.
    pub fn count(
        &self,
        v: Option<&Spanned<usize>>,
        key: &str,
        default: usize,
        range: std::ops::RangeInclusive<usize>,
    ) -> Result<usize, LocatedError> {
        match v {
            None => Ok(default),
            Some(p) if range.contains(p.get_ref()) => Ok(*p.get_ref()),
            Some(p) => Err(self.at(
                p.span(),
                key,
                format!("must lie in {}..={}", range.start(), range.end()),
            )),
        }
    }

    /// Every element finite; the key of element `i` is `key[i]`.
    pub fn finite_list(
        &self,
        v: &Spanned<Vec<Spanned<f64>>>,
        key: &str,
    ) -> Result<Vec<f64>, LocatedError> {
        v.get_ref()
            .iter()
            .enumerate()
            .map(|(i, x)| self.finite(x, &format!("{key}[{i}]")))
            .collect()
    }

    /// An error at the line where `field` is assigned inside the table `span` (or at the
    /// table's start when the field is not written there; see [`Source::key_line`]).
    pub fn field(
        &self,
        span: Range<usize>,
        field: &str,
        key: impl Into<String>,
        msg: impl Into<String>,
    ) -> LocatedError {
        self.err(self.key_line(&span, field), key, msg)
    }

    /// An error at the line of a top-level `key = …` (or no line).
    pub fn top(&self, key: &str, msg: impl Into<String>) -> LocatedError {
        LocatedError::new(
            self.file,
            crate::core::diag::line_of_key(self.text, key),
            key,
            msg,
        )
    }

    /// A deserialisation error of the whole file.
    pub fn toml(&self, e: &toml::de::Error) -> LocatedError {
        LocatedError::from_toml(self.file, self.text, e)
    }
}

/// Checks that `x` is finite and within `[lo, hi]`.
pub fn in_range(x: f64, lo: f64, hi: f64) -> bool {
    x.is_finite() && x >= lo && x <= hi
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
        // Inside inline tables, and the same line through `field`.
        let t = "p = [\n  { a = 1, b = 2 },\n  { b = 3,\n    a = 4 },\n]\n[[q]]\n";
        let cx = Source::new("f.toml", t);
        let second = t.find("{ b = 3").unwrap()..t.find("]\n[[").unwrap();
        assert_eq!(cx.key_line(&(0..t.len()), "b"), 2);
        assert_eq!(cx.key_line(&second, "a"), 4);
        assert_eq!(cx.field(second.clone(), "b", "p[1].b", "m").line, Some(3));
        assert_eq!(cx.field(second, "c", "p[1].c", "m").line, Some(3));
        assert_eq!(cx.section("q", "m").line, Some(6));
        assert_eq!(cx.section("r", "m").line, None);
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
