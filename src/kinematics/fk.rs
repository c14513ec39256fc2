//! Forward kinematics: body placements `oMi`, spatial velocities and accelerations, and
//! link frame placements.
//!
//! Recursions (RBDA §3.3, eqs. 3.29–3.31 in Pinocchio's local-frame form):
//! - `liMi = placement_i · J_i(q_i)`, `oMi = oM_parent · liMi`;
//! - `v_i = liMi⁻¹ · v_parent + S_i q̇_i`;
//! - `a_i = liMi⁻¹ · a_parent + S_i q̈_i + v_i ×ₘ S_i q̇_i`,
//!
//! with `S_i = (0, e_k)` for revolute and `(e_k, 0)` for prismatic bodies, `e_k` the body's
//! joint axis (x, y or z of the body frame, see [`crate::model`]). Velocities and accelerations are
//! spatial quantities expressed in the body frame; `a` is Featherstone's spatial acceleration, not
//! the classical acceleration of a point (see [`frame_classical_acceleration`]).

use crate::core::spatial::{column, unit, Mat3, Motion, Se3, Vec3};
use crate::model::data::Data;
use crate::model::{BodyKind, Model, WORLD};

/// `R · R_k(q)`: columns `i, j` (the two axes other than `k`, in cyclic order) rotate,
/// column `k` stays.
#[inline(always)]
fn rotate_columns<const I: usize, const J: usize>(r: &Mat3, s: f64, c: f64) -> Mat3 {
    let mut out = *r;
    for row in 0..3 {
        let a = r[(row, I)];
        let b = r[(row, J)];
        out[(row, I)] = c * a + s * b;
        out[(row, J)] = c * b - s * a;
    }
    out
}

/// `(rot, trans) · J(q)` for the body's joint motion `J` (`Rx/Ry/Rz(q)` or
/// `Tx/Ty/Tz(q)`), without a general matrix product; `sin_cos()` gives `(sin q, cos q)`
/// (called for revolute joints only).
#[inline(always)]
fn apply_joint(
    r: Mat3,
    trans: Vec3,
    kind: BodyKind,
    q: f64,
    sin_cos: impl FnOnce() -> (f64, f64),
) -> Se3 {
    let rot = |f: fn(&Mat3, f64, f64) -> Mat3| {
        let (s, c) = sin_cos();
        Se3 {
            rot: f(&r, s, c),
            trans,
        }
    };
    let slide = |k: usize| Se3 {
        rot: r,
        trans: trans + column(&r, k) * q,
    };
    match kind {
        BodyKind::RevoluteX => rot(rotate_columns::<1, 2>),
        BodyKind::RevoluteY => rot(rotate_columns::<2, 0>),
        BodyKind::RevoluteZ => rot(rotate_columns::<0, 1>),
        BodyKind::PrismaticX => slide(0),
        BodyKind::PrismaticY => slide(1),
        BodyKind::PrismaticZ => slide(2),
    }
}

/// `placement · J(q)`: the joint placement relative to the parent body, `liMi`.
#[inline(always)]
pub fn joint_transform(placement: &Se3, kind: BodyKind, q: f64) -> Se3 {
    apply_joint(placement.rot, placement.trans, kind, q, || {
        crate::core::fastmath::sin_cos(q)
    })
}

/// `oM_parent · placement_i · J_i(q)`, using the signed-permutation form of the placement
/// rotation when there is one (a column shuffle instead of a 3×3 product).
#[inline(always)]
fn compose_body(model: &Model, i: usize, op: &Se3, q: f64, sc: impl FnOnce() -> (f64, f64)) -> Se3 {
    let pl = &model.placement[i];
    if model.placement_identity[i] {
        return apply_joint(op.rot, op.rot * pl.trans + op.trans, model.kind[i], q, sc);
    }
    let base = match &model.placement_perm[i] {
        Some(p) => {
            // Select among register values (a runtime column index would force the pose
            // through memory and stall on store forwarding).
            let c0 = Vec3::new(op.rot[(0, 0)], op.rot[(1, 0)], op.rot[(2, 0)]);
            let c1 = Vec3::new(op.rot[(0, 1)], op.rot[(1, 1)], op.rot[(2, 1)]);
            let c2 = Vec3::new(op.rot[(0, 2)], op.rot[(1, 2)], op.rot[(2, 2)]);
            let col = |c: usize| {
                let (row, sign) = p[c];
                let v = match row {
                    0 => c0,
                    1 => c1,
                    _ => c2,
                };
                v * sign
            };
            Mat3::from_columns(&[col(0), col(1), col(2)])
        }
        None => op.rot * pl.rot,
    };
    apply_joint(base, op.rot * pl.trans + op.trans, model.kind[i], q, sc)
}

/// Value of body `i`'s joint coordinate (mimic joints read their master).
#[inline(always)]
pub(crate) fn body_q(model: &Model, q: &[f64], i: usize) -> f64 {
    q[model.q_index[i]] * model.q_mult[i] + model.q_offset[i]
}

/// Rate of body `i`'s joint coordinate.
#[inline(always)]
pub(crate) fn body_rate(model: &Model, qd: &[f64], i: usize) -> f64 {
    qd[model.q_index[i]] * model.q_mult[i]
}

/// The joint motion `S_i · rate` in the body frame.
#[inline(always)]
pub(crate) fn joint_motion(kind: BodyKind, rate: f64) -> Motion {
    let e = unit(kind.axis_index(), rate);
    if kind.is_revolute() {
        Motion::new(Vec3::zeros(), e)
    } else {
        Motion::new(e, Vec3::zeros())
    }
}

fn check_q(model: &Model, q: &[f64]) {
    assert_eq!(
        q.len(),
        model.nv,
        "q has {} values, the model has {} coordinates",
        q.len(),
        model.nv
    );
}

/// Body `i`'s placement `oMi` from its parent's (`prev` when the parent is body `i − 1`:
/// in a chain the parent is the body just computed, and reloading it from `o_m_i` would
/// stall on store forwarding) and `(sin, cos)` of its angle.
#[inline(always)]
fn body_placement(
    model: &Model,
    data: &Data,
    i: usize,
    prev: &Se3,
    qi: f64,
    sc: impl FnOnce() -> (f64, f64),
) -> Se3 {
    let parent = model.parent[i];
    if parent == WORLD {
        let pl = &model.placement[i];
        apply_joint(pl.rot, pl.trans, model.kind[i], qi, sc)
    } else if parent + 1 == i {
        compose_body(model, i, prev, qi, sc)
    } else {
        let op = data.o_m_i[parent];
        compose_body(model, i, &op, qi, sc)
    }
}

/// Bodies per block of [`forward_kinematics`].
const SIN_COS_BLOCK: usize = 16;

/// Updates the body placements `o_m_i` for configuration `q` (length `nv`).
///
/// Block by block, the sines and cosines of the joint angles come first: they do not
/// depend on one another, so the CPU overlaps them, where inside the chain of placements
/// each one's latency would wait for the previous body (the same values, bit for bit;
/// from Python, Panda FK 202 → 182 ns). [`forward_kinematics_prefix`] keeps the plain
/// loop, which measured faster inside `compute_frame_jacobian`.
pub fn forward_kinematics(model: &Model, data: &mut Data, q: &[f64]) {
    check_q(model, q);
    let end = model.nbodies();
    let mut sc = [(0.0, 1.0); SIN_COS_BLOCK];
    let mut prev = Se3::identity();
    for start in (0..end).step_by(SIN_COS_BLOCK) {
        let block = start..(start + SIN_COS_BLOCK).min(end);
        for (k, i) in block.clone().enumerate() {
            if model.kind[i].is_revolute() {
                sc[k] = crate::core::fastmath::sin_cos(body_q(model, q, i));
            }
        }
        for (k, i) in block.enumerate() {
            let cur = body_placement(model, data, i, &prev, body_q(model, q, i), || sc[k]);
            data.o_m_i[i] = cur;
            prev = cur;
        }
    }
}

/// Updates the placements `o_m_i` of bodies `0..end` only (parents come before their
/// children, so `0..=b` holds the support of body `b`); later bodies keep their values.
/// The same values as [`forward_kinematics`], bit for bit.
#[inline(always)]
pub(crate) fn forward_kinematics_prefix(model: &Model, data: &mut Data, q: &[f64], end: usize) {
    check_q(model, q);
    let mut prev = Se3::identity();
    for i in 0..end.min(model.nbodies()) {
        let qi = body_q(model, q, i);
        let cur = body_placement(model, data, i, &prev, qi, || {
            crate::core::fastmath::sin_cos(qi)
        });
        data.o_m_i[i] = cur;
        prev = cur;
    }
}

/// Placements, joint placements `li_m_i` and body velocities `v` for `(q, qd)`.
pub fn forward_kinematics_vel(model: &Model, data: &mut Data, q: &[f64], qd: &[f64]) {
    assert_eq!(qd.len(), model.nv);
    forward_kinematics(model, data, q);
    for i in 0..model.nbodies() {
        let li = joint_transform(&model.placement[i], model.kind[i], body_q(model, q, i));
        let vj = joint_motion(model.kind[i], body_rate(model, qd, i));
        let parent = model.parent[i];
        data.v[i] = if parent == WORLD {
            vj
        } else {
            li.act_inv_motion(&data.v[parent]).add(&vj)
        };
        data.li_m_i[i] = li;
    }
}

/// Placements, body velocities `v` and spatial accelerations `a` for `(q, qd, qdd)`.
pub fn forward_kinematics_acc(model: &Model, data: &mut Data, q: &[f64], qd: &[f64], qdd: &[f64]) {
    assert_eq!(qdd.len(), model.nv);
    forward_kinematics_vel(model, data, q, qd);
    for i in 0..model.nbodies() {
        let kind = model.kind[i];
        let vj = joint_motion(kind, body_rate(model, qd, i));
        let aj = joint_motion(kind, body_rate(model, qdd, i)).add(&data.v[i].cross_motion(&vj));
        let parent = model.parent[i];
        data.a[i] = if parent == WORLD {
            aj
        } else {
            data.li_m_i[i].act_inv_motion(&data.a[parent]).add(&aj)
        };
    }
}

/// Updates `o_m_f` (every link frame) from the current `o_m_i`.
pub fn update_frames(model: &Model, data: &mut Data) {
    for (out, link) in data.o_m_f.iter_mut().zip(&model.links) {
        *out = if link.body == WORLD {
            link.offset
        } else if link.offset_is_identity {
            data.o_m_i[link.body]
        } else {
            data.o_m_i[link.body].mul(&link.offset)
        };
    }
}

/// World placement of link `link` from the current `o_m_i`.
#[inline]
pub fn frame_placement(model: &Model, data: &Data, link: usize) -> Se3 {
    let l = &model.links[link];
    if l.body == WORLD {
        l.offset
    } else {
        data.o_m_i[l.body].mul(&l.offset)
    }
}

fn express(model: &Model, data: &Data, link: usize, local: Motion, expressed: Expressed) -> Motion {
    match expressed {
        Expressed::Local => local,
        Expressed::World => frame_placement(model, data, link).act_motion(&local),
        Expressed::WorldAligned => {
            let r = frame_placement(model, data, link).rot;
            Motion::new(r * local.v, r * local.w)
        }
    }
}

/// Spatial velocity of a link frame (needs [`forward_kinematics_vel`]).
pub fn frame_velocity(model: &Model, data: &Data, link: usize, expressed: Expressed) -> Motion {
    let l = &model.links[link];
    if l.body == WORLD {
        return Motion::zero();
    }
    let local = l.offset.act_inv_motion(&data.v[l.body]);
    express(model, data, link, local, expressed)
}

/// Spatial acceleration of a link frame (needs [`forward_kinematics_acc`]).
pub fn frame_acceleration(model: &Model, data: &Data, link: usize, expressed: Expressed) -> Motion {
    let l = &model.links[link];
    if l.body == WORLD {
        return Motion::zero();
    }
    let local = l.offset.act_inv_motion(&data.a[l.body]);
    express(model, data, link, local, expressed)
}

/// Classical acceleration of a link frame's origin and its angular acceleration, in the
/// frame (`Local`) or in world axes (`World`/`WorldAligned`): `a_classic = a.v + ω × v`.
pub fn frame_classical_acceleration(
    model: &Model,
    data: &Data,
    link: usize,
    expressed: Expressed,
) -> Motion {
    let l = &model.links[link];
    if l.body == WORLD {
        return Motion::zero();
    }
    let v = l.offset.act_inv_motion(&data.v[l.body]);
    let a = l.offset.act_inv_motion(&data.a[l.body]);
    let local = Motion::new(a.v + v.w.cross(&v.v), a.w);
    match expressed {
        Expressed::Local => local,
        _ => {
            let r = frame_placement(model, data, link).rot;
            Motion::new(r * local.v, r * local.w)
        }
    }
}

/// Which expression a Jacobian or velocity is given in (see [`crate::kinematics::jacobian`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Expressed {
    /// World axes, world origin as reference point.
    World,
    /// Frame axes, frame origin.
    Local,
    /// World axes, frame origin.
    WorldAligned,
}

impl Expressed {
    /// CLI spelling.
    pub fn as_str(&self) -> &'static str {
        match self {
            Expressed::World => "world",
            Expressed::Local => "local",
            Expressed::WorldAligned => "world-aligned",
        }
    }
}
