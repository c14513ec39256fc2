//! What a scenario kind is to the registry ([`crate::scenarios::KINDS`]): the name its
//! files give in `kind = "…"`, a check that parses and validates a file without running
//! it, and a run that returns the [`Report`] ([`ScenarioKind`]). Also the [`RunOptions`]
//! every run takes (with its stop flag and [`OnStop`]) and the [`ScenarioError`] every
//! reader returns.

use crate::io::report::Report;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

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
    /// A flag another thread may raise (the CLI's and Python's Ctrl-C): read between
    /// the run's stages and before every simulation step, so a run stops within one
    /// step (or one stage before the simulation). What it then does is [`Self::on_stop`].
    pub stop: Option<Arc<AtomicBool>>,
    /// What a raised [`Self::stop`] does to the run.
    pub on_stop: OnStop,
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
            stop: None,
            on_stop: OnStop::Cancel,
            rerun: None,
            package_path: Vec::new(),
            keep_mesh_uris: false,
            strict: false,
        }
    }
}

/// What a run does when its stop flag is raised.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OnStop {
    /// The run fails with a "cancelled" error; no output file is written (the
    /// recording's temporary file is removed). Python's `run_scenario`.
    Cancel,
    /// The simulation ends at the current step and the run finishes its files with what
    /// was simulated (the report says `"interrupted": true`). `armsim run`'s Ctrl-C.
    FinishFiles,
}

impl RunOptions {
    /// Whether the stop flag is raised.
    pub fn stop_requested(&self) -> bool {
        self.stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
    }

    /// Whether the run must end now with a "cancelled" error: the flag is raised and
    /// [`Self::on_stop`] is [`OnStop::Cancel`].
    pub fn cancelled(&self) -> bool {
        self.on_stop == OnStop::Cancel && self.stop_requested()
    }
}
