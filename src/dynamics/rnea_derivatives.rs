//! Analytical derivatives of inverse dynamics: `∂τ/∂q`, `∂τ/∂q̇` and `∂τ/∂q̈ = M`
//! (Carpentier & Mansard, *Analytical Derivatives of Rigid Body Dynamics Algorithms*,
//! RSS 2018, Alg. 1), in the world frame for one-axis joints. With `S_k` joint `k`'s
//! world motion subspace, `λ = λ(k)` its parent and `×`, `×*` the motion and force cross
//! products:
//!
//! - forward pass: `v_i = v_λ + S_i q̇_i`, `a_i = a_λ + S_i q̈_i + (v_λ × S_i) q̇_i`
//!   (`a_0 = −g`); `Y_i = ⁰X_i^* I_i ⁱX_0`, `f_i = Y_i a_i + v_i ×* Y_i v_i − f^ext_i`; the
//!   momentum variation `Ẏ_i = v_i ×* Y_i − Y_i v_i× + (· ×* Y_i v_i)`; and per joint
//!   `∂v_k = v_λ × S_k`, `∂a_k = a_λ × S_k + v_λ × ∂v_k`, `∂a^v_k = 2 ∂v_k`, so that for
//!   `k ⪯ i`: `∂v_i/∂q_k = S_k × v_i + ∂v_k`, `∂a_i/∂q_k = S_k × a_i + ∂v_k × v_i + ∂a_k`,
//!   `∂a_i/∂q̇_k = S_k × v_i + ∂a^v_k`;
//! - backward pass, with the subtree sums `Y_j`, `Ẏ_j`, `F_j = Σ f_i` and `τ_j = S_jᵀ F_j`
//!   (the rotation of a subtree about `S_k` cancels in `τ_j` for `k ⪯ j`):
//!   - `k ⪯ j`: `∂τ_j/∂q_k = S_jᵀ(Y_j ∂a_k + Ẏ_j ∂v_k)`,
//!     `∂τ_j/∂q̇_k = S_jᵀ(Y_j ∂a^v_k + Ẏ_j S_k)`, `M_jk = S_jᵀ Y_j S_k`;
//!   - `j ≺ k`: the same with `k`'s subtree sums, plus `S_jᵀ(S_k ×* F_k)` in `∂τ_j/∂q_k`.
//!
//! External wrenches (body frame, so turning with their body), a payload and armature
//! (on `M`'s diagonal) enter as in [`crate::dynamics::rnea`]. Mimic joints: entries are
//! scaled by both bodies' multipliers and summed onto the independent coordinates.

use crate::core::spatial::{Force, InertiaO, Mat3, Motion, Vec3};
use crate::dynamics::rnea::add_armature;
use crate::dynamics::rnea_derivatives_chain::takes_chain_columns;
use crate::dynamics::terms::Terms;
use crate::kinematics::{body_rate, forward_kinematics, world_subspace};
use crate::model::data::Data;
use crate::model::derivative_data::MomentumVariation;
use crate::model::{Model, WORLD};
use nalgebra::DMatrix;

/// The partial derivatives of `τ = ID(q, q̇, q̈)` ([`rnea_derivatives`]), held in
/// [`Data::deriv`].
#[derive(Clone, Copy, Debug)]
pub struct RneaPartials<'a> {
    /// `∂τ/∂q`, nv × nv.
    pub dtau_dq: &'a DMatrix<f64>,
    /// `∂τ/∂q̇`, nv × nv.
    pub dtau_dv: &'a DMatrix<f64>,
    /// `∂τ/∂q̈ = M(q)`, armature included.
    pub mass: &'a DMatrix<f64>,
}

/// `∂τ/∂q`, `∂τ/∂q̇` and `M` at `(q, q̇, q̈)` with the model's gravity and armature, as
/// Pinocchio's `computeRNEADerivatives(model, data, q, v, a)`; `data.tau` gets `τ`.
pub fn rnea_derivatives<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    v: &[f64],
    a: &[f64],
) -> RneaPartials<'a> {
    rnea_derivatives_impl(model, data, q, v, a, &Terms::of_model(model));
    rnea_partials(data)
}

/// [`rnea_derivatives`] with one external wrench per body (body frame).
pub fn rnea_derivatives_with_forces<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    f_ext: &[Force],
) -> RneaPartials<'a> {
    assert_eq!(
        f_ext.len(),
        model.nbodies(),
        "f_ext needs one wrench per body"
    );
    rnea_derivatives_impl(model, data, q, v, a, &Terms::with_forces(model, f_ext));
    rnea_partials(data)
}

pub(crate) fn rnea_partials(data: &Data) -> RneaPartials<'_> {
    RneaPartials {
        dtau_dq: &data.deriv.dtau_dq,
        dtau_dv: &data.deriv.dtau_dv,
        mass: &data.deriv.dtau_da,
    }
}

/// [`rnea_derivatives`] with the additions in `terms`.
pub(crate) fn rnea_derivatives_impl(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    terms: &Terms<'_>,
) {
    let nv = model.nv;
    assert!(
        q.len() == nv && qd.len() == nv && qdd.len() == nv,
        "q, v, a need nv values"
    );
    data.deriv.ensure(model);
    forward_kinematics(model, data, q);
    forward_pass(model, data, qd, qdd, terms);
    backward_pass(model, data, terms);
    add_armature(model, terms, qdd, &mut data.tau);
}

/// `Ẏ = v ×* Y − Y v× + (· ×* Y v)` for a body of inertia `y` at velocity `v` with
/// momentum `p = Y v`. In blocks (`Y = [[m 1, −[h]×], [[h]×, I_O]]`) its force block is
/// `−2 [p_f]×` and its moment block `[ω]× I_O − I_O [ω]× − [v]×[h]× − [h]×[v]× − [p_n]×`;
/// the linear part of the motion it acts on drops out.
fn momentum_variation(y: &InertiaO, v: &Motion, p: &Force) -> MomentumVariation {
    let w = crate::core::spatial::skew(&v.w);
    // [ω]× I_O − I_O [ω]× = W + Wᵀ with W = [ω]× I_O (I_O symmetric, [ω]× skew).
    let wi = w * y.i_o;
    let vh = v.v.dot(&y.h);
    let c = wi + wi.transpose() - (y.h * v.v.transpose() + v.v * y.h.transpose())
        + Mat3::identity() * (2.0 * vh)
        - crate::core::spatial::skew(&p.n);
    MomentumVariation { a: p.f * -2.0, c }
}

/// Velocities, accelerations, world inertias, forces and the per-joint partial motions.
pub(crate) fn forward_pass(
    model: &Model,
    data: &mut Data,
    qd: &[f64],
    qdd: &[f64],
    terms: &Terms<'_>,
) {
    let a0 = terms
        .gravity
        .map_or(Motion::zero(), |g| Motion::new(-g, Vec3::zeros()));
    let d = &mut data.deriv;
    for i in 0..model.nbodies() {
        let o = data.o_m_i[i];
        let s = world_subspace(model.kind[i], &o);
        data.s_world[i] = s;
        let parent = model.parent[i];
        let (vp, ap) = if parent == WORLD {
            (Motion::zero(), a0)
        } else {
            (d.ov[parent], d.oa[parent])
        };
        let rate = body_rate(model, qd, i);
        let dv = vp.cross_motion(&s);
        let v = vp.add(&s.scale(rate));
        let a = ap
            .add(&s.scale(body_rate(model, qdd, i)))
            .add(&dv.scale(rate));
        let mut y = model.inertia_o[i].transformed(&o);
        if let Some((pb, ip)) = terms.payload {
            if pb == i {
                y = y.add(&ip.transformed(&o));
            }
        }
        let p = y.mul_motion(&v);
        let mut f = y.mul_motion(&a).add(&v.cross_force(&p));
        if let Some(fe) = terms.f_ext {
            let w = o.act_force(&fe[i]);
            f.f -= w.f;
            f.n -= w.n;
        }
        d.ov[i] = v;
        d.oa[i] = a;
        d.dv_dq[i] = dv;
        d.da_dq[i] = ap.cross_motion(&s).add(&vp.cross_motion(&dv));
        d.da_dv[i] = dv.scale(2.0);
        d.oy[i] = y;
        d.doy[i] = momentum_variation(&y, &v, &p);
        d.of[i] = f;
    }
}

/// `τ` and the three partials from the subtree sums, walking each joint's ancestors once
/// for its row (`k ⪯ j`) and once for its column (`j ≺ k`); long serial chains go column
/// by column instead ([`crate::dynamics::rnea_derivatives_chain`]).
pub(crate) fn backward_pass(model: &Model, data: &mut Data, terms: &Terms<'_>) {
    if takes_chain_columns(model) {
        crate::dynamics::rnea_derivatives_chain::backward_pass(model, data, terms);
    } else if model.has_mimic {
        backward_walks::<true>(model, data, terms);
    } else {
        backward_walks::<false>(model, data, terms);
    }
}

/// [`backward_pass`]; with `SHARED` (mimic joints) several bodies may land on one entry,
/// which is then summed, else each entry is stored once.
fn backward_walks<const SHARED: bool>(model: &Model, data: &mut Data, terms: &Terms<'_>) {
    #[inline(always)]
    fn put<const SHARED: bool>(buf: &mut [f64], at: usize, x: f64) {
        if SHARED {
            buf[at] += x;
        } else {
            buf[at] = x;
        }
    }
    let n = model.nv;
    let d = &mut data.deriv;
    let dq = d.dtau_dq.as_mut_slice();
    let dv = d.dtau_dv.as_mut_slice();
    let da = d.dtau_da.as_mut_slice();
    dq.fill(0.0);
    dv.fill(0.0);
    da.fill(0.0);
    data.tau.fill(0.0);
    for i in (0..model.nbodies()).rev() {
        let (s, y, dy, f) = (data.s_world[i], d.oy[i], d.doy[i], d.of[i]);
        let (ci, mi) = (model.q_index[i], model.q_mult[i]);
        data.tau[ci] += mi * f.dot_motion(&s);
        let ys = y.mul_motion(&s);
        // Ẏᵀ S has no force part: pair its moment with angular parts only.
        let dys = dy.tr_mul_motion(&s).n;
        let mut k = i;
        while k != WORLD {
            let (ck, w) = (model.q_index[k], mi * model.q_mult[k]);
            let (sk, dvk) = (&data.s_world[k], &d.dv_dq[k]);
            let ys_dv = ys.dot_motion(dvk);
            let (row, col) = (ck * n + ci, ci * n + ck);
            put::<SHARED>(dq, row, w * (ys.dot_motion(&d.da_dq[k]) + dys.dot(&dvk.w)));
            put::<SHARED>(dv, row, w * (2.0 * ys_dv + dys.dot(&sk.w)));
            // M is symmetric: the column walk's entry (k, i) is this one.
            let mass = w * ys.dot_motion(sk);
            put::<SHARED>(da, row, mass);
            if k != i {
                put::<SHARED>(da, col, mass);
            }
            k = model.parent[k];
        }
        let fq = y
            .mul_motion(&d.da_dq[i])
            .add(&dy.mul_motion(&d.dv_dq[i]))
            .add(&s.cross_force(&f));
        let fv = y.mul_motion(&d.da_dv[i]).add(&dy.mul_motion(&s));
        let mut j = model.parent[i];
        while j != WORLD {
            let (at, w) = (ci * n + model.q_index[j], mi * model.q_mult[j]);
            let sj = &data.s_world[j];
            put::<SHARED>(dq, at, w * fq.dot_motion(sj));
            put::<SHARED>(dv, at, w * fv.dot_motion(sj));
            j = model.parent[j];
        }
        let parent = model.parent[i];
        if parent != WORLD {
            d.oy[parent] = d.oy[parent].add(&y);
            d.doy[parent] = d.doy[parent].add(&dy);
            d.of[parent] = d.of[parent].add(&f);
        }
    }
    for k in 0..n {
        da[k * n + k] += terms.armature(model, k);
    }
}

/// Adds the joint accelerations `q̈` to a forward pass run with `q̈ = 0`: everything is
/// affine in `q̈`, through `a_i += Σ_{j⪯i} S_j q̈_j` (world frame), so `f_i += Y_i δa_i`
/// and `∂a_k += δa_λ × S_k`. Used where `q̈` is known only after the bias forces (ABA
/// derivatives).
pub(crate) fn add_joint_accelerations(model: &Model, data: &mut Data, qdd: &[f64]) {
    let d = &mut data.deriv;
    for i in 0..model.nbodies() {
        let s = data.s_world[i];
        let parent = model.parent[i];
        let mine = s.scale(body_rate(model, qdd, i));
        let da = if parent == WORLD {
            mine
        } else {
            let dp = d.acc[parent];
            d.da_dq[i] = d.da_dq[i].add(&dp.cross_motion(&s));
            dp.add(&mine)
        };
        d.acc[i] = da;
        d.oa[i] = d.oa[i].add(&da);
        d.of[i] = d.of[i].add(&d.oy[i].mul_motion(&da));
    }
}
