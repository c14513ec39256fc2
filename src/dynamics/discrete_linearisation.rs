//! The linearisation of one integration step for MPC and trajectory optimisation: for
//! the state `x = (q, q̇)` and the held torque `u = τ`, the discrete dynamics
//! `x⁺ = Φ_h(x, u)` and their Jacobians `A = ∂x⁺/∂x` (2n × 2n) and `B = ∂x⁺/∂u` (2n × n),
//! from the analytical forward-dynamics derivatives with the scene's effects
//! ([`crate::dynamics::forward_dynamics_derivatives`]). With `f(x, u) = (q̇, q̈(q, q̇, τ))`,
//! `F = ∂f/∂x = [[0, I], [∂q̈/∂q, ∂q̈/∂q̇]]` and `G = ∂f/∂u = [[0], [M̃⁻¹]]`:
//!
//! - **semi-implicit (symplectic) Euler**, velocity form (Crocoddyl's Euler integrated
//!   action): `q̇⁺ = q̇ + h q̈`, `q⁺ = q + h q̇⁺`, so
//!   `A = [[I + h² ∂q̈/∂q, h (I + h ∂q̈/∂q̇)], [h ∂q̈/∂q, I + h ∂q̈/∂q̇]]`,
//!   `B = [[h² M̃⁻¹], [h M̃⁻¹]]`. (The simulator's own semi-implicit Euler steps the
//!   canonical momentum instead; this is the form optimisers linearise.)
//! - **classic RK4**, `u` held over the step: stages `x_i = x + c_i h k_{i−1}`
//!   (`c = 0, ½, ½, 1`), `k_i = f(x_i, u)`, `x⁺ = x + h/6 (k₁ + 2k₂ + 2k₃ + k₄)`; by the
//!   chain rule `K_i = ∂k_i/∂x = F_i (I + c_i h K_{i−1})` and
//!   `K^u_i = F_i c_i h K^u_{i−1} + G_i`, then `A = I + h/6 (K₁ + 2K₂ + 2K₃ + K₄)` and
//!   `B = h/6 (K^u₁ + 2K^u₂ + 2K^u₃ + K^u₄)`.
//!
//! Joint elasticity is refused: its motor angles and rates would be states too.
//! [`StepLinearisation`] owns its buffers; after [`StepLinearisation::new`] no call
//! allocates.

use crate::core::linalg::SingularMassMatrix;
use crate::dynamics::aba_derivatives::DIRECT_PRODUCT_MAX;
use crate::dynamics::effects::Effects;
use crate::dynamics::effects_derivatives::forward_dynamics_derivatives;
use crate::model::data::Data;
use crate::model::Model;
use nalgebra::DMatrix;

/// The one-step integrator a [`StepLinearisation`] differentiates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StepScheme {
    /// `q̇⁺ = q̇ + h q̈`, `q⁺ = q + h q̇⁺`.
    SemiImplicitEuler,
    /// Classic fourth-order Runge–Kutta with the torque held over the step.
    Rk4,
}

/// Why a step cannot be linearised.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LinearisationError {
    /// The step is not a positive finite number of seconds.
    #[error("step h = {h} s: must be a positive finite number")]
    Step {
        /// The step given (s).
        h: f64,
    },
    /// The effects include joint elasticity.
    #[error(
        "joint elasticity makes the motor angles and rates states too; the step \
         linearisation covers rigid joints only (leave elasticity out of the effects)"
    )]
    Elasticity,
    /// Forward dynamics failed at a stage (singular mass matrix, inputs overflowing).
    #[error("forward dynamics at stage {stage} of the step: {source}")]
    Dynamics {
        /// The stage (1 for semi-implicit Euler).
        stage: usize,
        /// What forward dynamics reported.
        #[source]
        source: SingularMassMatrix,
    },
    /// The step or its Jacobians came out non-finite (a step far beyond stability).
    #[error("the linearised step is not finite ({what}); the step h = {h} s is too large for this state")]
    NonFinite {
        /// `x⁺`, `A` or `B`.
        what: &'static str,
        /// The step (s).
        h: f64,
    },
}

/// The linearised step `x⁺ ≈ Φ_h(x̄, ū) + A (x − x̄) + B (u − ū)` (module docs), with its
/// buffers.
#[derive(Clone, Debug)]
pub struct StepLinearisation {
    scheme: StepScheme,
    h: f64,
    next: Vec<f64>,
    a: DMatrix<f64>,
    b: DMatrix<f64>,
    /// RK4: the stage state, its rate, and the stage Jacobians `∂x_i/∂x`, `∂x_i/∂u`,
    /// `K_i`, `K^u_i`.
    stage_x: Vec<f64>,
    stage_k: Vec<f64>,
    dx: DMatrix<f64>,
    dxu: DMatrix<f64>,
    k: DMatrix<f64>,
    ku: DMatrix<f64>,
    /// The lower block row of `F_i`, `[∂q̈/∂q  ∂q̈/∂q̇]` (n × 2n).
    fx: DMatrix<f64>,
}

impl StepLinearisation {
    /// Buffers for `model` and a step of `h` seconds with `scheme`.
    pub fn new(model: &Model, scheme: StepScheme, h: f64) -> Result<Self, LinearisationError> {
        if !(h > 0.0 && h.is_finite()) {
            return Err(LinearisationError::Step { h });
        }
        let (n, n2) = (model.nv, 2 * model.nv);
        Ok(StepLinearisation {
            scheme,
            h,
            next: vec![0.0; n2],
            a: DMatrix::zeros(n2, n2),
            b: DMatrix::zeros(n2, n),
            stage_x: vec![0.0; n2],
            stage_k: vec![0.0; n2],
            dx: DMatrix::zeros(n2, n2),
            dxu: DMatrix::zeros(n2, n),
            k: DMatrix::zeros(n2, n2),
            ku: DMatrix::zeros(n2, n),
            fx: DMatrix::zeros(n, n2),
        })
    }

    /// `A = ∂x⁺/∂x`, 2n × 2n, state order `(q, q̇)`.
    pub fn a(&self) -> &DMatrix<f64> {
        &self.a
    }

    /// `B = ∂x⁺/∂τ`, 2n × n.
    pub fn b(&self) -> &DMatrix<f64> {
        &self.b
    }

    /// `x⁺ = (q⁺, q̇⁺)`.
    pub fn next_state(&self) -> &[f64] {
        &self.next
    }

    /// The step's scheme and size.
    pub fn scheme(&self) -> (StepScheme, f64) {
        (self.scheme, self.h)
    }

    /// Linearises the step from `(q, q̇)` under torque `τ` with `effects`; afterwards
    /// [`Self::a`], [`Self::b`] and [`Self::next_state`] hold the result.
    pub fn linearise(
        &mut self,
        model: &Model,
        data: &mut Data,
        effects: &Effects,
        q: &[f64],
        qd: &[f64],
        tau: &[f64],
    ) -> Result<(), LinearisationError> {
        let n = model.nv;
        assert!(
            q.len() == n && qd.len() == n && tau.len() == n,
            "q, q̇, τ need nv values"
        );
        assert_eq!(self.next.len(), 2 * n, "buffers made for another model");
        if effects.elasticity.is_some() {
            return Err(LinearisationError::Elasticity);
        }
        match self.scheme {
            StepScheme::SemiImplicitEuler => self.euler(model, data, effects, q, qd, tau)?,
            StepScheme::Rk4 => self.rk4(model, data, effects, q, qd, tau)?,
        }
        let h = self.h;
        let finite = |m: &[f64]| m.iter().all(|x| x.is_finite());
        for (what, ok) in [
            ("x⁺", finite(&self.next)),
            ("A", finite(self.a.as_slice())),
            ("B", finite(self.b.as_slice())),
        ] {
            if !ok {
                return Err(LinearisationError::NonFinite { what, h });
            }
        }
        Ok(())
    }

    fn euler(
        &mut self,
        model: &Model,
        data: &mut Data,
        effects: &Effects,
        q: &[f64],
        qd: &[f64],
        tau: &[f64],
    ) -> Result<(), LinearisationError> {
        let (n, h) = (model.nv, self.h);
        forward_dynamics_derivatives(model, data, effects, q, qd, tau)
            .map_err(|source| LinearisationError::Dynamics { stage: 1, source })?;
        let p = &data.deriv;
        for i in 0..n {
            let vi = qd[i] + h * data.qdd[i];
            self.next[n + i] = vi;
            self.next[i] = q[i] + h * vi;
        }
        // Velocity rows: [h ∂q̈/∂q, I + h ∂q̈/∂q̇ | h M̃⁻¹]; position rows: h × those,
        // plus [I, 0 | 0].
        for c in 0..n {
            for r in 0..n {
                let dv_dq = h * p.ddq_dq[(r, c)];
                let dv_dv = h * p.ddq_dv[(r, c)] + f64::from(r == c);
                let dv_du = h * p.minv[(r, c)];
                self.a[(n + r, c)] = dv_dq;
                self.a[(n + r, n + c)] = dv_dv;
                self.b[(n + r, c)] = dv_du;
                self.a[(r, c)] = h * dv_dq + f64::from(r == c);
                self.a[(r, n + c)] = h * dv_dv;
                self.b[(r, c)] = h * dv_du;
            }
        }
        Ok(())
    }

    fn rk4(
        &mut self,
        model: &Model,
        data: &mut Data,
        effects: &Effects,
        q: &[f64],
        qd: &[f64],
        tau: &[f64],
    ) -> Result<(), LinearisationError> {
        let (n, h) = (model.nv, self.h);
        const C: [f64; 4] = [0.0, 0.5, 0.5, 1.0];
        const W: [f64; 4] = [1.0, 2.0, 2.0, 1.0];
        self.a.fill_with_identity();
        self.b.fill(0.0);
        // Stage 1 reads k₀ = 0 (c = 0): clear what the last call left.
        self.stage_k.fill(0.0);
        self.k.fill(0.0);
        self.ku.fill(0.0);
        self.next[..n].copy_from_slice(q);
        self.next[n..].copy_from_slice(qd);
        for (stage, (c, w)) in C.into_iter().zip(W).enumerate() {
            // x_i = x + c h k_{i−1}; ∂x_i/∂x = I + c h K_{i−1}; ∂x_i/∂u = c h K^u_{i−1}.
            for (i, xi) in self.stage_x.iter_mut().enumerate() {
                let x = if i < n { q[i] } else { qd[i - n] };
                *xi = x + c * h * self.stage_k[i];
            }
            self.dx.copy_from(&self.k);
            self.dx *= c * h;
            for i in 0..2 * n {
                self.dx[(i, i)] += 1.0;
            }
            self.dxu.copy_from(&self.ku);
            self.dxu *= c * h;
            let (xq, xv) = self.stage_x.split_at(n);
            forward_dynamics_derivatives(model, data, effects, xq, xv, tau).map_err(|source| {
                LinearisationError::Dynamics {
                    stage: stage + 1,
                    source,
                }
            })?;
            let p = &data.deriv;
            // k_i = (q̇_i, q̈_i); K_i = F_i ∂x_i/∂x; K^u_i = F_i ∂x_i/∂u + G_i.
            self.stage_k[..n].copy_from_slice(xv);
            self.stage_k[n..].copy_from_slice(&data.qdd);
            self.fx.as_mut_slice()[..n * n].copy_from_slice(p.ddq_dq.as_slice());
            self.fx.as_mut_slice()[n * n..].copy_from_slice(p.ddq_dv.as_slice());
            stage_rates(&self.fx, &self.dx, &mut self.k, None);
            stage_rates(&self.fx, &self.dxu, &mut self.ku, Some(&p.minv));
            let s = w * h / 6.0;
            add_scaled(self.a.as_mut_slice(), s, self.k.as_slice());
            add_scaled(self.b.as_mut_slice(), s, self.ku.as_slice());
            add_scaled(&mut self.next, s, &self.stage_k);
        }
        Ok(())
    }
}

/// `y += s x`.
fn add_scaled(y: &mut [f64], s: f64, x: &[f64]) {
    for (y, x) in y.iter_mut().zip(x) {
        *y += s * x;
    }
}

/// `K = F X + [0; G]`: the top half of `K` is the lower half of `X` (`F = [[0, I], [f]]`),
/// the lower half `f X` (plus `G = M̃⁻¹` for the torque columns). At arm sizes column by
/// column as sums of `f`'s columns (contiguous, vectorised, no allocation), else nalgebra's
/// blocked product, which allocates its packing buffers but is several times faster there.
fn stage_rates(f: &DMatrix<f64>, x: &DMatrix<f64>, k: &mut DMatrix<f64>, g: Option<&DMatrix<f64>>) {
    let n = f.nrows();
    k.rows_mut(0, n).copy_from(&x.rows(n, n));
    match g {
        Some(g) => k.rows_mut(n, n).copy_from(g),
        None => k.rows_mut(n, n).fill(0.0),
    }
    if n > DIRECT_PRODUCT_MAX {
        k.rows_mut(n, n).gemm(1.0, f, x, 1.0);
        return;
    }
    let (fs, n2) = (f.as_slice(), 2 * n);
    for (kc, xc) in k
        .as_mut_slice()
        .chunks_exact_mut(n2)
        .zip(x.as_slice().chunks_exact(n2))
    {
        for (col, xk) in fs.chunks_exact(n).zip(xc.iter()) {
            for (y, m) in kc[n..].iter_mut().zip(col) {
                *y += xk * m;
            }
        }
    }
}
