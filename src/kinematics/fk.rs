//! Forward kinematics: body placements `oMi`, spatial velocities and accelerations, and
//! link frame placements.
//!
//! Recursions (RBDA §3.3, eqs. 3.29–3.31 in Pinocchio's local-frame form):
//! - `liMi = placement_i · J_i(q_i)`, `oMi = oM_parent · liMi`;
//! - `v_i = liMi⁻¹ · v_parent + S_i q̇_i`;
//! - `a_i = liMi⁻¹ · a_parent + S_i q̈_i + v_i ×ₘ S_i q̇_i`,
//!
//! with `S_i = (0, e_z)` for revolute and `(e_z, 0)` for prismatic bodies (every joint axis
//! is the body's local z, see [`crate::model`]). Velocities and accelerations are spatial
//! quantities expressed in the body frame; `a` is Featherstone's spatial acceleration, not
//! the classical acceleration of a point (see [`frame_classical_acceleration`]).

use super::jacobian::Expressed;
use crate::data::Data;
use crate::model::{BodyKind, Model, WORLD};
use crate::spatial::{Mat3, Motion, Se3, Vec3};

/// `placement · Rz(q)` or `placement · Tz(q)`, without a general matrix product.
#[inline(always)]
pub fn joint_transform(placement: &Se3, kind: BodyKind, q: f64) -> Se3 {
    match kind {
        BodyKind::Revolute => {
            let (s, c) = crate::fastmath::sin_cos(q);
            let r = &placement.rot;
            // Columns of R·Rz(q): (c r0 + s r1, −s r0 + c r1, r2).
            let rot = Mat3::new(
                c * r[(0, 0)] + s * r[(0, 1)],
                c * r[(0, 1)] - s * r[(0, 0)],
                r[(0, 2)],
                c * r[(1, 0)] + s * r[(1, 1)],
                c * r[(1, 1)] - s * r[(1, 0)],
                r[(1, 2)],
                c * r[(2, 0)] + s * r[(2, 1)],
                c * r[(2, 1)] - s * r[(2, 0)],
                r[(2, 2)],
            );
            Se3 {
                rot,
                trans: placement.trans,
            }
        }
        BodyKind::Prismatic => Se3 {
            rot: placement.rot,
            trans: placement.trans
                + Vec3::new(
                    placement.rot[(0, 2)],
                    placement.rot[(1, 2)],
                    placement.rot[(2, 2)],
                ) * q,
        },
    }
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
    match kind {
        BodyKind::Revolute => Motion::new(Vec3::zeros(), Vec3::new(0.0, 0.0, rate)),
        BodyKind::Prismatic => Motion::new(Vec3::new(0.0, 0.0, rate), Vec3::zeros()),
    }
}

/// Updates `li_m_i` and `o_m_i` for configuration `q` (length `nv`).
pub fn forward_kinematics(model: &Model, data: &mut Data, q: &[f64]) {
    assert_eq!(
        q.len(),
        model.nv,
        "q has {} values, the model has {} coordinates",
        q.len(),
        model.nv
    );
    let nb = model.nbodies();
    for i in 0..nb {
        let li = joint_transform(&model.placement[i], model.kind[i], body_q(model, q, i));
        let parent = model.parent[i];
        data.o_m_i[i] = if parent == WORLD {
            li
        } else {
            data.o_m_i[parent].mul(&li)
        };
        data.li_m_i[i] = li;
    }
}

/// Placements and body velocities `v` for `(q, qd)`.
pub fn forward_kinematics_vel(model: &Model, data: &mut Data, q: &[f64], qd: &[f64]) {
    assert_eq!(qd.len(), model.nv);
    forward_kinematics(model, data, q);
    for i in 0..model.nbodies() {
        let vj = joint_motion(model.kind[i], body_rate(model, qd, i));
        let parent = model.parent[i];
        data.v[i] = if parent == WORLD {
            vj
        } else {
            data.li_m_i[i].act_inv_motion(&data.v[parent]).add(&vj)
        };
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
    for (l, link) in model.links.iter().enumerate() {
        data.o_m_f[l] = if link.body == WORLD {
            link.offset
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
