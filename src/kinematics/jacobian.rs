//! Geometric Jacobians of link frames and their time derivatives.
//!
//! All three expressions map `q̇` to a spatial velocity `(v, ω)` (linear rows first):
//! - [`Expressed::World`]: the frame's spatial velocity in world coordinates, with the
//!   *world origin* as reference point: `v` is the velocity of the (body-fixed) point that
//!   currently coincides with the world origin. This is Pinocchio's `WORLD`; it is the same
//!   for every frame on a body.
//! - [`Expressed::Local`]: the frame's velocity in its own axes at its own origin
//!   (Pinocchio's `LOCAL`, the body Jacobian).
//! - [`Expressed::WorldAligned`]: `v` is the velocity of the frame's origin and `ω` the
//!   angular velocity, both in world axes (Pinocchio's `LOCAL_WORLD_ALIGNED`): the
//!   "classical" Jacobian `[ṗ; ω] = J q̇` used for task-space control and IK.
//!
//! Columns: the world motion subspace of body `i` is `S_i^w = Ad(oMi) S_i`; for a
//! revolute joint `(p_i × a_i, a_i)`, for a prismatic one `(a_i, 0)`, `a_i` its world axis. Its
//! derivative is `Ṡ_i^w = v_i^w ×ₘ S_i^w` (the world velocity of body `i`, RBDA eq. 2.36 with
//! Ad a Lie-algebra homomorphism). The other expressions follow from
//! `J_L = Ad(oMf)⁻¹ J_W`, `J̇_L = Ad(oMf)⁻¹ J̇_W − v_f ×ₘ J_L`, and
//! `J_A = [J_W,v + J_W,ω × p; J_W,ω]`, `J̇_A = [J̇_W,v + J̇_W,ω × p + J_W,ω × ṗ; J̇_W,ω]`.
//! Mimic joints add `multiplier ×` their column into their master's column.

use crate::core::spatial::{column, Motion, Se3};
use crate::kinematics::fk::{body_rate, forward_kinematics, forward_kinematics_prefix};
use crate::model::data::Data;
use crate::model::{BodyKind, Model, WORLD};
use nalgebra::DMatrix;

pub use crate::kinematics::fk::Expressed;

#[inline(always)]
pub(crate) fn world_subspace(kind: BodyKind, o_m_i: &Se3) -> Motion {
    let z = column(&o_m_i.rot, kind.axis_index());
    if kind.is_revolute() {
        Motion::new(o_m_i.trans.cross(&z), z)
    } else {
        Motion::new(z, z * 0.0)
    }
}

/// Forward kinematics plus every joint's world motion subspace `data.s_world`
/// (Pinocchio's `computeJointJacobians`).
pub fn compute_joint_jacobians(model: &Model, data: &mut Data, q: &[f64]) {
    forward_kinematics(model, data, q);
    for i in 0..model.nbodies() {
        data.s_world[i] = world_subspace(model.kind[i], &data.o_m_i[i]);
    }
}

/// [`compute_joint_jacobians`] plus body world velocities `data.v_world` and the
/// subspace derivatives `data.ds_world` for velocity `qd`.
pub fn compute_joint_jacobians_time_variation(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
) {
    assert_eq!(qd.len(), model.nv);
    compute_joint_jacobians(model, data, q);
    for i in 0..model.nbodies() {
        let s = data.s_world[i];
        let vj = s.scale(body_rate(model, qd, i));
        let parent = model.parent[i];
        let vw = if parent == WORLD {
            vj
        } else {
            data.v_world[parent].add(&vj)
        };
        data.v_world[i] = vw;
        data.ds_world[i] = vw.cross_motion(&s);
    }
}

fn check_out(model: &Model, out: &DMatrix<f64>) {
    assert_eq!(out.nrows(), 6, "a Jacobian has 6 rows");
    assert_eq!(out.ncols(), model.nv, "a Jacobian has nv columns");
}

#[inline(always)]
fn add_col(out: &mut DMatrix<f64>, k: usize, m: &Motion) {
    let mut c = out.column_mut(k);
    c[0] += m.v.x;
    c[1] += m.v.y;
    c[2] += m.v.z;
    c[3] += m.w.x;
    c[4] += m.w.y;
    c[5] += m.w.z;
}

/// Calls `add(column, motion)` for every body supporting `link`, from the frame up to the
/// root, with that body's column of the Jacobian in `expressed`; `s_world(i)` is body
/// `i`'s world motion subspace. A mimic body reports its master's column (to be added).
#[inline(always)]
fn support_columns(
    model: &Model,
    data: &Data,
    link: usize,
    expressed: Expressed,
    s_world: impl Fn(usize) -> Motion,
    mut add: impl FnMut(usize, &Motion),
) {
    let body = model.links[link].body;
    if body == WORLD {
        return;
    }
    let o_m_f = data.o_m_i[body].mul(&model.links[link].offset);
    let mut i = body;
    while i != WORLD {
        let s = s_world(i).scale(model.q_mult[i]);
        let col = match expressed {
            Expressed::World => s,
            Expressed::Local => o_m_f.act_inv_motion(&s),
            Expressed::WorldAligned => Motion::new(s.v + s.w.cross(&o_m_f.trans), s.w),
        };
        add(model.q_index[i], &col);
        i = model.parent[i];
    }
}

/// Jacobian of link `link` in `expressed` into `out` (6 × nv), from the data of
/// [`compute_joint_jacobians`]. Allocates nothing.
pub fn frame_jacobian(
    model: &Model,
    data: &Data,
    link: usize,
    expressed: Expressed,
    out: &mut DMatrix<f64>,
) {
    check_out(model, out);
    // On the contiguous storage: `DMatrix::fill` walks element by element.
    out.as_mut_slice().fill(0.0);
    support_columns(
        model,
        data,
        link,
        expressed,
        |i| data.s_world[i],
        |k, col| add_col(out, k, col),
    );
}

/// Pinocchio's `computeFrameJacobian`: forward kinematics of the bodies up to `link`'s
/// body (its support, plus in a tree the bodies numbered before it), then the Jacobian of
/// `link` in `expressed` into `out`, **row-major** 6 × nv (a C-ordered numpy array).
/// Equal bit for bit to [`compute_joint_jacobians`] + [`frame_jacobian`]; the placements
/// of later bodies and `s_world` keep their values. Allocates nothing.
pub fn compute_frame_jacobian(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    link: usize,
    expressed: Expressed,
    out: &mut [f64],
) {
    let nv = model.nv;
    assert_eq!(out.len(), 6 * nv, "a Jacobian has 6 × nv values");
    let body = model.links[link].body;
    let end = if body == WORLD { 0 } else { body + 1 };
    forward_kinematics_prefix(model, data, q, end);
    out.fill(0.0);
    let o_m_i = &data.o_m_i;
    support_columns(
        model,
        data,
        link,
        expressed,
        |i| world_subspace(model.kind[i], &o_m_i[i]),
        |k, m| {
            for (r, x) in [m.v.x, m.v.y, m.v.z, m.w.x, m.w.y, m.w.z]
                .into_iter()
                .enumerate()
            {
                out[r * nv + k] += x;
            }
        },
    );
}

/// Time derivative of [`frame_jacobian`] into `out`, from the data of
/// [`compute_joint_jacobians_time_variation`]. Allocates nothing.
pub fn frame_jacobian_time_variation(
    model: &Model,
    data: &Data,
    link: usize,
    expressed: Expressed,
    out: &mut DMatrix<f64>,
) {
    check_out(model, out);
    out.as_mut_slice().fill(0.0);
    let body = model.links[link].body;
    if body == WORLD {
        return;
    }
    let o_m_f = data.o_m_i[body].mul(&model.links[link].offset);
    let vw = data.v_world[body];
    let p = o_m_f.trans;
    // Frame velocities: local, and the world velocity of its origin.
    let v_local = o_m_f.act_inv_motion(&vw);
    let p_dot = vw.v + vw.w.cross(&p);
    let mut i = body;
    while i != WORLD {
        let m = model.q_mult[i];
        let s = data.s_world[i].scale(m);
        let ds = data.ds_world[i].scale(m);
        let col = match expressed {
            Expressed::World => ds,
            Expressed::Local => {
                let jl = o_m_f.act_inv_motion(&s);
                let djw = o_m_f.act_inv_motion(&ds);
                let c = v_local.cross_motion(&jl);
                Motion::new(djw.v - c.v, djw.w - c.w)
            }
            Expressed::WorldAligned => Motion::new(ds.v + ds.w.cross(&p) + s.w.cross(&p_dot), ds.w),
        };
        add_col(out, model.q_index[i], &col);
        i = model.parent[i];
    }
}
