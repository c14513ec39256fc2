//! Link transforms of a [`Model`] as recording [`Transform`]s, in the frame tree of the
//! robot description `urdf_out` gives the model, split the way `robot_state_publisher`
//! splits them: fixed joints (and a base offset) are static, movable joints change with `q`.
//!
//! Owned here: [`RobotTf`] (the tree, built once per model) and the [`Se3`] ↔ [`Transform`]
//! conversions ([`to_transform`], [`to_se3`]). For a URDF model the tree is the URDF's; for
//! a DH table it includes the generated URDF's `world` link and `<link>_joint_frame`
//! links, so that `/tf` and `/robot_description` describe the same tree in viewers.

use crate::core::spatial::{Mat3, Se3, Vec3};
use crate::io::record::urdf_out::urdf_layout;
use crate::io::record::{Frame, Transform};
use crate::kinematics::{forward_kinematics, frame_placement};
use crate::model::data::Data;
use crate::model::{Model, ModelSpec, WORLD};
use nalgebra::{Quaternion, Rotation3, UnitQuaternion};

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

/// One movable joint's transform: parent link → the joint's child frame.
#[derive(Clone, Debug)]
struct Moving {
    parent_link: usize,
    child_link: usize,
    parent: String,
    child: String,
    /// Child link → the joint's URDF child frame, for joints with a distal offset.
    to_frame: Option<Se3>,
}

/// The frame tree of a model's robot description (see the module docs).
#[derive(Clone, Debug)]
pub struct RobotTf {
    moving: Vec<Moving>,
    statics: Vec<Transform>,
}

impl RobotTf {
    /// The tree of `model`, built from `spec` (the spec it was built from, for the names and
    /// distal offsets of the generated URDF).
    pub fn new(model: &Model, spec: &ModelSpec) -> Self {
        let layout = urdf_layout(spec);
        let mut data = Data::new(model);
        forward_kinematics(model, &mut data, &vec![0.0; model.nv]);
        let place = |l: usize| frame_placement(model, &data, l);
        let name = |l: usize| model.links[l].name.as_str();
        let mut statics = Vec::new();
        if let Some(world) = &layout.world {
            for (l, link) in model.links.iter().enumerate() {
                if link.parent_joint.is_none() && link.body == WORLD {
                    statics.push(to_transform(world, name(l), &place(l)));
                }
            }
        }
        let mut moving = Vec::new();
        for j in &model.joints {
            let (p, c) = (j.parent_link, j.child_link);
            if !j.jtype.is_movable() {
                statics.push(to_transform(name(p), name(c), &place(p).inv_mul(&place(c))));
                continue;
            }
            let offset = layout.joint_frames.get(&j.name).and_then(|mid| {
                let js = spec.joints.iter().find(|s| s.name == j.name)?;
                Some((mid.clone(), js.child_offset))
            });
            let (child, to_frame) = match offset {
                Some((mid, off)) => {
                    statics.push(to_transform(&mid, name(c), &off));
                    (mid, Some(off.inverse()))
                }
                None => (name(c).to_string(), None),
            };
            moving.push(Moving {
                parent_link: p,
                child_link: c,
                parent: name(p).to_string(),
                child,
                to_frame,
            });
        }
        RobotTf { moving, statics }
    }

    /// The transforms that never change (for `Header::static_tf`).
    pub fn static_transforms(&self) -> Vec<Transform> {
        self.statics.clone()
    }

    /// The movable joints' transforms from the placements in `data` (after
    /// [`forward_kinematics`]), in joint (tree) order.
    pub fn joint_transforms(&self, model: &Model, data: &Data) -> Vec<Transform> {
        self.moving
            .iter()
            .map(|m| {
                let parent = frame_placement(model, data, m.parent_link);
                let child = frame_placement(model, data, m.child_link);
                let mut rel = parent.inv_mul(&child);
                if let Some(f) = &m.to_frame {
                    rel = rel.mul(f);
                }
                to_transform(&m.parent, &m.child, &rel)
            })
            .collect()
    }

    /// A recording frame at time `t`: runs forward kinematics for `q` into `data` and
    /// collects [`RobotTf::joint_transforms`]. `qd` and `tau` may be empty.
    pub fn frame_at(
        &self,
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
            tf: self.joint_transforms(model, data),
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::core::spatial::rpy_to_matrix;
    use crate::io::record::tf::*;

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
