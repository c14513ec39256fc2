//! `kind = "linkage"` scenarios.

use crate::scenario::{Report, ScenarioError};
use std::path::Path;

/// Runs a linkage scenario.
pub fn run(path: &Path, _text: &str) -> Result<Report, ScenarioError> {
    Err(ScenarioError::new(
        path.display().to_string(),
        None,
        "kind",
        "linkage scenarios are not implemented yet",
    ))
}
