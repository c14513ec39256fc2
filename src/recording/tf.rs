//! Link transforms of a [`Model`] as recording [`Transform`]s, the way
//! `robot_state_publisher` splits them: fixed joints (and a non-identity world → root
//! offset) are static, movable joints change with `q`.
//!
//! Owned here: [`static_transforms`], [`joint_transforms`], [`frame_at`] and the
//! [`Se3`] ↔ [`Transform`] conversions ([`to_transform`], [`to_se3`]).

use super::{Frame, Transform};
use crate::data::Data;
use crate::kinematics::{forward_kinematics, frame_placement};
use crate::model::{Model, WORLD};
use crate::spatial::{Mat3, Se3, Vec3};
use nalgebra::{Quaternion, Rotation3, UnitQuaternion};

/// Name of the frame the root link is placed in when the model has a base offset.
pub const WORLD_FRAME: &str = "world";

/// `parent → child` as a [`Transform`]; the quaternion has `w ≥ 0`.
pub fn to_transform(parent: &str, child: &str, pose: &Se3) -> Transform {
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(pose.rot));
    let c = q.coords; // [x, y, z, w]
    let s = if c[3] < 0.0 { -1.0 } else { 1.0 };
    Transform {
        parent: parent.to_string(),
        child: child.to_string(),
        translation: [pose.trans.x, pose.trans.y, pose.trans.z],
        rotation: [s * c[0], s * c[1], s * c[2], s * c[3]],
    }
}

/// The pose of a [`Transform`] (the quaternion is normalised first).
pub fn to_se3(t: &Transform) -> Se3 {
    let [x, y, z, w] = t.rotation;
    let q = UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z));
    let rot: Mat3 = q.to_rotation_matrix().into_inner();
    Se3::new(rot, Vec3::from(t.translation))
}

/// World placement of every link at `q = 0` (fixed offsets do not depend on `q`).
fn placements_at_zero(model: &Model) -> Vec<Se3> {
    let mut data = Data::new(model);
    forward_kinematics(model, &mut data, &vec![0.0; model.nv]);
    (0..model.links.len())
        .map(|l| frame_placement(model, &data, l))
        .collect()
}

/// The transforms that never change: `world → root` when the model places its root link
/// away from the origin, and `parent → child` of every fixed joint.
pub fn static_transforms(model: &Model) -> Vec<Transform> {
    let place = placements_at_zero(model);
    let mut out = Vec::new();
    for (l, link) in model.links.iter().enumerate() {
        if link.parent_joint.is_none() && link.body == WORLD && link.offset != Se3::identity() {
            out.push(to_transform(WORLD_FRAME, &link.name, &place[l]));
        }
    }
    for j in model.joints.iter().filter(|j| !j.jtype.is_movable()) {
        let rel = place[j.parent_link].inv_mul(&place[j.child_link]);
        out.push(to_transform(
            &model.links[j.parent_link].name,
            &model.links[j.child_link].name,
            &rel,
        ));
    }
    out
}

/// `parent → child` of every movable joint, from the placements in `data` (after
/// [`forward_kinematics`]), in joint (tree) order.
pub fn joint_transforms(model: &Model, data: &Data) -> Vec<Transform> {
    model
        .joints
        .iter()
        .filter(|j| j.jtype.is_movable())
        .map(|j| {
            let parent = frame_placement(model, data, j.parent_link);
            let child = frame_placement(model, data, j.child_link);
            to_transform(
                &model.links[j.parent_link].name,
                &model.links[j.child_link].name,
                &parent.inv_mul(&child),
            )
        })
        .collect()
}

/// A recording frame at time `t`: runs forward kinematics for `q` into `data` and
/// collects [`joint_transforms`]. `qd` and `tau` may be empty.
pub fn frame_at(
    model: &Model,
    data: &mut Data,
    t: f64,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
) -> Frame {
    forward_kinematics(model, data, q);
    Frame {
        t,
        q: q.to_vec(),
        qd: qd.to_vec(),
        tau: tau.to_vec(),
        tf: joint_transforms(model, data),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::rpy_to_matrix;

    #[test]
    fn quaternion_round_trip() {
        for rpy in [
            [0.0, 0.0, 0.0],
            [0.3, -1.2, 2.9],
            [std::f64::consts::PI, 0.0, 0.0],
            [0.0, std::f64::consts::FRAC_PI_2, 0.0],
            [-3.0, 0.4, -3.1],
        ] {
            let p = Se3::new(rpy_to_matrix(rpy), Vec3::new(1.0, -2.0, 0.5));
            let t = to_transform("a", "b", &p);
            assert!(t.rotation[3] >= 0.0);
            let n: f64 = t.rotation.iter().map(|x| x * x).sum();
            assert!((n - 1.0).abs() < 1e-14);
            let back = to_se3(&t);
            assert!((back.rot - p.rot).abs().max() < 1e-14, "{rpy:?}");
            assert_eq!(back.trans, p.trans);
        }
    }
}
