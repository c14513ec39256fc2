//! TEMPORARY stub of the MCAP reader (the real one is written on another branch): the
//! signature `armsim view` calls, always failing. Drop this file at the merge.

use super::Recording;
use std::path::Path;

/// Why a recording could not be read (stub).
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// Always: this build has no MCAP reader yet.
    #[error("{0}: reading MCAP is not available in this build (stub)")]
    Unsupported(String),
}

/// Reads an MCAP recording (stub: always an error).
pub fn read_mcap(path: &Path) -> Result<Recording, RecordError> {
    Err(RecordError::Unsupported(path.display().to_string()))
}
