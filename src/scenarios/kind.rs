//! What a scenario kind is to the registry ([`crate::scenarios::KINDS`]): the name its
//! files give in `kind = "…"`, a check that parses and validates a file without running
//! it, and a run that returns the [`Report`] ([`ScenarioKind`]). Also the [`RunOptions`]
//! every run takes and the [`ScenarioError`] every reader returns.

use crate::io::report::Report;
use std::path::{Path, PathBuf};

/// An error in a scenario file (the crate's one located error).
pub type ScenarioError = crate::core::diag::LocatedError;

/// One scenario kind: each kind's module defines one as `pub const KIND` and the
/// registry lists them.
pub struct ScenarioKind {
    /// The value of the file's top-level `kind` key.
    pub name: &'static str,
    /// Parses and validates `text` (named `file` in messages): no analyses, no files
    /// written (the fuzz targets' entry).
    pub check: fn(file: &str, text: &str) -> Result<(), ScenarioError>,
    /// Runs the scenario read from `path` (its text is `text`).
    pub run: fn(path: &Path, text: &str, opts: &RunOptions) -> Result<Report, ScenarioError>,
}

/// Options of a run that do not come from the file.
#[derive(Clone)]
pub struct RunOptions {
    /// Output directory (overrides `[outputs] dir`; default `out/<name>`).
    pub out_dir: Option<PathBuf>,
    /// Write output files at all.
    pub write_files: bool,
    /// Polled during the simulation: `true` stops it (SIGINT).
    pub stop: fn() -> bool,
    /// Also log the run to Rerun (an `.rrd` file or a spawned viewer).
    pub rerun: Option<crate::io::record::rerun::rerun_out::RerunSink>,
    /// Directories searched first for `package://` mesh URIs (`--package-path`).
    pub package_path: Vec<PathBuf>,
    /// Keep the recording's robot description's mesh URIs as the model file writes them
    /// instead of absolute `file://` URIs (`--keep-mesh-uris`).
    pub keep_mesh_uris: bool,
    /// Refuse a model that loads only with warnings (`--strict`).
    pub strict: bool,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            out_dir: None,
            write_files: true,
            stop: || false,
            rerun: None,
            package_path: Vec::new(),
            keep_mesh_uris: false,
            strict: false,
        }
    }
}
