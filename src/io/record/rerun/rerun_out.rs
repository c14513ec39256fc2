//! Rerun output: logs a [`Recording`] (robot geometry, link motion, tool path, joint plots,
//! workspace clouds, collisions) to a Rerun `.rrd` file or to a spawned Rerun viewer.
//!
//! This module owns the mapping from the recording types to Rerun entities:
//!
//! | entity                                   | what                                              |
//! |------------------------------------------|---------------------------------------------------|
//! | `world/robot/<link>`                     | `Transform3D`: the link's world pose, per frame    |
//! | `world/robot/<link>/visual_<k>`          | visual geometry in the link frame (static)         |
//! | `world/robot/<link>/collision`           | red box on a link at its collision times           |
//! | `world/robot/skeleton`                   | segments parent origin → child origin, per frame   |
//! | `world/obstacles/<name>`                 | scene obstacles ([`SceneExtras`]), static          |
//! | `world/tool_path`                        | the tool link's origin over time (static strip)    |
//! | `world/workspace/cloud_<i>`              | point cloud coloured by its value (viridis)        |
//! | `world/workspace/…`, `reports/workspace` | the workspace picture (`rerun_workspace`)          |
//! | `world/obstacles/<name>/shape_<k>`       | the scene's obstacles (static; `rerun_obstacles`)  |
//! | `plots/torque/<joint>`                   | joint torque (or force), per frame                 |
//! | `plots/torque/<joint>/upper_limit` / `lower_limit` | `±` effort limit (constant line)         |
//! | `plots/q/<joint>`                        | joint position, per frame                          |
//! | `log/collisions`, `log/info`             | text log                                           |
//! | `reports/header`, `reports/torque_check` | markdown documents (static)                        |
//!
//! Links are flat children of `world/robot`, each with its *world* pose composed from the
//! recording's static and per-frame parent → child transforms, so a recording whose tree
//! is unusual (frames not rooted at `world`, links missing) still draws what it has. The
//! timeline is `time` (a duration in seconds, from [`Frame::t`]). Bulk data goes through
//! `send_columns`, one chunk per entity.
//!
//! Geometry comes from a [`ModelSpec`] (or the URDF in the recording's header): boxes,
//! cylinders, capsules, spheres, and meshes read with [`crate::collision::mesh`]
//! (STL/OBJ/DAE). A visual mesh that cannot be found or read is replaced by the link's
//! primitive collision geometry where there is one, and reported as a warning.
//!
//! Saving encodes in memory and writes the file atomically (temporary file + rename), so a
//! failed run never leaves a partial `.rrd`. Spawning starts the external `rerun` viewer
//! (from PyPI `rerun-sdk`, same version as the `rerun` crate) and streams to it.

pub use crate::io::record::rerun::rerun_entities::{link_entity, path};
pub use crate::io::record::rerun::rerun_sink::*;
pub use crate::io::record::rerun::rerun_workspace::log_workspace_scene;

use crate::io::record::rerun::rerun_recording::log_with;
use crate::io::record::rerun::rerun_stream::{check_sink, finish, open};
use crate::io::record::{PointCloud, Recording};
use crate::model::ModelSpec;
use rerun::RecordingStream;
use std::path::Path;

/// Logs `rec` to `sink`. Geometry comes from `spec`, else from the URDF in
/// `rec.header.robot_description`, else only frames and points are drawn. Mesh URIs are
/// resolved against `mesh_base` (default: the directory of `spec.source` when that is a
/// file).
pub fn log_recording(
    rec: &Recording,
    spec: Option<&ModelSpec>,
    mesh_base: Option<&Path>,
    sink: &RerunSink,
) -> Result<RerunReport, RerunError> {
    log_recording_with(rec, spec, mesh_base, &SceneExtras::default(), sink)
}

/// [`log_recording`] with the scene around the robot (obstacles, see [`SceneExtras`]).
pub fn log_recording_with(
    rec: &Recording,
    spec: Option<&ModelSpec>,
    mesh_base: Option<&Path>,
    extras: &SceneExtras,
    sink: &RerunSink,
) -> Result<RerunReport, RerunError> {
    check_sink(sink)?;
    crate::io::record::rerun::rerun_tree::check_size(rec, spec).map_err(RerunError::TooLarge)?;
    let parsed;
    let mut pre_warnings = Vec::new();
    let spec = match (spec, &rec.header.robot_description) {
        (Some(s), _) => Some(s),
        (None, Some(text)) => match crate::model::parse::urdf::parse(text, "robot_description") {
            Ok(s) => {
                parsed = s;
                Some(&parsed)
            }
            Err(e) => {
                pre_warnings.push(format!(
                    "robot description not usable, drawing frames only: {e}"
                ));
                None
            }
        },
        (None, None) => None,
    };
    let name = if rec.header.name.is_empty() {
        "armsim".to_string()
    } else {
        rec.header.name.clone()
    };
    let (stream, storage) = open(sink, &name)?;
    let (mut report, robot) = log_with(&stream, rec, spec, mesh_base, pre_warnings)?;
    let drawn: Vec<&str> = rec.obstacles.iter().map(|m| m.name.as_str()).collect();
    let scene = crate::io::record::rerun::rerun_scene::log_obstacles(
        &stream,
        extras,
        &drawn,
        &mut report.warnings,
    )?;
    // Frame the robot (link origins over the motion, padded for the link bodies) and the
    // obstacles near it (a floor larger than the workspace does not push the camera away).
    let eye = robot.map(|(lo, hi)| {
        let pad = 0.15;
        let (mut lo, mut hi) = (lo.map(|x| x - pad), hi.map(|x| x + pad));
        if let Some((olo, ohi)) = scene {
            for k in 0..3 {
                let reach = 0.4;
                lo[k] = lo[k].min(olo[k].max(lo[k] - reach));
                hi[k] = hi[k].max(ohi[k].min(hi[k] + reach));
            }
        }
        crate::io::record::rerun::rerun_blueprint::Eye::framing(lo, hi)
    });
    // The skeleton lines run through the link bodies: hidden when bodies are drawn.
    let hidden: &[&str] = if report.visuals > 0 {
        &["/world/robot/skeleton"]
    } else {
        &[]
    };
    crate::io::record::rerun::rerun_blueprint::send(&stream, rec, hidden, eye)?;
    report.bytes = finish(&stream, storage, sink)?;
    Ok(report)
}

/// Logs one workspace cloud (points coloured by value, e.g. manipulability) alone.
pub fn log_workspace(cloud: &PointCloud, sink: &RerunSink) -> Result<RerunReport, RerunError> {
    let rec = Recording {
        header: crate::io::record::Header {
            name: "workspace".into(),
            ..Default::default()
        },
        clouds: vec![cloud.clone()],
        ..Default::default()
    };
    log_recording(&rec, None, None, sink)
}

/// Logs `rec` into an existing stream (no blueprint, no flush). See [`log_recording`].
pub fn log_to_stream(
    stream: &RecordingStream,
    rec: &Recording,
    spec: Option<&ModelSpec>,
    mesh_base: Option<&Path>,
) -> Result<RerunReport, RerunError> {
    log_with(stream, rec, spec, mesh_base, Vec::new()).map(|r| r.0)
}

#[cfg(test)]
mod tests {
    use crate::io::record::rerun::rerun_out::*;

    #[test]
    fn colormap_ends_and_middle() {
        assert_eq!(colormap(0.0), [68, 1, 84]);
        assert_eq!(colormap(1.0), [253, 231, 37]);
        assert_eq!(colormap(0.5), [33, 145, 140]);
        assert_eq!(colormap(-3.0), colormap(0.0));
        assert_eq!(colormap(7.0), colormap(1.0));
        assert_eq!(colormap(f32::NAN), [128, 128, 128]);
        // Halfway between the first two stops.
        assert_eq!(colormap(0.125), [64, 42, 112]);
    }
}
