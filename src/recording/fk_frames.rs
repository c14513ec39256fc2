//! Recording pieces computed from a [`Model`]: the [`Header`] (joint names, effort limits,
//! the fixed frames, the URDF text) and one [`Frame`] per time step by forward kinematics.
//!
//! Transforms follow `robot_state_publisher`: fixed joints (and `world` → root link) are
//! static and go into [`Header::static_tf`]; every movable joint (mimic ones included) gives
//! one parent link → child link transform per frame.

use super::{Frame, Header, Transform};
use crate::data::Data;
use crate::kinematics::{forward_kinematics, frame_placement};
use crate::model::Model;
use crate::spatial::Se3;
use nalgebra::{Rotation3, UnitQuaternion};

/// Name of the fixed frame the root link hangs from.
pub const WORLD_FRAME: &str = "world";

/// `aMb` as a [`Transform`] from `parent` to `child` (rotation `[x, y, z, w]`).
pub fn transform_from_se3(parent: &str, child: &str, m: &Se3) -> Transform {
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m.rot));
    Transform {
        parent: parent.to_string(),
        child: child.to_string(),
        translation: [m.trans.x, m.trans.y, m.trans.z],
        rotation: [q.i, q.j, q.k, q.w],
    }
}

/// The header of a recording of `model`: coordinate names, finite effort limits, the
/// static transforms and the URDF text (when the model came from one).
pub fn header_from_model(model: &Model, name: &str) -> Header {
    // Fixed joints are rigid whatever q is: measure them at the neutral configuration.
    let mut data = Data::new(model);
    if model.nv > 0 {
        forward_kinematics(model, &mut data, &model.neutral());
    }
    let mut static_tf = Vec::new();
    for link in &model.links {
        match link.parent_joint.map(|j| &model.joints[j]) {
            // The root: world → root link, unless the root *is* the world frame.
            None if link.name != WORLD_FRAME => {
                static_tf.push(transform_from_se3(WORLD_FRAME, &link.name, &link.offset));
            }
            Some(j) if j.body.is_none() => {
                let p = frame_placement(model, &data, j.parent_link);
                let c = frame_placement(model, &data, j.child_link);
                let parent = &model.links[j.parent_link].name;
                static_tf.push(transform_from_se3(parent, &link.name, &p.inv_mul(&c)));
            }
            _ => {}
        }
    }
    Header {
        name: name.to_string(),
        joint_names: model.dof_names(),
        effort_limits: model
            .effort_limit
            .iter()
            .map(|&e| (e.is_finite() && e > 0.0).then_some(e))
            .collect(),
        static_tf,
        robot_description: model.urdf_text.clone(),
        metadata: vec![
            ("robot".to_string(), model.name.clone()),
            ("model_source".to_string(), model.source.clone()),
            (
                "armsim_version".to_string(),
                env!("CARGO_PKG_VERSION").to_string(),
            ),
        ],
    }
}

/// One frame at time `t`: runs forward kinematics for `q` into `data` and records every
/// movable joint's parent link → child link transform. `qd` and `tau` are stored as given
/// (empty when unknown).
///
/// # Panics
/// When `q.len() != model.nv` (as [`forward_kinematics`]).
pub fn frame_from_state(
    model: &Model,
    data: &mut Data,
    t: f64,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
) -> Frame {
    forward_kinematics(model, data, q);
    let tf = model
        .joints
        .iter()
        .filter(|j| j.body.is_some())
        .map(|j| {
            let p = frame_placement(model, data, j.parent_link);
            let c = frame_placement(model, data, j.child_link);
            transform_from_se3(
                &model.links[j.parent_link].name,
                &model.links[j.child_link].name,
                &p.inv_mul(&c),
            )
        })
        .collect();
    Frame {
        t,
        q: q.to_vec(),
        qd: qd.to_vec(),
        tau: tau.to_vec(),
        tf,
    }
}
