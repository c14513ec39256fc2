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

use super::rerun_obstacles::log_obstacles;
use super::{CollisionEvent, Frame, PointCloud, Recording, Transform};
use crate::model::ModelSpec;
use crate::spatial::{Mat3, Se3, Vec3};
use nalgebra::{Quaternion, Rotation3, UnitQuaternion};
use rerun::{
    archetypes, components::FillMode, EntityPath, EntityPathPart, RecordingStream,
    RecordingStreamBuilder, TimeColumn,
};
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use super::rerun_geometry::{log_geometry, Aabb};
pub(crate) use super::rerun_geometry::{log_primitive, vertex_normals};
pub use super::rerun_sink::*;
pub use super::rerun_workspace::log_workspace_scene;

pub(super) fn sdk(e: impl std::fmt::Display) -> RerunError {
    RerunError::Sdk(e.to_string())
}

/// Sends `cols` for `ent` as one chunk on the [`TIMELINE`], one row per time in `times`.
fn send_timed(
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
    let parsed;
    let mut pre_warnings = Vec::new();
    let spec = match (spec, &rec.header.robot_description) {
        (Some(s), _) => Some(s),
        (None, Some(text)) => match crate::model::urdf::parse(text, "robot_description") {
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
    let scene = super::rerun_scene::log_obstacles(&stream, extras, &drawn, &mut report.warnings)?;
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
        super::rerun_blueprint::Eye::framing(lo, hi)
    });
    // The skeleton lines run through the link bodies: hidden when bodies are drawn.
    let hidden: &[&str] = if report.visuals > 0 {
        &["/world/robot/skeleton"]
    } else {
        &[]
    };
    super::rerun_blueprint::send(&stream, rec, hidden, eye)?;
    report.bytes = finish(&stream, storage, sink)?;
    Ok(report)
}

/// Logs one workspace cloud (points coloured by value, e.g. manipulability) alone.
pub fn log_workspace(cloud: &PointCloud, sink: &RerunSink) -> Result<RerunReport, RerunError> {
    let rec = Recording {
        header: super::Header {
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
            crate::io::write_atomic(p, &bytes).map_err(|e| RerunError::Output {
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

/// The transform tree of a recording: every frame that is the child of some transform.
pub(super) struct Tree {
    names: Vec<String>,
    pub(super) index: HashMap<String, usize>,
    /// Static parent → child transform of each link, if any.
    statics: Vec<Option<(Option<usize>, Se3)>>,
    /// Whether the link has a transform in some frame.
    moving: Vec<bool>,
}

fn se3_of(t: &Transform) -> Option<Se3> {
    let [x, y, z, w] = t.rotation;
    let ok = t
        .translation
        .iter()
        .chain(&t.rotation)
        .all(|v| v.is_finite());
    let n = (x * x + y * y + z * z + w * w).sqrt();
    if !ok || n < 1e-9 {
        return None;
    }
    let q = UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z));
    Some(Se3::new(
        *q.to_rotation_matrix().matrix(),
        Vec3::from(t.translation),
    ))
}

pub(super) fn quat_xyzw(r: &Mat3) -> [f32; 4] {
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*r));
    [q.i as f32, q.j as f32, q.k as f32, q.w as f32]
}

pub(super) fn f32x3(v: &Vec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

impl Tree {
    fn add(&mut self, name: &str) -> usize {
        if let Some(&i) = self.index.get(name) {
            return i;
        }
        self.names.push(name.to_string());
        self.statics.push(None);
        self.moving.push(false);
        self.index.insert(name.to_string(), self.names.len() - 1);
        self.names.len() - 1
    }

    fn build(rec: &Recording, spec: Option<&ModelSpec>, warnings: &mut Vec<String>) -> Tree {
        let mut tree = Tree {
            names: Vec::new(),
            index: HashMap::new(),
            statics: Vec::new(),
            moving: Vec::new(),
        };
        let mut bad = 0usize;
        for t in &rec.header.static_tf {
            let c = tree.add(&t.child);
            match se3_of(t) {
                Some(m) => tree.statics[c] = Some((None, m)),
                None => bad += 1,
            }
        }
        for f in &rec.frames {
            for t in &f.tf {
                let c = tree.add(&t.child);
                tree.moving[c] = true;
            }
        }
        if let Some(s) = spec {
            for l in &s.links {
                tree.add(&l.name);
            }
        }
        // Parents of static transforms, now that every child has an index.
        for t in &rec.header.static_tf {
            let p = tree.index.get(&t.parent).copied();
            if let Some((parent, _)) = tree.statics[tree.index[&t.child]].as_mut() {
                *parent = p;
            }
        }
        if bad > 0 {
            warnings.push(format!(
                "{bad} static transform(s) with a non-finite or zero rotation ignored"
            ));
        }
        tree
    }

    /// World pose of every link for `frame` (`None`: statics only). Frames not reached
    /// from a known transform sit at the origin.
    fn poses(&self, frame: Option<&Frame>, bad: &mut usize) -> (Vec<Se3>, Vec<Option<usize>>) {
        let n = self.names.len();
        let mut local: Vec<Option<(Option<usize>, Se3)>> = self.statics.clone();
        if let Some(f) = frame {
            for t in &f.tf {
                let c = self.index[&t.child];
                match se3_of(t) {
                    Some(m) => local[c] = Some((self.index.get(&t.parent).copied(), m)),
                    None => *bad += 1,
                }
            }
        }
        let parent: Vec<Option<usize>> = local.iter().map(|l| l.and_then(|(p, _)| p)).collect();
        // 0 unvisited, 1 on the current walk, 2 done.
        let mut state = vec![0u8; n];
        let mut world = vec![Se3::identity(); n];
        let mut walk = Vec::new();
        for start in 0..n {
            let mut i = start;
            // Walk up to a resolved link or a root; a cycle is cut where it closes.
            loop {
                if state[i] != 0 {
                    break;
                }
                state[i] = 1;
                walk.push(i);
                match parent[i] {
                    Some(p) if state[p] != 1 => i = p,
                    _ => break,
                }
            }
            while let Some(j) = walk.pop() {
                let base = match parent[j] {
                    Some(p) if state[p] == 2 => world[p],
                    _ => Se3::identity(),
                };
                world[j] = match &local[j] {
                    Some((_, m)) => base.mul(m),
                    None => base,
                };
                state[j] = 2;
            }
        }
        (world, parent)
    }
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
) -> Result<(RerunReport, Option<super::rerun_scene::Bounds>), RerunError> {
    let mut report = RerunReport::default();
    stream
        .log_static("world", &archetypes::ViewCoordinates::RIGHT_HAND_Z_UP())
        .map_err(sdk)?;
    let tree = Tree::build(rec, spec, &mut warnings);

    // Frames with a usable time, in the recording's order.
    let frames: Vec<&Frame> = rec.frames.iter().filter(|f| f.t.is_finite()).collect();
    if frames.len() < rec.frames.len() {
        warnings.push(format!(
            "{} frame(s) with a non-finite time skipped",
            rec.frames.len() - frames.len()
        ));
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
            super::rerun_scene::grow(&mut robot, &m.trans);
        }
    }
    for c in rec
        .clouds
        .iter()
        .filter(|c| !tree.index.contains_key(&c.frame))
    {
        for p in c.points.iter().filter(|p| p.iter().all(|x| x.is_finite())) {
            let v = Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
            super::rerun_scene::grow(&mut robot, &v);
        }
    }
    Ok((report, robot))
}

/// Text log rows at time `t` (temporal, so that every row is kept).
fn log_texts(
    stream: &RecordingStream,
    ent: &str,
    t: f64,
    texts: &[String],
    level: &str,
) -> Result<(), RerunError> {
    if texts.is_empty() {
        return Ok(());
    }
    let cols = archetypes::TextLog::update_fields()
        .with_many_text(texts.iter().cloned())
        .with_many_level(std::iter::repeat_n(level, texts.len()))
        .columns_of_unit_batches()
        .map_err(sdk)?;
    send_timed(stream, ent, vec![t; texts.len()], cols)
}

fn log_links(
    stream: &RecordingStream,
    tree: &Tree,
    times: &[f64],
    posed: &[(Vec<Se3>, Vec<Option<usize>>)],
    report: &mut RerunReport,
) -> Result<(), RerunError> {
    for (i, name) in tree.names.iter().enumerate() {
        let ent = link_entity(name);
        report.links.push(ent.to_string());
        stream
            .log_static(ent.clone(), &archetypes::TransformAxes3D::new(0.05))
            .map_err(sdk)?;
        let has_tf = tree.moving[i] || tree.statics[i].is_some();
        if !has_tf {
            continue;
        }
        if times.is_empty() {
            let m = &posed[0].0[i];
            stream
                .log_static(
                    ent,
                    &archetypes::Transform3D::from_translation_rotation(
                        f32x3(&m.trans),
                        rerun::Quaternion::from_xyzw(quat_xyzw(&m.rot)),
                    ),
                )
                .map_err(sdk)?;
            continue;
        }
        report.moving_links += 1;
        let tr: Vec<[f32; 3]> = posed.iter().map(|(w, _)| f32x3(&w[i].trans)).collect();
        let qs: Vec<rerun::Quaternion> = posed
            .iter()
            .map(|(w, _)| rerun::Quaternion::from_xyzw(quat_xyzw(&w[i].rot)))
            .collect();
        let cols = archetypes::Transform3D::update_fields()
            .with_many_translation(tr)
            .with_many_quaternion(qs)
            .columns_of_unit_batches()
            .map_err(sdk)?;
        send_timed(stream, ent, times.iter().copied(), cols)?;
    }
    Ok(())
}

fn log_skeleton(
    stream: &RecordingStream,
    times: &[f64],
    posed: &[(Vec<Se3>, Vec<Option<usize>>)],
) -> Result<(), RerunError> {
    let strips_of = |(w, parent): &(Vec<Se3>, Vec<Option<usize>>)| -> Vec<[[f32; 3]; 2]> {
        parent
            .iter()
            .enumerate()
            .filter_map(|(c, p)| {
                let p = (*p)?;
                let (a, b) = (w[p].trans, w[c].trans);
                ((a - b).norm() > 1e-9).then(|| [f32x3(&a), f32x3(&b)])
            })
            .collect()
    };
    let ent = path(&["world", "robot", "skeleton"]);
    let style = |s: archetypes::LineStrips3D| {
        s.with_radii([0.006f32])
            .with_colors([rerun::Color::from_rgb(230, 160, 40)])
    };
    if times.is_empty() {
        let strips = strips_of(&posed[0]);
        if !strips.is_empty() {
            stream
                .log_static(ent, &style(archetypes::LineStrips3D::new(strips)))
                .map_err(sdk)?;
        }
        return Ok(());
    }
    let per: Vec<Vec<[[f32; 3]; 2]>> = posed.iter().map(strips_of).collect();
    let lengths: Vec<usize> = per.iter().map(Vec::len).collect();
    if lengths.iter().all(|&l| l == 0) {
        return Ok(());
    }
    stream
        .log_static(
            ent.clone(),
            &style(archetypes::LineStrips3D::update_fields()),
        )
        .map_err(sdk)?;
    let cols = archetypes::LineStrips3D::update_fields()
        .with_strips(per.into_iter().flatten())
        .columns(lengths)
        .map_err(sdk)?;
    send_timed(stream, ent, times.iter().copied(), cols)
}

/// The deepest link with a transform (the last in order among ties).
fn tool_link(tree: &Tree, parent: &[Option<usize>]) -> Option<usize> {
    let n = tree.names.len();
    let depth = |mut i: usize| {
        let mut d = 0usize;
        while let Some(p) = parent[i] {
            d += 1;
            i = p;
            if d > n {
                break;
            }
        }
        d
    };
    let mut best: Option<(usize, usize)> = None;
    for i in 0..n {
        if !(tree.moving[i] || tree.statics[i].is_some()) {
            continue;
        }
        let d = depth(i);
        if best.is_none_or(|(bd, _)| d >= bd) {
            best = Some((d, i));
        }
    }
    best.map(|(_, i)| i)
}

fn log_tool_path(
    stream: &RecordingStream,
    tree: &Tree,
    posed: &[(Vec<Se3>, Vec<Option<usize>>)],
) -> Result<Option<String>, RerunError> {
    let Some(tool) = tool_link(tree, &posed[0].1) else {
        return Ok(None);
    };
    if posed.len() >= 2 {
        let pts: Vec<[f32; 3]> = posed.iter().map(|(w, _)| f32x3(&w[tool].trans)).collect();
        stream
            .log_static(
                "world/tool_path",
                &archetypes::LineStrips3D::new([pts])
                    .with_radii([0.004f32])
                    .with_colors([rerun::Color::from_rgb(255, 120, 0)])
                    .with_labels([format!("{} path", tree.names[tool])]),
            )
            .map_err(sdk)?;
    }
    Ok(Some(tree.names[tool].clone()))
}

fn log_joint_plots(
    stream: &RecordingStream,
    rec: &Recording,
    frames: &[&Frame],
) -> Result<(), RerunError> {
    if frames.is_empty() {
        return Ok(());
    }
    let series = |field: fn(&Frame) -> &Vec<f64>, k: usize| -> (Vec<f64>, Vec<f64>) {
        frames
            .iter()
            .filter_map(|f| field(f).get(k).map(|&v| (f.t, v)))
            .unzip()
    };
    let send = |ent: EntityPath, t: Vec<f64>, v: Vec<f64>| -> Result<(), RerunError> {
        if t.is_empty() {
            return Ok(());
        }
        let cols = archetypes::Scalars::new(v)
            .columns_of_unit_batches()
            .map_err(sdk)?;
        send_timed(stream, ent, t, cols)
    };
    let (t0, t1) = (frames[0].t, frames[frames.len() - 1].t);
    let style = |ent: &EntityPath, name: String, rgb: [u8; 3]| {
        stream
            .log_static(
                ent.clone(),
                &archetypes::SeriesLines::new()
                    .with_names([name])
                    .with_colors([rerun::Color::from_rgb(rgb[0], rgb[1], rgb[2])]),
            )
            .map_err(sdk)
    };
    for (k, joint) in rec.header.joint_names.iter().enumerate() {
        let (t, v) = series(|f| &f.tau, k);
        if !t.is_empty() {
            let ent = path(&["plots", "torque", joint]);
            style(&ent, format!("τ {joint}"), [40, 120, 220])?;
            send(ent.clone(), t, v)?;
            if let Some(&Some(lim)) = rec.header.effort_limits.get(k) {
                if lim.is_finite() {
                    let ts = if t1 > t0 { vec![t0, t1] } else { vec![t0] };
                    for (part, sign) in [("upper_limit", 1.0), ("lower_limit", -1.0)] {
                        let e = child(&ent, part);
                        let name = if sign > 0.0 { "+limit" } else { "-limit" };
                        style(&e, name.to_string(), [220, 40, 40])?;
                        send(e, ts.clone(), vec![sign * lim; ts.len()])?;
                    }
                }
            }
        }
        let (t, v) = series(|f| &f.q, k);
        if !t.is_empty() {
            let ent = path(&["plots", "q", joint]);
            style(&ent, joint.clone(), [60, 160, 90])?;
            send(ent, t, v)?;
        }
    }
    Ok(())
}

/// Logs the clouds; returns one line per coloured cloud (its value range).
fn log_clouds(
    stream: &RecordingStream,
    rec: &Recording,
    tree: &Tree,
    report: &mut RerunReport,
    warnings: &mut Vec<String>,
) -> Result<Vec<String>, RerunError> {
    let mut info = Vec::new();
    for (i, c) in rec.clouds.iter().enumerate() {
        let name = format!("cloud_{i}");
        let ent = match tree.index.get(&c.frame) {
            Some(_) => child(&link_entity(&c.frame), &name),
            None => path(&["world", "workspace", &name]),
        };
        let pts: Vec<[f32; 3]> = c.points.clone();
        let finite: Vec<f32> = c.values.iter().copied().filter(|v| v.is_finite()).collect();
        let lo = finite.iter().copied().fold(f32::INFINITY, f32::min);
        let hi = finite.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        let mut arch = archetypes::Points3D::new(pts).with_radii([0.004f32]);
        if c.values.len() == c.points.len() && !finite.is_empty() {
            let span = if hi > lo { hi - lo } else { 1.0 };
            let colors: Vec<rerun::Color> = c
                .values
                .iter()
                .map(|v| {
                    let [r, g, b] = colormap((v - lo) / span);
                    rerun::Color::from_rgb(r, g, b)
                })
                .collect();
            arch = arch.with_colors(colors);
            info.push(format!(
                "{ent}: {} points, value {lo:.6} (dark violet) … {hi:.6} (yellow)",
                c.points.len()
            ));
        } else if !c.values.is_empty() {
            warnings.push(format!(
                "{ent}: {} values for {} points (or none finite); drawn uncoloured",
                c.values.len(),
                c.points.len()
            ));
        }
        if c.t.is_finite() && !rec.frames.is_empty() {
            stream.set_duration_secs(TIMELINE, c.t);
            stream.log(ent, &arch).map_err(sdk)?;
            stream.reset_time();
        } else {
            stream.log_static(ent, &arch).map_err(sdk)?;
        }
        report.points += c.points.len();
    }
    Ok(info)
}

fn log_collisions(
    stream: &RecordingStream,
    events: &[CollisionEvent],
    tree: &Tree,
    times: &[f64],
    boxes: &HashMap<usize, Aabb>,
) -> Result<(), RerunError> {
    // Event times per link, sorted.
    let mut per_link: BTreeMap<usize, Vec<f64>> = BTreeMap::new();
    for e in events.iter().filter(|e| e.t.is_finite()) {
        stream.set_duration_secs(TIMELINE, e.t);
        stream
            .log(
                "log/collisions",
                &archetypes::TextLog::new(format!("collision: {} ↔ {}", e.body_a, e.body_b))
                    .with_level(rerun::TextLogLevel::WARN),
            )
            .map_err(sdk)?;
        for b in [&e.body_a, &e.body_b] {
            if let Some(&i) = tree.index.get(b) {
                per_link.entry(i).or_default().push(e.t);
            }
        }
    }
    for (i, mut ts) in per_link {
        ts.sort_by(f64::total_cmp);
        ts.dedup();
        let ent = child(&link_entity(&tree.names[i]), "collision");
        let (lo, hi) = boxes.get(&i).copied().unwrap_or(([-0.03; 3], [0.03; 3]));
        let pad = 0.01;
        let marker = archetypes::Boxes3D::from_mins_and_sizes(
            [[
                (lo[0] - pad) as f32,
                (lo[1] - pad) as f32,
                (lo[2] - pad) as f32,
            ]],
            [[
                (hi[0] - lo[0] + 2.0 * pad) as f32,
                (hi[1] - lo[1] + 2.0 * pad) as f32,
                (hi[2] - lo[2] + 2.0 * pad) as f32,
            ]],
        )
        .with_colors([rerun::Color::from_rgb(255, 0, 0)])
        .with_radii([0.004f32])
        .with_fill_mode(FillMode::MajorWireframe);
        for (k, &t) in ts.iter().enumerate() {
            stream.set_duration_secs(TIMELINE, t);
            stream.log(ent.clone(), &marker).map_err(sdk)?;
            // Clear at the next frame time that is not itself a collision time.
            let next_event = ts.get(k + 1).copied().unwrap_or(f64::INFINITY);
            if let Some(&tc) = times.iter().find(|&&x| x > t) {
                if tc < next_event {
                    stream.set_duration_secs(TIMELINE, tc);
                    stream
                        .log(ent.clone(), &archetypes::Boxes3D::clear_fields())
                        .map_err(sdk)?;
                }
            }
        }
    }
    stream.reset_time();
    Ok(())
}

fn log_reports(stream: &RecordingStream, rec: &Recording) -> Result<(), RerunError> {
    let h = &rec.header;
    let mut md = format!(
        "# {}\n\n",
        if h.name.is_empty() {
            "recording"
        } else {
            &h.name
        }
    );
    md.push_str(&format!(
        "{} frames, {} joints, {} clouds, {} collision events\n\n",
        rec.frames.len(),
        h.joint_names.len(),
        rec.clouds.len(),
        rec.collisions.len()
    ));
    for (k, v) in &h.metadata {
        md.push_str(&format!("- **{k}**: {v}\n"));
    }
    stream
        .log_static(
            "reports/header",
            &archetypes::TextDocument::from_markdown(md),
        )
        .map_err(sdk)?;
    if !rec.torque_check.is_empty() {
        let opt = |x: Option<f64>, p: usize| x.map_or("–".to_string(), |v| format!("{v:.p$}"));
        let mut md = String::from(
            "| joint | peak τ | rms τ | peak speed | peak power | limit | margin % | ok | first violation (s) |\n\
             |---|---|---|---|---|---|---|---|---|\n",
        );
        for r in &rec.torque_check {
            md.push_str(&format!(
                "| {} | {:.3} | {:.3} | {:.3} | {:.3} | {} | {} | {} | {} |\n",
                r.joint,
                r.peak_torque,
                r.rms_torque,
                r.peak_speed,
                r.peak_power,
                opt(r.limit, 3),
                opt(r.margin, 1),
                if r.ok { "yes" } else { "**NO**" },
                opt(r.first_violation, 4)
            ));
        }
        stream
            .log_static(
                "reports/torque_check",
                &archetypes::TextDocument::from_markdown(md),
            )
            .map_err(sdk)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

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
