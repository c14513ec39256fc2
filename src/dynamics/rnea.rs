//! Recursive Newton–Euler inverse dynamics, `τ = ID(q, q̇, q̈, f_ext)` (RBDA Table 5.1,
//! in body coordinates):
//!
//! - forward pass: `v_i = ⁱX_λ v_λ + S_i q̇_i`,
//!   `a_i = ⁱX_λ a_λ + S_i q̈_i + v_i ×ₘ S_i q̇_i`, with `a_0 = −g` (gravity as a
//!   fictitious base acceleration), and `f_i = I_i a_i + v_i ×_f I_i v_i − f_i^ext`;
//! - backward pass: `τ_i = S_iᵀ f_i`, `f_λ += ᵡX_i^* f_i`.
//!
//! Armature (`model.armature`, plus the rotor effect's) adds `I_a,k q̈_k` to `τ_k`.
//!
//! Mimic joints: a body driven by `q_k` through `θ = m q_k + o` adds `m S_iᵀ f_i` to `τ_k`
//! (the projection `Gᵀ τ` onto the independent coordinates).

use crate::core::spatial::{Force, Motion, Vec3};
use crate::dynamics::terms::Terms;
use crate::kinematics::{body_q, body_rate, joint_motion, joint_transform};
use crate::model::data::Data;
use crate::model::{BodyKind, Model, WORLD};

/// `S_iᵀ f` for a body whose joint moves about/along axis `kind`.
#[inline(always)]
pub(crate) fn project(kind: BodyKind, f: &Force) -> f64 {
    match kind {
        BodyKind::RevoluteX => f.n.x,
        BodyKind::RevoluteY => f.n.y,
        BodyKind::RevoluteZ => f.n.z,
        BodyKind::PrismaticX => f.f.x,
        BodyKind::PrismaticY => f.f.y,
        BodyKind::PrismaticZ => f.f.z,
    }
}

/// Inverse dynamics `τ = M(q) q̈ + C(q, q̇) q̇ + g(q)` into `data.tau` (also returned),
/// with the model's gravity (`model.gravity`) and armature (`model.armature`), as
/// Pinocchio's `rnea(model, data, q, v, a)`.
pub fn rnea<'a>(model: &Model, data: &'a mut Data, q: &[f64], v: &[f64], a: &[f64]) -> &'a [f64] {
    rnea_impl(model, data, q, v, a, &Terms::of_model(model))
}

/// [`rnea`] with external forces: `f_ext` holds one wrench per body (`model.nbodies()`),
/// in the body frame; they are subtracted from the bodies' net forces.
pub fn rnea_with_forces<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    f_ext: &[Force],
) -> &'a [f64] {
    assert_eq!(
        f_ext.len(),
        model.nbodies(),
        "f_ext needs one wrench per body"
    );
    rnea_impl(model, data, q, v, a, &Terms::with_forces(model, f_ext))
}

/// [`rnea`] with the additions in `terms` (gravity optional: `None` skips the gravity
/// code; forces; a payload; extra armature).
pub(crate) fn rnea_impl<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    terms: &Terms<'_>,
) -> &'a [f64] {
    let nv = model.nv;
    assert!(
        q.len() == nv && qd.len() == nv && qdd.len() == nv,
        "q, qd, qdd need nv values"
    );
    let (f_ext, payload) = (terms.f_ext, terms.payload);
    let a0 = terms.gravity.map(|g| Motion::new(-g, Vec3::zeros()));
    for i in 0..model.nbodies() {
        let kind = model.kind[i];
        let li = joint_transform(&model.placement[i], kind, body_q(model, q, i));
        let vj = joint_motion(kind, body_rate(model, qd, i));
        let aj = joint_motion(kind, body_rate(model, qdd, i));
        let parent = model.parent[i];
        let (v, a) = if parent == WORLD {
            match &a0 {
                Some(a0) => (vj, li.act_inv_motion(a0).add(&aj)),
                None => (vj, aj),
            }
        } else {
            let v = li.act_inv_motion(&data.v[parent]).add(&vj);
            let a = li
                .act_inv_motion(&data.a[parent])
                .add(&aj)
                .add(&v.cross_motion(&vj));
            (v, a)
        };
        let inertia = &model.inertia_o[i];
        let mut f = inertia
            .mul_motion(&a)
            .add(&v.cross_force(&inertia.mul_motion(&v)));
        if let Some(fe) = f_ext {
            f.f -= fe[i].f;
            f.n -= fe[i].n;
        }
        if let Some((pb, ip)) = payload {
            if pb == i {
                f = f
                    .add(&ip.mul_motion(&a))
                    .add(&v.cross_force(&ip.mul_motion(&v)));
            }
        }
        data.li_m_i[i] = li;
        data.v[i] = v;
        data.a[i] = a;
        data.f[i] = f;
    }
    data.tau.fill(0.0);
    for i in (0..model.nbodies()).rev() {
        let f = data.f[i];
        data.tau[model.q_index[i]] += model.q_mult[i] * project(model.kind[i], &f);
        let parent = model.parent[i];
        if parent != WORLD {
            let fp = data.li_m_i[i].act_force(&f);
            data.f[parent] = data.f[parent].add(&fp);
        }
    }
    add_armature(model, terms, qdd, &mut data.tau);
    &data.tau
}

/// `τ_k += I_a,k q̈_k` for the coordinates with armature (zero armature adds nothing, not
/// even a signed zero).
pub(crate) fn add_armature(model: &Model, terms: &Terms<'_>, qdd: &[f64], tau: &mut [f64]) {
    for (k, (t, a)) in tau.iter_mut().zip(qdd).enumerate() {
        let ia = terms.armature(model, k);
        if ia != 0.0 {
            *t += ia * a;
        }
    }
}

/// Bias forces `h(q, q̇) = C(q, q̇) q̇ + g(q)` (Pinocchio's `nle`): [`rnea`] with
/// `q̈ = 0`, into `data.tau`.
pub fn bias<'a>(model: &Model, data: &'a mut Data, q: &[f64], v: &[f64]) -> &'a [f64] {
    let zero = std::mem::take(&mut data.scratch_nv);
    rnea(model, data, q, v, &zero);
    data.scratch_nv = zero;
    &data.tau
}

/// Generalised gravity `g(q)` with `model.gravity`: [`rnea`] with `q̇ = q̈ = 0`, into
/// `data.tau`.
pub fn gravity_torque<'a>(model: &Model, data: &'a mut Data, q: &[f64]) -> &'a [f64] {
    let zero = std::mem::take(&mut data.scratch_nv);
    rnea(model, data, q, &zero, &zero);
    data.scratch_nv = zero;
    &data.tau
}
