//! `kind = "torsional"` scenarios.

use crate::scenario::{Report, ScenarioError};
use std::path::Path;

/// Runs a torsional-chain scenario.
pub fn run(path: &Path, _text: &str) -> Result<Report, ScenarioError> {
    Err(ScenarioError::new(
        path.display().to_string(),
        None,
        "kind",
        "torsional scenarios are not implemented yet",
    ))
}
