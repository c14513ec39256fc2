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

use crate::core::spatial::{Mat3, Se3, Vec3};
use crate::io::record::rerun::rerun_obstacles::log_obstacles;
use crate::io::record::{Frame, PointCloud, Recording};
use crate::model::ModelSpec;
use nalgebra::{Rotation3, UnitQuaternion};
use rerun::{
    archetypes, EntityPath, EntityPathPart, RecordingStream, RecordingStreamBuilder, TimeColumn,
};
use std::collections::HashMap;
use std::path::Path;

use crate::io::record::rerun::rerun_geometry::log_geometry;
pub(crate) use crate::io::record::rerun::rerun_geometry::{log_primitive, vertex_normals};
use crate::io::record::rerun::rerun_motion::{log_links, log_skeleton, log_tool_path};
use crate::io::record::rerun::rerun_plots::{
    log_clouds, log_collisions, log_joint_plots, log_reports, log_texts,
};
pub use crate::io::record::rerun::rerun_sink::*;
use crate::io::record::rerun::rerun_tree::Tree;
pub use crate::io::record::rerun::rerun_workspace::log_workspace_scene;

pub(super) fn sdk(e: impl std::fmt::Display) -> RerunError {
    RerunError::Sdk(e.to_string())
}

/// Sends `cols` for `ent` as one chunk on the [`TIMELINE`], one row per time in `times`.
pub(super) fn send_timed(
    stream: &RecordingStream,
    ent: impl Into<EntityPath>,
    times: impl IntoIterator<Item = f64>,
    cols: impl IntoIterator<Item = rerun::SerializedComponentColumn>,
) -> Result<(), RerunError> {
    stream
        .send_columns(ent, [TimeColumn::new_duration_secs(TIMELINE, times)], cols)
        .map_err(sdk)
}

/// `world/robot/<link>`, the link name as one (escaped) path part.
pub fn link_entity(link: &str) -> EntityPath {
    path(&["world", "robot", link])
}

/// An entity path from unescaped parts.
pub fn path(parts: &[&str]) -> EntityPath {
    EntityPath::new(parts.iter().map(|p| EntityPathPart::new(*p)).collect())
}

pub(super) fn child(base: &EntityPath, part: &str) -> EntityPath {
    base.join(&EntityPath::new(vec![EntityPathPart::new(part)]))
}

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

pub(super) fn check_sink(sink: &RerunSink) -> Result<(), RerunError> {
    if let RerunSink::Save(p) = sink {
        let out = |msg: String| RerunError::Output {
            path: p.clone(),
            msg,
        };
        if p.file_name().is_none() {
            return Err(out("not a file name".into()));
        }
        if p.is_dir() {
            return Err(out("is a directory".into()));
        }
        let dir = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        if !dir.is_dir() {
            return Err(out(format!("directory '{}' does not exist", dir.display())));
        }
    }
    Ok(())
}

pub(super) type Storage = Option<rerun::sink::MemorySinkStorage>;

pub(super) fn open(sink: &RerunSink, name: &str) -> Result<(RecordingStream, Storage), RerunError> {
    let b = RecordingStreamBuilder::new(APP_ID)
        .enabled(true)
        .recording_name(name);
    match sink {
        RerunSink::Save(_) => b.memory().map(|(s, st)| (s, Some(st))).map_err(sdk),
        RerunSink::Spawn => b
            .spawn()
            .map(|s| (s, None))
            .map_err(|e| RerunError::Viewer(format!("{e} (is `rerun` on PATH?)"))),
    }
    .inspect(|(s, _)| {
        // Only the `time` timeline: no log_tick / log_time columns.
        s.set_log_tick_enabled(false);
        s.set_log_time_enabled(false);
    })
}

pub(super) fn finish(
    stream: &RecordingStream,
    storage: Storage,
    sink: &RerunSink,
) -> Result<Option<u64>, RerunError> {
    match (sink, storage) {
        (RerunSink::Save(p), Some(st)) => {
            let bytes = st.drain_as_bytes().map_err(sdk)?;
            crate::core::files::write_atomic(p, &bytes).map_err(|e| RerunError::Output {
                path: p.clone(),
                msg: format!("cannot write: {e}"),
            })?;
            Ok(Some(bytes.len() as u64))
        }
        _ => {
            stream
                .flush_blocking()
                .map_err(|e| RerunError::Viewer(e.to_string()))?;
            Ok(None)
        }
    }
}

pub(super) fn quat_xyzw(r: &Mat3) -> [f32; 4] {
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*r));
    [q.i as f32, q.j as f32, q.k as f32, q.w as f32]
}

pub(super) fn f32x3(v: &Vec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
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

    #[test]
    fn entity_paths_escape_link_names() {
        assert_eq!(
            link_entity("base_link").to_string(),
            "/world/robot/base_link"
        );
        let odd = link_entity("a/b c");
        assert_eq!(odd.len(), 3);
    }
}
