//! Articulated-body algorithm, `q̈ = FD(q, q̇, τ, f_ext)` in O(n) (RBDA Table 7.1, body
//! coordinates):
//!
//! 1. forward: `v_i`, `c_i = v_i ×ₘ S_i q̇_i`, `I^A_i = I_i`, `p^A_i = v_i ×_f I_i v_i − f^ext_i`;
//! 2. backward: `U_i = I^A_i S_i`, `D_i = S_iᵀ U_i`, `u_i = τ_i − S_iᵀ p^A_i`;
//!    `I^a = I^A_i − U_i D_i⁻¹ U_iᵀ`, `p^a = p^A_i + I^a c_i + U_i D_i⁻¹ u_i`,
//!    `I^A_λ += λX_i^* I^a ⁱX_λ`, `p^A_λ += λX_i^* p^a`;
//! 3. forward: `a'_i = ⁱX_λ a_λ + c_i` (`a_0 = −g`), `q̈_i = D_i⁻¹(u_i − U_iᵀ a'_i)`,
//!    `a_i = a'_i + S_i q̈_i`.
//!
//! Armature (`model.armature`, plus the rotor effect's) is added to `D_i`.
//!
//! Every body must be driven by its own coordinate (no mimic joints: with those, forward
//! dynamics goes through the projected mass matrix, see [`crate::dynamics::forward_dynamics`]).

use crate::core::spatial::{skew, Force, Mat3, Motion, Se3, Vec3};
use crate::dynamics::terms::Terms;
use crate::kinematics::{body_q, body_rate, joint_motion, joint_transform};
use crate::model::data::Data;
use crate::model::{Model, WORLD};
use nalgebra::{Matrix6, Vector6};

#[inline(always)]
fn fvec(f: &Force) -> Vector6<f64> {
    Vector6::new(f.f.x, f.f.y, f.f.z, f.n.x, f.n.y, f.n.z)
}

#[inline(always)]
fn to_force(v: &Vector6<f64>) -> Force {
    Force::new(Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]))
}

#[inline(always)]
fn mvec(m: &Motion) -> Vector6<f64> {
    Vector6::new(m.v.x, m.v.y, m.v.z, m.w.x, m.w.y, m.w.z)
}

/// `λX_i^* I ⁱX_λ`: a 6×6 inertia in child coordinates moved to the parent, in blocks.
/// With `I = [[A, B], [Bᵀ, C]]`, rotate (`A' = R A Rᵀ`, …) then shift by `P = [p]×`:
/// `A'' = A'`, `B'' = B' − A' P`, `C'' = C' + P B' − B'ᵀ P − P A' P`.
#[inline]
pub fn inertia_to_parent(x: &Se3, i: &Matrix6<f64>) -> Matrix6<f64> {
    let r = &x.rot;
    let rt = r.transpose();
    let a: Mat3 = i.fixed_view::<3, 3>(0, 0).into_owned();
    let b: Mat3 = i.fixed_view::<3, 3>(0, 3).into_owned();
    let c: Mat3 = i.fixed_view::<3, 3>(3, 3).into_owned();
    let a1 = r * a * rt;
    let b1 = r * b * rt;
    let c1 = r * c * rt;
    let p = skew(&x.trans);
    let ap = a1 * p;
    let pb = p * b1;
    let b2 = b1 - ap;
    let c2 = c1 + pb + pb.transpose() - p * ap;
    let mut out = Matrix6::zeros();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&a1);
    out.fixed_view_mut::<3, 3>(0, 3).copy_from(&b2);
    out.fixed_view_mut::<3, 3>(3, 0).copy_from(&b2.transpose());
    out.fixed_view_mut::<3, 3>(3, 3).copy_from(&c2);
    out
}

/// Forward dynamics `q̈` by ABA into `data.qdd` (also returned), with the model's gravity
/// and armature, as Pinocchio's `aba(model, data, q, v, tau)`. No check of the result
/// (see [`crate::dynamics::forward_dynamics`] for the checked dispatcher). Panics if the model has
/// mimic joints.
pub fn aba<'a>(model: &Model, data: &'a mut Data, q: &[f64], v: &[f64], tau: &[f64]) -> &'a [f64] {
    aba_impl(model, data, q, v, tau, &Terms::of_model(model))
}

/// [`aba`] with external forces: one wrench per body (`model.nbodies()`), body frame.
pub fn aba_with_forces<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    f_ext: &[Force],
) -> &'a [f64] {
    assert_eq!(
        f_ext.len(),
        model.nbodies(),
        "f_ext needs one wrench per body"
    );
    aba_impl(model, data, q, v, tau, &Terms::with_forces(model, f_ext))
}

/// [`aba`] with the additions in `terms` (gravity optional, forces, a payload inertia on
/// one body, rotor armature `I_m N²` on top of the model's: added to `D_i`, RBDA §7.3
/// with rotor inertia).
pub(crate) fn aba_impl<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    terms: &Terms<'_>,
) -> &'a [f64] {
    let (f_ext, payload) = (terms.f_ext, terms.payload);
    let nv = model.nv;
    assert!(
        q.len() == nv && qd.len() == nv && tau.len() == nv,
        "q, qd, tau need nv values"
    );
    assert!(
        !model.has_mimic,
        "ABA needs one coordinate per body; use forward_dynamics"
    );
    let nb = model.nbodies();
    for i in 0..nb {
        let kind = model.kind[i];
        let li = joint_transform(&model.placement[i], kind, body_q(model, q, i));
        let vj = joint_motion(kind, body_rate(model, qd, i));
        let parent = model.parent[i];
        let (v, c) = if parent == WORLD {
            (vj, Motion::zero())
        } else {
            let v = li.act_inv_motion(&data.v[parent]).add(&vj);
            (v, v.cross_motion(&vj))
        };
        let inertia = &model.inertia_o[i];
        let mut pa = v.cross_force(&inertia.mul_motion(&v));
        data.ia[i] = model.inertia6[i];
        if let Some((pb, ip)) = payload {
            if pb == i {
                pa = pa.add(&v.cross_force(&ip.mul_motion(&v)));
                data.ia[i] += ip.to_matrix();
            }
        }
        if let Some(fe) = f_ext {
            pa.f -= fe[i].f;
            pa.n -= fe[i].n;
        }
        data.li_m_i[i] = li;
        data.v[i] = v;
        data.c[i] = c;
        data.pa[i] = fvec(&pa);
    }
    for i in (0..nb).rev() {
        let kind = model.kind[i];
        let s = kind.axis_index() + if kind.is_revolute() { 3 } else { 0 };
        let u_col: Vector6<f64> = data.ia[i].column(s).into_owned();
        let d = u_col[s] + terms.armature(model, model.q_index[i]);
        let d_inv = 1.0 / d;
        // Body coordinate θ = m q + o: its generalised force is τ / m.
        let u = tau[model.q_index[i]] / model.q_mult[i] - data.pa[i][s];
        data.u_col[i] = u_col;
        data.d_inv[i] = d_inv;
        data.u[i] = u;
        let parent = model.parent[i];
        if parent != WORLD {
            let ia = data.ia[i] - u_col * u_col.transpose() * d_inv;
            let pa = data.pa[i] + ia * mvec(&data.c[i]) + u_col * (u * d_inv);
            let li = data.li_m_i[i];
            let moved = inertia_to_parent(&li, &ia);
            data.ia[parent] += moved;
            let fp = fvec(&li.act_force(&to_force(&pa)));
            data.pa[parent] += fp;
        }
    }
    let a0 = terms.gravity.map(|g| Motion::new(-g, Vec3::zeros()));
    for i in 0..nb {
        let li = data.li_m_i[i];
        let parent = model.parent[i];
        let a1 = if parent == WORLD {
            match &a0 {
                Some(a0) => li.act_inv_motion(a0),
                None => Motion::zero(),
            }
        } else {
            li.act_inv_motion(&data.a[parent]).add(&data.c[i])
        };
        let th_dd = data.d_inv[i] * (data.u[i] - data.u_col[i].dot(&mvec(&a1)));
        let kind = model.kind[i];
        data.a[i] = a1.add(&joint_motion(kind, th_dd));
        data.qdd[model.q_index[i]] = th_dd / model.q_mult[i];
    }
    &data.qdd
}

#[cfg(test)]
mod tests {
    use crate::core::spatial::{Inertia, InertiaO};
    use crate::dynamics::aba::*;

    #[test]
    fn block_transform_equals_explicit_product() {
        // λX_i^* I ⁱX_λ with ⁱX_λ = [[Rᵀ, −Rᵀ[p]×], [0, Rᵀ]] for X = (R, p) = λMi.
        let x = Se3::from_xyz_rpy([0.3, -0.1, 0.5], [0.7, -0.4, 1.2]);
        let i = InertiaO::from_inertia(&Inertia::new(
            1.7,
            Vec3::new(0.05, 0.1, -0.2),
            Mat3::new(0.1, 0.01, 0.0, 0.01, 0.2, -0.02, 0.0, -0.02, 0.15),
        ))
        .to_matrix();
        // An articulated inertia is a general symmetric matrix: perturb every block.
        let mut ia = i;
        for r in 0..6 {
            for c in 0..6 {
                ia[(r, c)] +=
                    0.01 * ((r * 7 + c * 3) % 5) as f64 + 0.01 * ((c * 7 + r * 3) % 5) as f64;
            }
        }
        let rt = x.rot.transpose();
        let mut m = Matrix6::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&rt);
        m.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(-rt * skew(&x.trans)));
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(&rt);
        let explicit = m.transpose() * ia * m;
        let fast = inertia_to_parent(&x, &ia);
        assert!(
            (explicit - fast).abs().max() < 1e-14,
            "{explicit} vs {fast}"
        );
        // For a rigid body it equals transforming the body itself.
        let rigid = InertiaO::from_inertia(&Inertia::new(
            1.7,
            Vec3::new(0.05, 0.1, -0.2),
            Mat3::identity() * 0.1,
        ));
        let moved = inertia_to_parent(&x, &rigid.to_matrix());
        assert!((moved - rigid.transformed(&x).to_matrix()).abs().max() < 1e-14);
    }
}
