//! What the textbook-machine scenario kinds share besides [`Source`]: the ranges of
//! lengths and ratios, the PNG plots these kinds write into `armsim run --out DIR`, the
//! scenario's name, and the parse-then-report run.

use crate::core::diag::LocatedError as ScenarioError;
use crate::io::plots::panels::{render_panels, Panel};
use crate::scenarios::source::Source;
use std::path::{Path, PathBuf};

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
    let bytes = render_panels(title, panels, cols, (640, 420)).map_err(|e| e.to_string())?;
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
    ctx: &Source,
    out_dir: Option<&Path>,
    (name, suffix): (&str, &str),
    (panels, cols): (&[Panel], usize),
    json: serde_json::Value,
    mut text: String,
) -> Result<crate::io::report::Report, ScenarioError> {
    let written = write_plot(out_dir, &format!("{name}_{suffix}"), name, panels, cols)
        .map_err(|m| ScenarioError::new(ctx.file, None, "plot", m))?;
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
    report: fn(&Source, &S, Option<&Path>) -> Result<crate::io::report::Report, ScenarioError>,
) -> Result<crate::io::report::Report, ScenarioError> {
    let file = path.display().to_string();
    let sc = parse(&file, text)?;
    report(&Source::new(&file, text), &sc, out_dir)
}
