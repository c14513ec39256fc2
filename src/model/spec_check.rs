//! The numbers of a [`ModelSpec`](crate::model::ModelSpec)'s links and joints that no tree can
//! make meaningful: non-finite placements, axes and limits, a zero axis, a lower limit
//! above the upper one, negative friction or rotor inertia (inertias are checked in
//! [`crate::model::inertia_check`]).

use crate::core::spatial::Se3;
use crate::model::spec::{JointSpec, LinkSpec};
use crate::model::{Builder, ModelError};

impl Builder<'_> {
    pub(super) fn check_finite_se3(&self, t: &Se3) -> bool {
        t.rot.iter().all(|x| x.is_finite()) && t.trans.iter().all(|x| x.is_finite())
    }

    pub(super) fn check_link(&self, l: &LinkSpec) -> Result<(), ModelError> {
        for g in l.visuals.iter().chain(l.collisions.iter()) {
            if !self.check_finite_se3(&g.origin) {
                return Err(self.err_link(l, "geometry origin: non-finite number"));
            }
        }
        Ok(())
    }

    pub(super) fn check_joint(&self, j: &JointSpec) -> Result<(), ModelError> {
        if !self.check_finite_se3(&j.origin) || !self.check_finite_se3(&j.child_offset) {
            return Err(self.err_joint(j, "origin: non-finite number"));
        }
        if j.jtype.is_movable() {
            if !j.axis.iter().all(|x| x.is_finite()) {
                return Err(self.err_joint(j, "axis: non-finite number"));
            }
            if j.axis.norm() < 1e-9 {
                return Err(self.err_joint(j, "axis: zero vector"));
            }
        }
        let lim = &j.limits;
        for (name, v) in [
            ("lower", lim.lower),
            ("upper", lim.upper),
            ("velocity", lim.velocity),
            ("effort", lim.effort),
        ] {
            if v.is_nan() {
                return Err(self.err_joint(j, format!("limit: {name} is not a number")));
            }
        }
        if lim.lower > lim.upper {
            return Err(self.err_joint(
                j,
                format!(
                    "limit: lower limit {} is greater than upper limit {}",
                    lim.lower, lim.upper
                ),
            ));
        }
        if lim.velocity < 0.0 || lim.effort < 0.0 {
            return Err(self.err_joint(j, "limit: negative velocity or effort limit"));
        }
        for (name, v) in [
            ("damping", j.damping),
            ("friction", j.friction),
            ("motor_inertia", j.motor_inertia),
            ("gear_ratio", j.gear_ratio),
        ] {
            if !v.is_finite() {
                return Err(self.err_joint(j, format!("{name}: non-finite number")));
            }
        }
        if j.motor_inertia < 0.0 || j.damping < 0.0 || j.friction < 0.0 {
            return Err(self.err_joint(j, "negative damping, friction or motor inertia"));
        }
        if j.gear_ratio == 0.0 {
            return Err(self.err_joint(j, "gear_ratio: must not be zero"));
        }
        if let Some(m) = &j.mimic {
            if !m.multiplier.is_finite() || !m.offset.is_finite() {
                return Err(self.err_joint(j, "mimic: non-finite multiplier or offset"));
            }
        }
        Ok(())
    }
}
