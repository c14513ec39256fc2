//! MoveIt `PositionConstraint` / `OrientationConstraint` messages of a request: a tool-pose
//! goal (`goal_constraints[0]`) and the `path_constraints`.
//!
//! Read from each constraint: `link_name` (a link of the model), `header.frame_id` (the
//! world: empty, `world`, `/world` or the model's root link; anything else is refused,
//! armsim has no TF tree), and `weight` (ignored).
//! - `PositionConstraint`: `target_point_offset` (`{x, y, z}` in the link frame, default 0)
//!   and `constraint_region` with exactly one of `primitives` (box, sphere or cylinder)
//!   and its `primitive_poses` entry; `meshes` are refused.
//! - `OrientationConstraint`: `orientation` (`{x, y, z, w}`), the three
//!   `absolute_*_axis_tolerance`s and `parameterization` (0, MoveIt's default: XYZ Euler
//!   angles of `R*ᵀ R`; 1: its rotation vector).
//!
//! **Goal.** Position and orientation constraints (at most one of each, on the same
//! link) give the pose the link must reach: the point `target_point_offset` at the
//! region's centre, the link frame at `orientation`; the region and the tolerances only
//! have to be positive (armsim reaches the centre and the orientation to 1e-9). A
//! position alone is a position-only goal (its offset must then be zero); an orientation
//! alone is refused. A tolerance of π or more (a free axis) is refused for goals.
//!
//! **Path.** Each position constraint is a region the point must stay in. An orientation
//! constraint becomes what the planner certifies, never looser than MoveIt's test
//! (`|e_i| ≤ tol_i` for each component `e` of the error):
//! - every tolerance below π: the geodesic angle to `orientation` at most the smallest
//!   tolerance (each XYZ Euler angle and each rotation-vector component is at most it);
//! - XYZ Euler with `z` free (tolerance ≥ π): the link's `z` axis within `min(tol_x, tol_y)`
//!   of the target's `z` axis (the Euler angles `x`, `y` depend on that axis only, and
//!   each is at most its angle); likewise `x` free: the `x` axis within `min(tol_y, tol_z)`;
//! - all three free: no constraint (a warning);
//! - otherwise (`y` free alone, two free, a free axis with the rotation vector): refused.

use crate::core::spatial::{Mat3, Se3, Vec3};
use crate::model::Model;
use crate::model::Shape;
use crate::planning::moveit::scene::{check_frame, components, pose, primitive};
use crate::planning::moveit::yaml::{Doc, Node};
use crate::planning::path_constraints::{ConstraintKind, PathConstraint, RegionShape};
use crate::planning::plan_error::{PlanningInputError, PlanningInputWarning};
use crate::planning::pose_goal::PoseGoal;
use std::f64::consts::PI;

/// A position constraint, read.
struct Position {
    link: usize,
    offset: Vec3,
    pose: Se3,
    shape: RegionShape,
}

/// An orientation constraint, read.
struct Orientation {
    link: usize,
    rotation: Mat3,
    tol: [f64; 3],
    rotation_vector: bool,
}

fn link(doc: &Doc<'_>, c: &Node, at: &str, model: &Model) -> Result<usize, PlanningInputError> {
    let n = doc.req(c, at, "link_name")?;
    let name = doc.str(n, &format!("{at}.link_name"))?;
    model.link_id(name).ok_or_else(|| {
        doc.err(
            n,
            format!("{at}.link_name"),
            format!("link '{name}' is not in model '{}'", model.name),
        )
    })
}

fn position(
    doc: &Doc<'_>,
    c: &Node,
    at: &str,
    model: &Model,
) -> Result<Position, PlanningInputError> {
    doc.map(c, at)?;
    let root = model.links[0].name.as_str();
    check_frame(doc, c, at, &[root])?;
    let link = link(doc, c, at, model)?;
    let offset = match doc.get(c, "target_point_offset") {
        Some(n) => Vec3::from(components(
            doc,
            n,
            &format!("{at}.target_point_offset"),
            ["x", "y", "z"],
        )?),
        None => Vec3::zeros(),
    };
    let rat = format!("{at}.constraint_region");
    let region = doc.req(c, at, "constraint_region")?;
    doc.map(region, &rat)?;
    if let Some(m) = doc.opt_seq(region, &rat, "meshes")?.first() {
        return Err(doc.err(
            m,
            format!("{rat}.meshes[0]"),
            "mesh regions are not supported (boxes, spheres and cylinders are)",
        ));
    }
    let prims = doc.opt_seq(region, &rat, "primitives")?;
    let poses = doc.opt_seq(region, &rat, "primitive_poses")?;
    if prims.len() != 1 || poses.len() != 1 {
        return Err(doc.err(
            region,
            &rat,
            format!(
                "exactly one primitive and one primitive pose are supported, found {} and {}",
                prims.len(),
                poses.len()
            ),
        ));
    }
    let shape = match primitive(doc, &prims[0], &format!("{rat}.primitives[0]"))? {
        Shape::Box { size } => RegionShape::Box {
            half: size.map(|s| 0.5 * s),
        },
        Shape::Sphere { radius } => RegionShape::Sphere { radius },
        Shape::Cylinder { radius, length } => RegionShape::Cylinder {
            radius,
            half_length: 0.5 * length,
        },
        _ => unreachable!("primitive() returns boxes, spheres and cylinders"),
    };
    let pose = pose(doc, &poses[0], &format!("{rat}.primitive_poses[0]"))?;
    Ok(Position {
        link,
        offset,
        pose,
        shape,
    })
}

fn orientation(
    doc: &Doc<'_>,
    c: &Node,
    at: &str,
    model: &Model,
) -> Result<Orientation, PlanningInputError> {
    doc.map(c, at)?;
    let root = model.links[0].name.as_str();
    check_frame(doc, c, at, &[root])?;
    let link = link(doc, c, at, model)?;
    let oat = format!("{at}.orientation");
    let on = doc.req(c, at, "orientation")?;
    let q = components(doc, on, &oat, ["x", "y", "z", "w"])?;
    let rotation = crate::planning::moveit::scene::quaternion_matrix(q).ok_or_else(|| {
        doc.err(
            on,
            &oat,
            "the quaternion [x, y, z, w] is zero: not a rotation",
        )
    })?;
    let mut tol = [0.0; 3];
    for (k, axis) in ["x", "y", "z"].iter().enumerate() {
        let key = format!("absolute_{axis}_axis_tolerance");
        let n = doc.req(c, at, &key)?;
        tol[k] = doc.num(n, &format!("{at}.{key}"))?;
        if tol[k].is_nan() || tol[k] <= 0.0 {
            return Err(doc.err(
                n,
                format!("{at}.{key}"),
                format!("must be positive, found {}", tol[k]),
            ));
        }
    }
    let rotation_vector = match doc.get(c, "parameterization") {
        None => false,
        Some(n) => match doc.num(n, &format!("{at}.parameterization"))? {
            0.0 => false,
            1.0 => true,
            p => {
                return Err(doc.err(
                    n,
                    format!("{at}.parameterization"),
                    format!("{p} is not 0 (XYZ Euler angles) or 1 (rotation vector)"),
                ))
            }
        },
    };
    Ok(Orientation {
        link,
        rotation,
        tol,
        rotation_vector,
    })
}

/// The tool-pose goal of `goal_constraints[0]` (node `g`, element `at`), if it has
/// position or orientation constraints.
pub(super) fn goal_pose(
    doc: &Doc<'_>,
    g: &Node,
    at: &str,
    model: &Model,
) -> Result<Option<PoseGoal>, PlanningInputError> {
    let ps = doc.opt_seq(g, at, "position_constraints")?;
    let os = doc.opt_seq(g, at, "orientation_constraints")?;
    for (key, list) in [
        ("position_constraints", ps),
        ("orientation_constraints", os),
    ] {
        if let Some(extra) = list.get(1) {
            return Err(doc.err(
                extra,
                format!("{at}.{key}[1]"),
                "a goal pose takes at most one position and one orientation constraint",
            ));
        }
    }
    let p = ps
        .first()
        .map(|n| position(doc, n, &format!("{at}.position_constraints[0]"), model))
        .transpose()?;
    let o = os
        .first()
        .map(|n| orientation(doc, n, &format!("{at}.orientation_constraints[0]"), model))
        .transpose()?;
    let (p, o) = match (p, o) {
        (None, None) => return Ok(None),
        (None, Some(_)) => {
            return Err(doc.err(&os[0], format!("{at}.orientation_constraints[0]"), "an orientation goal needs a position constraint too (orientation-only goals are not supported)"))
        }
        (Some(p), o) => (p, o),
    };
    let Some(o) = o else {
        if p.offset.norm() > 0.0 {
            return Err(doc.err(
                &ps[0],
                format!("{at}.position_constraints[0].target_point_offset"),
                "a position-only goal must have a zero target_point_offset",
            ));
        }
        return Ok(Some(PoseGoal {
            link: p.link,
            target: Se3::from_translation(p.pose.trans),
            position_only: true,
        }));
    };
    let oat = format!("{at}.orientation_constraints[0]");
    if o.link != p.link {
        return Err(doc.err(
            &os[0],
            format!("{oat}.link_name"),
            format!(
                "names link '{}', the position constraint '{}': a goal pose is for one link",
                model.links[o.link].name, model.links[p.link].name
            ),
        ));
    }
    if o.tol.iter().any(|t| *t >= PI) {
        return Err(doc.err(&os[0], &oat, "a goal orientation with a free axis (tolerance ≥ π) is not supported: give the full orientation"));
    }
    // The link frame puts the offset point at the region's centre.
    let trans = p.pose.trans - o.rotation * p.offset;
    Ok(Some(PoseGoal {
        link: p.link,
        target: Se3::new(o.rotation, trans),
        position_only: false,
    }))
}

/// The request's `path_constraints` (node `root` of the request).
pub(super) fn path_constraints(
    doc: &Doc<'_>,
    root: &Node,
    model: &Model,
    warnings: &mut Vec<PlanningInputWarning>,
) -> Result<Vec<PathConstraint>, PlanningInputError> {
    let at = "path_constraints";
    let Some(pc) = doc.get(root, at) else {
        return Ok(Vec::new());
    };
    doc.map(pc, at)?;
    for key in ["joint_constraints", "visibility_constraints"] {
        if let Some(c) = doc.opt_seq(pc, at, key)?.first() {
            return Err(doc.err(
                c,
                format!("{at}.{key}[0]"),
                "only position and orientation path constraints are supported",
            ));
        }
    }
    let mut out = Vec::new();
    for (i, n) in doc
        .opt_seq(pc, at, "position_constraints")?
        .iter()
        .enumerate()
    {
        let p = position(doc, n, &format!("{at}.position_constraints[{i}]"), model)?;
        out.push(PathConstraint {
            link: p.link,
            kind: ConstraintKind::Position {
                offset: p.offset,
                pose: p.pose,
                shape: p.shape,
            },
        });
    }
    for (i, n) in doc
        .opt_seq(pc, at, "orientation_constraints")?
        .iter()
        .enumerate()
    {
        let cat = format!("{at}.orientation_constraints[{i}]");
        let o = orientation(doc, n, &cat, model)?;
        let free = o.tol.map(|t| t >= PI);
        let kind = match (free, o.rotation_vector) {
            ([false, false, false], _) => ConstraintKind::Orientation {
                rotation: o.rotation,
                tolerance: o.tol[0].min(o.tol[1]).min(o.tol[2]),
            },
            ([true, true, true], _) => {
                warnings.push(doc.err(n, &cat, "every axis is free (tolerances ≥ π): the constraint holds everywhere and is ignored"));
                continue;
            }
            ([false, false, true], false) => axis(&o, 2, o.tol[0].min(o.tol[1])),
            ([true, false, false], false) => axis(&o, 0, o.tol[1].min(o.tol[2])),
            _ => {
                return Err(doc.err(n, &cat, format!(
                    "tolerances {:?} with the {} parameterization are not supported: every tolerance below π, or (XYZ Euler angles) only z or only x free",
                    o.tol,
                    if o.rotation_vector { "rotation-vector" } else { "XYZ Euler" }
                )))
            }
        };
        out.push(PathConstraint { link: o.link, kind });
    }
    Ok(out)
}

/// The link's axis `k` within `tol` of the target orientation's axis `k`.
fn axis(o: &Orientation, k: usize, tol: f64) -> ConstraintKind {
    let mut a = Vec3::zeros();
    a[k] = 1.0;
    ConstraintKind::Axis {
        axis: a,
        direction: o.rotation.column(k).into_owned(),
        tolerance: tol,
    }
}
