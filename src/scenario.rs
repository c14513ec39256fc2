//! Scenario files (TOML) and `armsim run`: the top-level `kind` key picks the runner.
//!
//! - `kind = "linkage"`: a closed-chain planar mechanism ([`crate::mechanism`]);
//! - `kind = "torsional"`: a torsional drivetrain chain ([`crate::drivetrain`]);
//! - `kind = "arm"` (the default): an arm scenario (planned motion, torque check,
//!   collisions, simulation; [`crate::arm`]).
//!
//! Every runner returns a [`Report`] (the JSON document and a human summary) or a
//! [`ScenarioError`] naming the file, the line and the key.

use std::fmt;
use std::path::Path;

/// An error in a scenario file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct ScenarioError {
    /// The scenario file.
    pub file: String,
    /// 1-based line, where known.
    pub line: Option<usize>,
    /// The key or table, e.g. `links.AB`, `[excitation]`.
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl ScenarioError {
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

    /// From a `toml` deserialisation error of `text` (line from its span; the key from
    /// the message (`unknown field`, `missing field`) or the line, prefixed with the
    /// enclosing `[table]`).
    pub fn from_toml(file: &str, text: &str, e: &toml::de::Error) -> Self {
        let line = e.span().map(|s| line_at(text, s.start));
        let quoted = |what: &str| {
            let m = e.message();
            let i = m.find(what)? + what.len();
            let rest = m[i..].strip_prefix('`')?;
            Some(rest[..rest.find('`')?].to_string())
        };
        let line_text = line.and_then(|l| text.lines().nth(l - 1)).unwrap_or("");
        let from_line = line_text
            .split('=')
            .next()
            .map(|k| k.trim().to_string())
            .filter(|k| !k.is_empty() && !k.starts_with('#') && !k.starts_with('['));
        let table = line.and_then(|l| {
            text.lines()
                .take(l)
                .collect::<Vec<_>>()
                .iter()
                .rev()
                .find_map(|t| {
                    let t = t.trim();
                    let inner = t.strip_prefix("[[").and_then(|x| x.strip_suffix("]]"));
                    let inner =
                        inner.or_else(|| t.strip_prefix('[').and_then(|x| x.strip_suffix(']')));
                    inner.map(|x| x.trim().to_string())
                })
        });
        let key = match quoted("unknown field ")
            .or_else(|| quoted("missing field "))
            .or(from_line)
        {
            Some(k) => match &table {
                Some(t)
                    if line_text.trim_start().starts_with('[') || !k.starts_with(t.as_str()) =>
                {
                    if line_text.trim_start().starts_with('[')
                        && e.message().contains("missing field")
                    {
                        format!("{t}.{k}")
                    } else if line_text.trim_start().starts_with('[') {
                        t.clone()
                    } else {
                        format!("{t}.{k}")
                    }
                }
                _ => k,
            },
            None => table.unwrap_or_else(|| "file".into()),
        };
        let message = e
            .message()
            .lines()
            .map(str::trim)
            .collect::<Vec<_>>()
            .join(" ");
        Self::new(file, line, key, message)
    }
}

impl fmt::Display for ScenarioError {
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
    text.lines()
        .position(|l| {
            l.trim_start()
                .strip_prefix(key)
                .is_some_and(|rest| rest.trim_start().starts_with('='))
        })
        .map(|i| i + 1)
}

/// What a scenario run produced.
#[derive(Debug, Clone)]
pub struct Report {
    /// The JSON document `armsim run --json` prints.
    pub json: serde_json::Value,
    /// The human-readable summary.
    pub text: String,
}

/// Reads a scenario file and runs it (arm scenarios write their files to `out/<name>`).
pub fn run_file(path: &Path) -> Result<Report, ScenarioError> {
    run_file_with(path, &crate::arm::RunOptions::default())
}

/// Reads a scenario file and runs it with `opts` (output directory, interrupt).
pub fn run_file_with(path: &Path, opts: &crate::arm::RunOptions) -> Result<Report, ScenarioError> {
    let file = path.display().to_string();
    let text = crate::io::read_input_string(path)
        .map_err(|e| ScenarioError::new(&file, None, "file", format!("cannot read: {e}")))?;
    if text.trim().is_empty() {
        return Err(ScenarioError::new(
            &file,
            Some(1),
            "file",
            "the file is empty",
        ));
    }
    let table: toml::Table =
        toml::from_str(&text).map_err(|e| ScenarioError::from_toml(&file, &text, &e))?;
    let kind = match table.get("kind") {
        None => "arm",
        Some(toml::Value::String(s)) => s.as_str(),
        Some(_) => {
            return Err(ScenarioError::new(
                &file,
                line_of_key(&text, "kind"),
                "kind",
                "expected a string: \"arm\", \"linkage\" or \"torsional\"",
            ))
        }
    };
    match kind {
        "linkage" => crate::mechanism::scenario::run(path, &text),
        "torsional" => crate::drivetrain::scenario::run(path, &text),
        "arm" => crate::arm::run(path, &text, opts).map(|o| o.report),
        "synthesis" => {
            crate::mechanism::synthesis_scenario::run(path, &text, opts.out_dir.as_deref())
        }
        "flywheel" => {
            crate::mechanism::flywheel_scenario::run(path, &text, opts.out_dir.as_deref())
        }
        "flexible_rotor" => {
            crate::drivetrain::rotor_scenario::run(path, &text, opts.out_dir.as_deref())
        }
        "isolation" => {
            crate::drivetrain::isolation_scenario::run(path, &text, opts.out_dir.as_deref())
        }
        "centrodes" => {
            crate::mechanism::centrode_scenario::run(path, &text, opts.out_dir.as_deref())
        }
        other => Err(ScenarioError::new(
            &file,
            line_of_key(&text, "kind"),
            "kind",
            format!(
                "unknown scenario kind '{other}' (expected \"arm\", \"linkage\" or \"torsional\")"
            ),
        )),
    }
}

/// Parses and validates scenario text without running the analyses (the fuzz targets'
/// entry: no filesystem, no long computation); `file` names the text in messages. Same
/// `kind` dispatch and messages as [`run_file`]. Arm scenarios are validated up to the
/// planning ([`crate::arm::load`]: model file read relative to `file`, no IK, no run).
pub fn check(file: &str, text: &str) -> Result<(), ScenarioError> {
    if text.trim().is_empty() {
        return Err(ScenarioError::new(
            file,
            Some(1),
            "file",
            "the file is empty",
        ));
    }
    let table: toml::Table =
        toml::from_str(text).map_err(|e| ScenarioError::from_toml(file, text, &e))?;
    let line = line_of_key(text, "kind");
    let kind_error = |msg: String| ScenarioError::new(file, line, "kind", msg);
    match table.get("kind") {
        Some(toml::Value::String(k)) if k == "linkage" => {
            crate::mechanism::scenario::parse(file, text).map(drop)
        }
        Some(toml::Value::String(k)) if k == "torsional" => {
            crate::drivetrain::scenario::parse(file, text).map(drop)
        }
        Some(toml::Value::String(k)) if k == "synthesis" => {
            crate::mechanism::synthesis_scenario::parse(file, text).map(drop)
        }
        Some(toml::Value::String(k)) if k == "flywheel" => {
            crate::mechanism::flywheel_scenario::parse(file, text).map(drop)
        }
        Some(toml::Value::String(k)) if k == "flexible_rotor" => {
            crate::drivetrain::rotor_scenario::parse(file, text).map(drop)
        }
        Some(toml::Value::String(k)) if k == "isolation" => {
            crate::drivetrain::isolation_scenario::parse(file, text).map(drop)
        }
        Some(toml::Value::String(k)) if k == "centrodes" => {
            crate::mechanism::centrode_scenario::parse(file, text).map(drop)
        }
        None => crate::arm::load(Path::new(file), text).map(drop),
        Some(toml::Value::String(k)) if k == "arm" => {
            crate::arm::load(Path::new(file), text).map(drop)
        }
        Some(toml::Value::String(other)) => Err(kind_error(format!(
            "unknown scenario kind '{other}' (expected \"arm\", \"linkage\" or \"torsional\")"
        ))),
        Some(_) => Err(kind_error(
            "expected a string: \"arm\", \"linkage\" or \"torsional\"".into(),
        )),
    }
}
