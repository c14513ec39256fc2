//! Logs a [`Recording`] into an open stream ([`log_with`]): the link poses per frame
//! (within the viewer's pose budget), the skeleton and tool path, the robot's geometry,
//! the recorded obstacles, the joint plots, the clouds, the collisions, the reports and
//! the warnings; returns what was logged and the bounds the camera should frame.

use crate::core::spatial::{Se3, Vec3};
use crate::io::record::rerun::rerun_entities::sdk;
use crate::io::record::rerun::rerun_geometry::log_geometry;
use crate::io::record::rerun::rerun_motion::{log_links, log_skeleton, log_tool_path};
use crate::io::record::rerun::rerun_obstacles::log_obstacles;
use crate::io::record::rerun::rerun_plots::{
    log_clouds, log_collisions, log_joint_plots, log_reports, log_texts,
};
use crate::io::record::rerun::rerun_sink::{RerunError, RerunReport};
use crate::io::record::rerun::rerun_tree::Tree;
use crate::io::record::{Frame, Recording};
use crate::model::ModelSpec;
use rerun::{archetypes, RecordingStream};
use std::collections::HashMap;
use std::path::Path;

/// Logs `rec` into `stream` (see the module doc), `warnings` first among its warnings;
/// returns the report and the bounds of the link origins and world clouds.
pub(super) fn log_with(
    stream: &RecordingStream,
    rec: &Recording,
    spec: Option<&ModelSpec>,
    mesh_base: Option<&Path>,
    mut warnings: Vec<String>,
) -> Result<
    (
        RerunReport,
        Option<crate::io::record::rerun::rerun_scene::Bounds>,
    ),
    RerunError,
> {
    let mut report = RerunReport::default();
    stream
        .log_static("world", &archetypes::ViewCoordinates::RIGHT_HAND_Z_UP())
        .map_err(sdk)?;
    let tree = Tree::build(rec, spec, &mut warnings).map_err(RerunError::TooLarge)?;

    // Frames with a usable time, in the recording's order.
    let mut frames: Vec<&Frame> = rec.frames.iter().filter(|f| f.t.is_finite()).collect();
    if frames.len() < rec.frames.len() {
        warnings.push(format!(
            "{} frame(s) with a non-finite time skipped",
            rec.frames.len() - frames.len()
        ));
    }
    // Within the pose budget: every k-th frame (and the last).
    let stride = crate::io::record::rerun::rerun_tree::frame_stride(frames.len(), tree.names.len());
    if stride > 1 {
        warnings.push(format!(
            "drawing every {stride}th of the {} frames: {} frames × {} transform frames exceed \
             the viewer's budget of {} poses",
            frames.len(),
            frames.len(),
            tree.names.len(),
            crate::io::record::rerun::rerun_tree::MAX_POSES
        ));
        let last = frames.last().copied();
        frames = frames.into_iter().step_by(stride).collect();
        if let Some(l) = last {
            if !std::ptr::eq(*frames.last().unwrap_or(&l), l) {
                frames.push(l);
            }
        }
    }
    let times: Vec<f64> = frames.iter().map(|f| f.t).collect();
    report.frames = frames.len();

    // World poses per frame (or once, from the statics, without frames).
    let mut bad = 0usize;
    let posed: Vec<(Vec<Se3>, Vec<Option<usize>>)> = if frames.is_empty() {
        vec![tree.poses(None, &mut bad)]
    } else {
        frames
            .iter()
            .map(|f| tree.poses(Some(f), &mut bad))
            .collect()
    };
    if bad > 0 {
        warnings.push(format!(
            "{bad} frame transform(s) with a non-finite or zero rotation ignored"
        ));
    }

    log_links(stream, &tree, &times, &posed, &mut report)?;
    log_skeleton(stream, &times, &posed)?;
    report.tool = log_tool_path(stream, &tree, &posed)?;
    let boxes = match spec {
        Some(s) => log_geometry(stream, s, &tree, mesh_base, &mut report, &mut warnings)?,
        None => HashMap::new(),
    };
    let first = posed.first().map(|(w, _)| w);
    let frame_pose = |name: &str| Some(first?[*tree.index.get(name)?]);
    let (obstacles, base) = (&rec.obstacles, mesh_base);
    log_obstacles(
        stream,
        obstacles,
        &frame_pose,
        base,
        &mut report,
        &mut warnings,
    )?;
    log_joint_plots(stream, rec, &frames)?;
    let t0 = times.first().copied().unwrap_or(0.0);
    let info = log_clouds(stream, rec, &tree, &mut report, &mut warnings)?;
    log_texts(stream, "log/info", t0, &info, rerun::TextLogLevel::INFO)?;
    log_collisions(stream, &rec.collisions, &tree, &times, &boxes)?;
    log_reports(stream, rec)?;
    log_texts(
        stream,
        "log/warnings",
        t0,
        &warnings,
        rerun::TextLogLevel::WARN,
    )?;
    report.warnings = warnings;
    // What the camera frames: the link origins over the motion and the world clouds.
    let mut robot = None;
    for (w, _) in &posed {
        for m in w {
            crate::io::record::rerun::rerun_scene::grow(&mut robot, &m.trans);
        }
    }
    for c in rec
        .clouds
        .iter()
        .filter(|c| !tree.index.contains_key(&c.frame))
    {
        for p in c.points.iter().filter(|p| p.iter().all(|x| x.is_finite())) {
            let v = Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
            crate::io::record::rerun::rerun_scene::grow(&mut robot, &v);
        }
    }
    Ok((report, robot))
}
