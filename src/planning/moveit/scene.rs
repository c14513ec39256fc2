//! MoveIt `PlanningScene` YAML → environment [`Obstacle`]s.
//!
//! Read: `world.collision_objects[]` with `id`, optional `header.frame_id`, optional
//! `operation` (ADD), optional object `pose`, `primitives[]` (`type` box / sphere /
//! cylinder, `dimensions`) and one `primitive_poses[]` entry per primitive. A pose is
//! `position` (`[x, y, z]` or `{x, y, z}`) and `orientation` (a quaternion, `[x, y, z, w]`
//! or `{x, y, z, w}`), each optional (zero, identity); the quaternion is normalised, and an
//! all-zero or non-finite one is an error. An object `pose` is applied before its
//! primitive poses (`world ← object ← primitive`, as MoveIt does).
//!
//! Refused with an "unsupported" error: cones and prisms, meshes, planes, octomaps,
//! objects attached to the robot, operations other than ADD (armsim reads whole scenes,
//! not diffs), frames other than the world (see [`WORLD_FRAMES`]). Everything else in the
//! message (robot state, allowed collision matrix, colours, …) is ignored.

use crate::collision::Obstacle;
use crate::core::spatial::{Mat3, Se3, Vec3};
use crate::model::Shape;
use crate::planning::moveit::yaml::{kind, Doc, Node};
use crate::planning::plan_error::PlanningInputError;
use saphyr::{Scalar, YamlData};
use std::collections::HashSet;

/// Frame ids taken as the world, i.e. the root frame of the robot model: empty, `world`,
/// `/world`. Callers may accept more (e.g. the model's root link name).
pub const WORLD_FRAMES: [&str; 3] = ["", "world", "/world"];

/// Parses PlanningScene text read from `file` (used in messages). `frames` names frame
/// ids accepted besides [`WORLD_FRAMES`].
pub fn parse_scene(
    text: &str,
    file: &str,
    frames: &[&str],
) -> Result<Vec<Obstacle>, PlanningInputError> {
    let (doc, root) = Doc::parse(text, file)?;
    refuse_attached(&doc, &root)?;
    let Some(world) = doc.get(&root, "world") else {
        return Ok(Vec::new());
    };
    doc.map(world, "world")?;
    refuse_octomap(&doc, world)?;
    let objects = doc.opt_seq(world, "world", "collision_objects")?;
    let mut out = Vec::new();
    let mut names: HashSet<String> = HashSet::new();
    for (i, obj) in objects.iter().enumerate() {
        let first = out.len();
        read_object(&doc, obj, i, frames, &mut out)?;
        for o in &out[first..] {
            if !names.insert(o.name.clone()) {
                return Err(doc.err(
                    obj,
                    format!("world.collision_objects[{i}]"),
                    format!("obstacle name '{}' is used twice", o.name),
                ));
            }
        }
    }
    Ok(out)
}

fn refuse_attached(doc: &Doc<'_>, root: &Node) -> Result<(), PlanningInputError> {
    let Some(state) = doc.get(root, "robot_state") else {
        return Ok(());
    };
    doc.map(state, "robot_state")?;
    let attached = doc.opt_seq(state, "robot_state", "attached_collision_objects")?;
    if let Some(a) = attached.first() {
        return Err(doc.err(
            a,
            "robot_state.attached_collision_objects[0]",
            "objects attached to the robot are not supported",
        ));
    }
    Ok(())
}

fn refuse_octomap(doc: &Doc<'_>, world: &Node) -> Result<(), PlanningInputError> {
    let data = doc
        .get(world, "octomap")
        .and_then(|o| doc.get(o, "octomap"))
        .and_then(|o| doc.get(o, "data"));
    match data.map(|d| &d.data) {
        Some(YamlData::Sequence(s)) if !s.is_empty() => Err(doc.err(
            &s[0],
            "world.octomap",
            "octomaps are not supported (obstacles must be primitives)",
        )),
        _ => Ok(()),
    }
}

/// Reads collision object `i` into `out` (one obstacle per primitive).
fn read_object(
    doc: &Doc<'_>,
    obj: &Node,
    i: usize,
    frames: &[&str],
    out: &mut Vec<Obstacle>,
) -> Result<(), PlanningInputError> {
    let at = format!("world.collision_objects[{i}]");
    doc.map(obj, &at)?;
    let id_node = doc.req(obj, &at, "id")?;
    let id = doc.str(id_node, &format!("{at}.id"))?;
    if id.is_empty() {
        return Err(doc.err(id_node, format!("{at}.id"), "empty id"));
    }
    let at = format!("{at} '{id}'");
    check_operation(doc, obj, &at)?;
    check_frame(doc, obj, &at, frames)?;
    for key in ["meshes", "planes"] {
        if let Some(m) = doc.opt_seq(obj, &at, key)?.first() {
            return Err(doc.err(
                m,
                format!("{at}.{key}[0]"),
                format!("{key} are not supported (obstacles must be boxes, spheres or cylinders)"),
            ));
        }
    }
    let base = match doc.get(obj, "pose") {
        Some(p) => Some(pose(doc, p, &format!("{at}.pose"))?),
        None => None,
    };
    let prims = doc.opt_seq(obj, &at, "primitives")?;
    let poses = doc.opt_seq(obj, &at, "primitive_poses")?;
    if prims.is_empty() {
        return Err(doc.err(
            obj,
            &at,
            "no primitives: an object needs at least one shape",
        ));
    }
    if poses.len() != prims.len() {
        let node = doc.get(obj, "primitive_poses").unwrap_or(obj);
        return Err(doc.err(
            node,
            format!("{at}.primitive_poses"),
            format!(
                "{} pose(s) for {} primitive(s): every primitive needs its pose",
                poses.len(),
                prims.len()
            ),
        ));
    }
    for (k, (prim, p)) in prims.iter().zip(poses).enumerate() {
        let shape = primitive(doc, prim, &format!("{at}.primitives[{k}]"))?;
        let local = pose(doc, p, &format!("{at}.primitive_poses[{k}]"))?;
        let world = match &base {
            Some(b) => b.mul(&local),
            None => local,
        };
        let name = if k == 0 {
            id.to_string()
        } else {
            format!("{id}/{k}")
        };
        out.push(Obstacle::new(name, shape, world));
    }
    Ok(())
}

/// `operation`: ADD (the default; `0` or `"add"`, any case) is the only one read.
fn check_operation(doc: &Doc<'_>, obj: &Node, at: &str) -> Result<(), PlanningInputError> {
    let Some(op) = doc.get(obj, "operation") else {
        return Ok(());
    };
    let name = match &op.data {
        YamlData::Value(Scalar::Integer(i)) => match i {
            0 => "ADD".to_string(),
            1 => "REMOVE".to_string(),
            2 => "APPEND".to_string(),
            3 => "MOVE".to_string(),
            _ => format!("{i}"),
        },
        YamlData::Value(Scalar::String(s)) => s.to_ascii_uppercase(),
        _ => {
            return Err(doc.err(
                op,
                format!("{at}.operation"),
                format!("expected ADD, found {}", kind(op)),
            ))
        }
    };
    if name == "ADD" {
        return Ok(());
    }
    Err(doc.err(
        op,
        format!("{at}.operation"),
        format!(
            "operation {name} is not supported: armsim reads a whole scene, every object is ADDed"
        ),
    ))
}

/// `header.frame_id` must be the world (or one of `frames`).
pub(super) fn check_frame(
    doc: &Doc<'_>,
    obj: &Node,
    at: &str,
    frames: &[&str],
) -> Result<(), PlanningInputError> {
    let Some(frame) = doc.get(obj, "header").and_then(|h| doc.get(h, "frame_id")) else {
        return Ok(());
    };
    let f = doc.str(frame, &format!("{at}.header.frame_id"))?;
    if WORLD_FRAMES.contains(&f) || frames.contains(&f) {
        return Ok(());
    }
    let mut known: Vec<String> = WORLD_FRAMES[1..].iter().map(|s| format!("'{s}'")).collect();
    known.extend(frames.iter().map(|s| format!("'{s}'")));
    Err(doc.err(
        frame,
        format!("{at}.header.frame_id"),
        format!(
            "frame '{f}' is not supported: obstacles must be given in the world frame ({}, or empty)",
            known.join(", ")
        ),
    ))
}

/// A `SolidPrimitive`: `type` (name or MoveIt's number) and `dimensions`.
pub(super) fn primitive(doc: &Doc<'_>, prim: &Node, at: &str) -> Result<Shape, PlanningInputError> {
    doc.map(prim, at)?;
    let t = doc.req(prim, at, "type")?;
    let kind_name = match &t.data {
        YamlData::Value(Scalar::String(s)) => s.to_ascii_lowercase(),
        YamlData::Value(Scalar::Integer(i)) => match i {
            1 => "box".into(),
            2 => "sphere".into(),
            3 => "cylinder".into(),
            4 => "cone".into(),
            5 => "prism".into(),
            _ => format!("{i}"),
        },
        _ => {
            return Err(doc.err(
                t,
                format!("{at}.type"),
                format!("expected a primitive type, found {}", kind(t)),
            ))
        }
    };
    let (n, what): (usize, &str) = match kind_name.as_str() {
        "box" => (3, "[x, y, z] (full side lengths)"),
        "sphere" => (1, "[radius]"),
        "cylinder" => (2, "[height, radius]"),
        "cone" | "prism" => {
            return Err(doc.err(
                t,
                format!("{at}.type"),
                format!(
                    "{kind_name} primitives are not supported (boxes, spheres and cylinders are)"
                ),
            ))
        }
        other => {
            return Err(doc.err(
                t,
                format!("{at}.type"),
                format!("unknown primitive type '{other}' (expected box, sphere or cylinder)"),
            ))
        }
    };
    let dn = doc.req(prim, at, "dimensions")?;
    let dat = format!("{at}.dimensions");
    let dims = doc.seq(dn, &dat)?;
    if dims.len() != n {
        return Err(doc.err(
            dn,
            &dat,
            format!(
                "a {kind_name} needs {n} dimension(s) {what}, found {}",
                dims.len()
            ),
        ));
    }
    let mut d = [0.0; 3];
    for (k, v) in dims.iter().enumerate() {
        d[k] = doc.num(v, &format!("{dat}[{k}]"))?;
        if d[k] <= 0.0 || d[k] > crate::collision::MAX_COORD {
            return Err(doc.err(
                v,
                format!("{dat}[{k}]"),
                format!(
                    "must be positive and at most {} m, found {}",
                    crate::core::diag::fmt_num(crate::collision::MAX_COORD),
                    crate::core::diag::fmt_num(d[k])
                ),
            ));
        }
    }
    Ok(match kind_name.as_str() {
        "box" => Shape::Box { size: d },
        "sphere" => Shape::Sphere { radius: d[0] },
        _ => Shape::Cylinder {
            radius: d[1],
            length: d[0],
        },
    })
}

/// A `geometry_msgs/Pose`: `position` and `orientation`, each optional.
pub(crate) fn pose(doc: &Doc<'_>, p: &Node, at: &str) -> Result<Se3, PlanningInputError> {
    doc.map(p, at)?;
    let trans = match doc.get(p, "position") {
        None => Vec3::zeros(),
        Some(n) => {
            let pat = format!("{at}.position");
            let xyz = components(doc, n, &pat, ["x", "y", "z"])?;
            if let Some(x) = xyz.iter().find(|x| x.abs() > crate::collision::MAX_COORD) {
                return Err(doc.err(
                    n,
                    &pat,
                    format!(
                        "{} m is beyond the {} m accepted for a position",
                        crate::core::diag::fmt_num(*x),
                        crate::core::diag::fmt_num(crate::collision::MAX_COORD)
                    ),
                ));
            }
            Vec3::from(xyz)
        }
    };
    let rot = match doc.get(p, "orientation") {
        None => Mat3::identity(),
        Some(n) => {
            let oat = format!("{at}.orientation");
            let q = components(doc, n, &oat, ["x", "y", "z", "w"])?;
            quaternion_matrix(q).ok_or_else(|| {
                doc.err(
                    n,
                    &oat,
                    "the quaternion [x, y, z, w] is zero: not a rotation",
                )
            })?
        }
    };
    Ok(Se3::new(rot, trans))
}

/// `N` numbers as a list `[a, b, …]` or as a mapping with the keys `names`.
pub(super) fn components<const N: usize>(
    doc: &Doc<'_>,
    n: &Node,
    at: &str,
    names: [&str; N],
) -> Result<[f64; N], PlanningInputError> {
    if let YamlData::Mapping(_) = n.data {
        let mut out = [0.0; N];
        for (k, key) in names.iter().enumerate() {
            let v = doc.req(n, at, key)?;
            out[k] = doc.num(v, &format!("{at}.{key}"))?;
        }
        return Ok(out);
    }
    if let YamlData::Sequence(_) = n.data {
        return doc.nums::<N>(n, at);
    }
    Err(doc.err(
        n,
        at,
        format!(
            "expected [{}] or {{{}}}, found {}",
            names.join(", "),
            names.map(|k| format!("{k}: …")).join(", "),
            kind(n)
        ),
    ))
}

/// Rotation matrix of the quaternion `[x, y, z, w]` after normalisation; `None` when it is
/// zero.
pub fn quaternion_matrix(q: [f64; 4]) -> Option<Mat3> {
    // Scaled by its largest component first: [1e200, 1e200, 0, 0] is a rotation whose
    // sum of squares overflows.
    let big = q.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    if big == 0.0 || !big.is_finite() {
        return None;
    }
    let q = q.map(|c| c / big);
    let norm = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    let [x, y, z, w] = q.map(|c| c / norm);
    Some(Mat3::new(
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y - z * w),
        2.0 * (x * z + y * w),
        2.0 * (x * y + z * w),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - x * w),
        2.0 * (x * z - y * w),
        2.0 * (y * z + x * w),
        1.0 - 2.0 * (x * x + y * y),
    ))
}
