//! Reading the textbook-machine scenario kinds (`synthesis`, `flywheel`,
//! `flexible_rotor`, `isolation`): a typed TOML read whose errors name the file, the line
//! and the key; checks of spanned numbers; and the PNG plots these kinds write into
//! `armsim run --out DIR`.
//!
//! The kinds deserialise into `#[serde(deny_unknown_fields)]` structs whose numbers are
//! `toml::Spanned`, so a value that parses but is out of range is still reported at its
//! line.

use crate::core::diag::fmt_num;
use crate::core::diag::{line_at, LocatedError as ScenarioError};
use crate::io::plots::panels::{render_panels, Panel};
use serde::de::DeserializeOwned;
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// The range of a length (any consistent unit).
pub const LENGTHS: (f64, f64) = (1e-100, 1e100);
/// The lengths of one mechanism lie within this factor of each other.
pub const MAX_SCALE_RATIO: f64 = 1e9;
/// The largest time or velocity ratio.
pub const MAX_RATIO: f64 = 1e6;

/// Error builder bound to one scenario file.
pub struct Ctx<'a> {
    /// The file name used in messages.
    pub file: String,
    /// Its text.
    pub text: &'a str,
}

impl<'a> Ctx<'a> {
    /// A builder for `text`, the contents of `file`.
    pub fn new(file: &str, text: &'a str) -> Self {
        Self {
            file: file.to_string(),
            text,
        }
    }

    /// Deserialises the whole file (unknown keys, wrong types and missing keys located).
    pub fn parse<T: DeserializeOwned>(&self) -> Result<T, ScenarioError> {
        toml::from_str(self.text).map_err(|e| ScenarioError::from_toml(&self.file, self.text, &e))
    }

    /// An error at the line of byte `span.start`.
    pub fn at(
        &self,
        span: Range<usize>,
        key: impl Into<String>,
        msg: impl Into<String>,
    ) -> ScenarioError {
        ScenarioError::new(&self.file, Some(line_at(self.text, span.start)), key, msg)
    }

    /// An error at the line of the `[name]` or `[[name]]` header (the first line when
    /// there is none).
    pub fn section(&self, name: &str, msg: impl Into<String>) -> ScenarioError {
        let (a, b) = (format!("[{name}]"), format!("[[{name}]]"));
        let line = self
            .text
            .lines()
            .position(|l| {
                let t = l.trim_start();
                t.starts_with(&a) || t.starts_with(&b)
            })
            .map_or(1, |i| i + 1);
        ScenarioError::new(&self.file, Some(line), name, msg)
    }

    /// `Ok` when at least one of the sections is `present`, else `msg` at line 1 of the
    /// file (a file that asks for nothing).
    pub fn any_section(&self, present: &[bool], msg: &str) -> Result<(), ScenarioError> {
        if present.iter().any(|p| *p) {
            Ok(())
        } else {
            Err(ScenarioError::new(&self.file, Some(1), "file", msg))
        }
    }

    /// A finite number.
    pub fn finite(&self, v: &Spanned<f64>, key: &str) -> Result<f64, ScenarioError> {
        let x = *v.get_ref();
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.at(v.span(), key, "must be a finite number"))
        }
    }

    /// A finite number `> 0`.
    pub fn positive(&self, v: &Spanned<f64>, key: &str) -> Result<f64, ScenarioError> {
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
    pub fn non_negative(&self, v: &Spanned<f64>, key: &str) -> Result<f64, ScenarioError> {
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
    ) -> Result<f64, ScenarioError> {
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

    /// A length: finite, positive and within [`LENGTHS`] (so that the products and squares
    /// of a mechanism's lengths stay finite and normal).
    pub fn length(&self, v: &Spanned<f64>, key: &str) -> Result<f64, ScenarioError> {
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
    ) -> Result<(), ScenarioError> {
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
    pub fn ratio(&self, v: &Spanned<f64>, key: &str, or_equal: bool) -> Result<f64, ScenarioError> {
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
    ) -> Result<Option<f64>, ScenarioError> {
        v.map(|v| self.positive(v, key)).transpose()
    }

    /// An optional number `≥ 0`, `default` when absent.
    pub fn non_negative_or(
        &self,
        v: Option<&Spanned<f64>>,
        key: &str,
        default: f64,
    ) -> Result<f64, ScenarioError> {
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
    ) -> Result<usize, ScenarioError> {
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
    ) -> Result<Vec<f64>, ScenarioError> {
        v.get_ref()
            .iter()
            .enumerate()
            .map(|(i, x)| self.finite(x, &format!("{key}[{i}]")))
            .collect()
    }
}

/// Writes `panels` under `title` as `<dir>/<stem>.png` (atomically) when `dir` is given;
/// returns the path written.
pub fn write_plot(
    dir: Option<&Path>,
    stem: &str,
    title: &str,
    panels: &[Panel],
    cols: usize,
) -> Result<Option<PathBuf>, String> {
    let Some(dir) = dir else {
        return Ok(None);
    };
    if panels.is_empty() {
        return Ok(None);
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
    let bytes = render_panels(title, panels, cols, (640, 420))?;
    let safe: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    let path = dir.join(format!("{safe}.png"));
    crate::core::files::write_atomic(&path, &bytes)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(Some(path))
}

/// The finished report of a scenario with plots: writes `panels` as
/// `<out_dir>/<name>_<suffix>.png` (see [`write_plot`]), names the file in the text, and
/// returns the JSON and the text; a plot that cannot be written is an error at key `plot`.
pub fn finish_with_plot(
    ctx: &Ctx,
    out_dir: Option<&Path>,
    (name, suffix): (&str, &str),
    (panels, cols): (&[Panel], usize),
    json: serde_json::Value,
    mut text: String,
) -> Result<crate::io::report::Report, ScenarioError> {
    let written = write_plot(out_dir, &format!("{name}_{suffix}"), name, panels, cols)
        .map_err(|m| ScenarioError::new(&ctx.file, None, "plot", m))?;
    if let Some(p) = written {
        text.push_str(&format!("plot: {}\n", p.display()));
    }
    Ok(crate::io::report::Report { json, text })
}

/// The scenario's name: its `name` key, else the file stem.
pub fn scenario_name(name: Option<&str>, file: &str) -> String {
    name.map(str::to_string).unwrap_or_else(|| {
        Path::new(file)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scenario".into())
    })
}

/// Runs one scenario kind: `parse` the file's text, then `report` on the result (plots to
/// `out_dir` when given).
pub fn parse_and_report<S>(
    path: &Path,
    text: &str,
    out_dir: Option<&Path>,
    parse: fn(&str, &str) -> Result<S, ScenarioError>,
    report: fn(&Ctx, &S, Option<&Path>) -> Result<crate::io::report::Report, ScenarioError>,
) -> Result<crate::io::report::Report, ScenarioError> {
    let file = path.display().to_string();
    let sc = parse(&file, text)?;
    report(&Ctx::new(&file, text), &sc, out_dir)
}
