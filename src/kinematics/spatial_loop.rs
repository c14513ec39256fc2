//! Loop closure on the spatial tree [`Model`]: a closed chain modelled as a tree (cut at
//! one joint) plus constraints that two link frames coincide, and the Newton projection
//! of a configuration onto the constraint manifold.
//!
//! For frames `a`, `b` with world poses `(R_a, p_a)`, `(R_b, p_b)`:
//! - position closure: `c = p_a − p_b` (3 rows), `∂c/∂q = J_a^v − J_b^v` with the
//!   world-aligned linear Jacobians (`ṗ = J^v q̇`, [`Expressed::WorldAligned`]);
//! - pose closure adds `e = log(R_bᵀ R_a)` (3 rows, in frame `b`). Since
//!   `d/dt (R_bᵀ R_a) = [R_bᵀ (ω_a − ω_b)]× R_bᵀ R_a`, its exact Jacobian is
//!   `J_l⁻¹(e) R_bᵀ (J_a^ω − J_b^ω)` with the inverse left Jacobian of SO(3)
//!   `J_l⁻¹(e) = I − ½[e]× + (1/θ² − (1 + cos θ)/(2 θ sin θ)) [e]×²`, `θ = |e|`
//!   (Barfoot, *State Estimation for Robotics*, 2017, §7.1.5).
//!
//! Projection (Gauss–Newton with minimum-norm steps): with some coordinates held (the
//! inputs), `q_free ← q_free − J_free⁺ c(q)` until `‖c‖∞ ≤ tol`. The minimum-norm step
//! makes the result the nearest point on the manifold to first order, and works with
//! redundant rows (a planar loop closed by a full pose has three identically zero rows).

use crate::core::spatial::{skew, Mat3, Vec3};
use crate::kinematics::{
    compute_joint_jacobians, forward_kinematics, frame_jacobian, frame_placement, Expressed,
};
use crate::model::data::Data;
use crate::model::Model;
use nalgebra::{DMatrix, DVector};

/// What coincides.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClosureKind {
    /// Frame origins (3 equations).
    Position,
    /// Origins and orientations (6 equations).
    Pose,
}

/// Link frames `link_a` and `link_b` (indices in [`Model::links`]) must coincide.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoopClosure {
    /// First frame.
    pub link_a: usize,
    /// Second frame.
    pub link_b: usize,
    /// Position or pose.
    pub kind: ClosureKind,
}

/// `log` of a rotation matrix as a rotation vector.
pub fn log3(r: &Mat3) -> Vec3 {
    let c = ((r.trace() - 1.0) * 0.5).clamp(-1.0, 1.0);
    let w = Vec3::new(
        r[(2, 1)] - r[(1, 2)],
        r[(0, 2)] - r[(2, 0)],
        r[(1, 0)] - r[(0, 1)],
    );
    // |w| = 2 sin θ: atan2 keeps θ accurate near 0 and π, where acos alone loses digits.
    let theta = (0.5 * w.norm()).atan2(c);
    if theta < 1e-6 {
        // sin θ / θ ≈ 1 − θ²/6.
        return w * (0.5 * (1.0 + theta * theta / 6.0));
    }
    if std::f64::consts::PI - theta > 1e-6 {
        return w * (theta / (2.0 * theta.sin()));
    }
    // Near π: the axis from the symmetric part, (R + Rᵀ)/2 + I = 2 a aᵀ + O((π − θ)²).
    let b = ((r + r.transpose()) * 0.5 + Mat3::identity()) * 0.5;
    let k = (0..3)
        .max_by(|&i, &j| b[(i, i)].total_cmp(&b[(j, j)]))
        .unwrap_or(0);
    let mut a = b.column(k) / b[(k, k)].max(1e-300).sqrt();
    a /= a.norm();
    if a.dot(&w) < 0.0 {
        a = -a;
    }
    a * theta
}

/// The inverse left Jacobian of SO(3) at rotation vector `e`.
pub fn left_jacobian_inverse(e: &Vec3) -> Mat3 {
    let t = e.norm();
    let k = skew(e);
    let coef = if t < 1e-4 {
        1.0 / 12.0 + t * t / 720.0
    } else {
        1.0 / (t * t) - (1.0 + t.cos()) / (2.0 * t * t.sin())
    };
    Mat3::identity() - k * 0.5 + k * k * coef
}

impl LoopClosure {
    /// Number of equations.
    pub fn dim(&self) -> usize {
        match self.kind {
            ClosureKind::Position => 3,
            ClosureKind::Pose => 6,
        }
    }

    /// Residual from the placements in `data` (after forward kinematics).
    pub fn residual(&self, model: &Model, data: &Data) -> DVector<f64> {
        let a = frame_placement(model, data, self.link_a);
        let b = frame_placement(model, data, self.link_b);
        let dp = a.trans - b.trans;
        match self.kind {
            ClosureKind::Position => DVector::from_column_slice(dp.as_slice()),
            ClosureKind::Pose => {
                let e = log3(&(b.rot.transpose() * a.rot));
                DVector::from_iterator(6, dp.iter().chain(e.iter()).copied())
            }
        }
    }

    /// Jacobian (`dim × nv`) from `data` after [`compute_joint_jacobians`].
    pub fn jacobian(&self, model: &Model, data: &Data) -> DMatrix<f64> {
        let mut ja = DMatrix::zeros(6, model.nv);
        let mut jb = DMatrix::zeros(6, model.nv);
        frame_jacobian(model, data, self.link_a, Expressed::WorldAligned, &mut ja);
        frame_jacobian(model, data, self.link_b, Expressed::WorldAligned, &mut jb);
        let d = ja - jb;
        let mut out = DMatrix::zeros(self.dim(), model.nv);
        out.rows_mut(0, 3).copy_from(&d.rows(0, 3));
        if self.kind == ClosureKind::Pose {
            let a = frame_placement(model, data, self.link_a);
            let b = frame_placement(model, data, self.link_b);
            let e = log3(&(b.rot.transpose() * a.rot));
            let m = left_jacobian_inverse(&e) * b.rot.transpose();
            let mut rot = DMatrix::zeros(3, model.nv);
            for c in 0..model.nv {
                let w = Vec3::new(d[(3, c)], d[(4, c)], d[(5, c)]);
                rot.column_mut(c).copy_from(&(m * w));
            }
            out.rows_mut(3, 3).copy_from(&rot);
        }
        out
    }
}

/// Stacked residual of `closures` at `q` (runs forward kinematics).
pub fn residual(
    model: &Model,
    data: &mut Data,
    closures: &[LoopClosure],
    q: &[f64],
) -> DVector<f64> {
    forward_kinematics(model, data, q);
    let parts: Vec<DVector<f64>> = closures.iter().map(|c| c.residual(model, data)).collect();
    DVector::from_iterator(
        parts.iter().map(|p| p.len()).sum(),
        parts.iter().flat_map(|p| p.iter().copied()),
    )
}

/// Stacked Jacobian of `closures` at `q`.
pub fn jacobian(
    model: &Model,
    data: &mut Data,
    closures: &[LoopClosure],
    q: &[f64],
) -> DMatrix<f64> {
    compute_joint_jacobians(model, data, q);
    let rows: usize = closures.iter().map(LoopClosure::dim).sum();
    let mut out = DMatrix::zeros(rows, model.nv);
    let mut r = 0;
    for c in closures {
        let j = c.jacobian(model, data);
        out.rows_mut(r, c.dim()).copy_from(&j);
        r += c.dim();
    }
    out
}

/// A projected configuration.
#[derive(Clone, Debug)]
pub struct Projection {
    /// The configuration on the manifold.
    pub q: Vec<f64>,
    /// Iterations used.
    pub iterations: usize,
    /// `‖c(q)‖∞`.
    pub residual: f64,
    /// Rank of the constraint Jacobian in the free coordinates.
    pub rank: usize,
    /// Redundant constraint equations (rows − rank).
    pub redundant: usize,
}

/// The projection did not converge.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("loop closure did not converge: residual {residual:.3e} after {iterations} iterations")]
pub struct ProjectionError {
    /// Best residual.
    pub residual: f64,
    /// Iterations used.
    pub iterations: usize,
}

fn free_columns(nv: usize, fixed: &[usize]) -> Vec<usize> {
    (0..nv).filter(|c| !fixed.contains(c)).collect()
}

/// Projects `q0` onto the manifold of `closures`, holding the coordinates `fixed`.
pub fn project(
    model: &Model,
    data: &mut Data,
    closures: &[LoopClosure],
    q0: &[f64],
    fixed: &[usize],
    tol: f64,
    max_iter: usize,
) -> Result<Projection, ProjectionError> {
    let free = free_columns(model.nv, fixed);
    let mut q = q0.to_vec();
    let mut r = residual(model, data, closures, &q);
    let mut norm = r.amax();
    let mut it = 0;
    let mut rank = 0;
    let mut rows = r.len();
    while it < max_iter {
        let j = jacobian(model, data, closures, &q);
        let jf = j.select_columns(&free);
        let sol = crate::core::least_squares::min_norm_solve(&jf, &(-&r), None);
        rank = sol.rank;
        rows = jf.nrows();
        if norm <= tol {
            break;
        }
        it += 1;
        let mut alpha = 1.0;
        let mut improved = false;
        for _ in 0..30 {
            let mut trial = q.clone();
            for (k, &c) in free.iter().enumerate() {
                trial[c] += alpha * sol.x[k];
            }
            let tr = residual(model, data, closures, &trial);
            if tr.amax() < norm {
                q = trial;
                norm = tr.amax();
                r = tr;
                improved = true;
                break;
            }
            alpha *= 0.5;
        }
        if !improved {
            break;
        }
    }
    if norm <= tol {
        Ok(Projection {
            q,
            iterations: it,
            residual: norm,
            rank,
            redundant: rows - rank,
        })
    } else {
        Err(ProjectionError {
            residual: norm,
            iterations: it,
        })
    }
}

/// Velocities of the free coordinates that keep the closures satisfied, given the
/// velocities `qd` of the `fixed` ones (other entries of `qd` are overwritten):
/// `J_free q̇_free = −J_fixed q̇_fixed`, minimum-norm.
pub fn constrained_velocity(
    model: &Model,
    data: &mut Data,
    closures: &[LoopClosure],
    q: &[f64],
    fixed: &[usize],
    qd: &mut [f64],
) {
    let free = free_columns(model.nv, fixed);
    let j = jacobian(model, data, closures, q);
    let mut rhs = DVector::zeros(j.nrows());
    for &c in fixed {
        rhs -= j.column(c) * qd[c];
    }
    let sol = crate::core::least_squares::min_norm_solve(&j.select_columns(&free), &rhs, None);
    for (k, &c) in free.iter().enumerate() {
        qd[c] = sol.x[k];
    }
}
