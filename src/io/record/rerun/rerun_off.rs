//! Rerun output when armsim is built without the `rerun` feature (`--no-default-features`,
//! as the fuzz targets are): the types of [`crate::io::record::rerun::rerun_sink`] and the log
//! calls of `rerun_out`, which refuse with [`RerunError::NotBuilt`] before doing any work.

pub use crate::io::record::rerun::rerun_sink::*;
use crate::io::record::{PointCloud, Recording};
use crate::model::ModelSpec;
use std::path::Path;

/// Refuses: this build has no Rerun SDK.
pub fn log_recording(
    _rec: &Recording,
    _spec: Option<&ModelSpec>,
    _mesh_base: Option<&Path>,
    _sink: &RerunSink,
) -> Result<RerunReport, RerunError> {
    Err(RerunError::NotBuilt)
}

/// Refuses: this build has no Rerun SDK.
pub fn log_recording_with(
    _rec: &Recording,
    _spec: Option<&ModelSpec>,
    _mesh_base: Option<&Path>,
    _extras: &SceneExtras,
    _sink: &RerunSink,
) -> Result<RerunReport, RerunError> {
    Err(RerunError::NotBuilt)
}

/// Refuses: this build has no Rerun SDK.
pub fn log_workspace(_cloud: &PointCloud, _sink: &RerunSink) -> Result<RerunReport, RerunError> {
    Err(RerunError::NotBuilt)
}

/// Refuses: this build has no Rerun SDK.
pub fn log_workspace_scene(
    _model: &crate::model::Model,
    _ws: &crate::workspace::WorkspaceResult,
    _sink: &RerunSink,
) -> Result<RerunReport, RerunError> {
    Err(RerunError::NotBuilt)
}
