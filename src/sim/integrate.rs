//! One integration step ([`Integrator`]): the closed-loop right-hand side `ẋ = f(t, x)`,
//! semi-implicit Euler in the canonical momentum, classic RK4, and linearly implicit Euler.

use crate::dynamics;
use crate::model::data::Data;
use crate::sim::{Controller, Integrator, Reference, SimError, Simulator};
use nalgebra::DMatrix;

impl Simulator<'_> {
    /// `ẋ = f(t, x)` into `out`.
    fn rhs(
        &mut self,
        t: f64,
        x: &[f64],
        out: &mut [f64],
        reference: &dyn Reference,
        ctrl: &Controller,
    ) -> Result<(), SimError> {
        let n = self.n;
        self.control(t, x, reference, ctrl);
        let (q, qd) = (&x[..n], &x[n..2 * n]);
        out[..n].copy_from_slice(qd);
        // Plant-only wrenches join the effects for the forward dynamics (capacity is kept,
        // so this allocates only the first time).
        let own = self.effects.external.len();
        self.effects.external.extend_from_slice(&self.plant);
        let r = self.plant_rhs(t, q, qd, x, out);
        self.effects.external.truncate(own);
        r
    }

    fn plant_rhs(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        x: &[f64],
        out: &mut [f64],
    ) -> Result<(), SimError> {
        let n = self.n;
        if self.elastic {
            let (th, thd) = (&x[2 * n..3 * n], &x[3 * n..]);
            let qdd = dynamics::elastic_forward_dynamics(
                self.model,
                &mut self.data,
                &self.effects,
                q,
                qd,
                th,
                thd,
                &self.tau,
                &mut self.thdd,
            )
            .map_err(|source| SimError::Dynamics { t, source })?;
            out[n..2 * n].copy_from_slice(qdd);
            out[2 * n..3 * n].copy_from_slice(thd);
            out[3 * n..].copy_from_slice(&self.thdd);
        } else {
            let qdd = dynamics::forward_dynamics_with(
                self.model,
                &mut self.data,
                &self.effects,
                q,
                qd,
                &self.tau,
            )
            .map_err(|source| SimError::Dynamics { t, source })?;
            out[n..].copy_from_slice(qdd);
        }
        Ok(())
    }

    /// The link side of one symplectic Euler step, in the canonical momentum
    /// `p = M(q) q̇` (see [`Integrator::SemiImplicitEuler`]): with `w = q̇ₙ₊₁` the
    /// velocity over the step,
    ///
    /// `M(qₙ) (w − q̇ₙ) = h [Q − g(qₙ) + ∂T/∂q(qₙ, w)]`, `qₙ₊₁ = qₙ + h w`,
    /// `q̇ₙ₊₁ = M(qₙ₊₁)⁻¹ M(qₙ) w`,
    ///
    /// `Q` every other generalised force (controller, springs, friction, wrenches) at
    /// `(qₙ, q̇ₙ)`. Since `M q̈ₙ = Q − g − C(qₙ, q̇ₙ) q̇ₙ` (from `rhs`, `qdd`), the first
    /// equation is `w = q̇ₙ + h q̈ₙ + h M⁻¹ [∂T/∂q(qₙ, w) + C q̇ₙ]`, solved by fixed-point
    /// iteration (contraction ~ h ω).
    fn symplectic_link_step(
        &mut self,
        t: f64,
        h: f64,
        x: &mut [f64],
        qdd: &[f64],
    ) -> Result<(), SimError> {
        let n = self.n;
        let model = self.model;
        let payload = self.effects.payload.as_ref().map(|p| p.on_body());
        // The rotor armature is part of M for rigid joints (elastic joints ignore it).
        let rotor = if self.elastic {
            None
        } else {
            self.effects.rotor.as_ref()
        };
        let factor = |data: &mut Data, q: &[f64]| -> Result<(), SimError> {
            dynamics::crba_impl(model, data, q, payload);
            if let Some(r) = rotor {
                for k in 0..n {
                    data.mass[(k, k)] += r.armature(k);
                }
            }
            data.chol.copy_from(&data.mass);
            dynamics::cholesky_in_place(&mut data.chol)
                .map_err(|source| SimError::Dynamics { t, source })
        };
        let (q, rest) = x.split_at_mut(n);
        let qd = &mut rest[..n];
        factor(&mut self.data, q)?;
        // C(qₙ, q̇ₙ) q̇ₙ: RNEA without gravity at zero acceleration.
        self.acc.fill(0.0);
        let bare = dynamics::Terms {
            payload,
            ..Default::default()
        };
        dynamics::rnea_impl(model, &mut self.data, q, qd, &self.acc, &bare);
        self.se_c.copy_from_slice(&self.data.tau);
        for i in 0..n {
            self.se_w[i] = qd[i] + h * qdd[i];
        }
        let mut last = f64::INFINITY;
        for _ in 0..50 {
            let tq = dynamics::kinetic_energy_gradient_impl(
                model,
                &mut self.data,
                q,
                &self.se_w,
                payload,
            );
            for ((p, t), c) in self.se_p.iter_mut().zip(tq).zip(&self.se_c) {
                *p = t + c;
            }
            dynamics::cholesky_solve_in_place(&self.data.chol, &mut self.se_p);
            let (mut diff, mut scale) = (0.0f64, 0.0f64);
            for i in 0..n {
                let w = qd[i] + h * qdd[i] + h * self.se_p[i];
                diff = diff.max((w - self.se_w[i]).abs());
                scale = scale.max(w.abs());
                self.se_w[i] = w;
            }
            // Converged to rounding, or no longer contracting (rounding noise, or a step
            // beyond the method's stability, which the divergence check then reports).
            if diff.is_nan() || diff <= 4.0 * f64::EPSILON * scale || diff >= last {
                break;
            }
            last = diff;
        }
        // pₙ₊₁ = M(qₙ) w (M is still in data.mass), then qₙ₊₁ and q̇ₙ₊₁ = M(qₙ₊₁)⁻¹ pₙ₊₁.
        for (i, (p, qi)) in self.se_p.iter_mut().zip(q.iter_mut()).enumerate() {
            *p = (0..n).map(|j| self.data.mass[(i, j)] * self.se_w[j]).sum();
            *qi += h * self.se_w[i];
        }
        if !q.iter().all(|v| v.is_finite()) {
            // Diverged: leave it to the caller's check.
            qd.copy_from_slice(&self.se_w);
            return Ok(());
        }
        factor(&mut self.data, q)?;
        dynamics::cholesky_solve_in_place(&self.data.chol, &mut self.se_p);
        qd.copy_from_slice(&self.se_p);
        Ok(())
    }

    /// One step of `method` from `(t, x)` to `(t + h, x)`, in place.
    pub(super) fn step(
        &mut self,
        t: f64,
        h: f64,
        x: &mut [f64],
        reference: &dyn Reference,
        ctrl: &Controller,
        method: Integrator,
    ) -> Result<(), SimError> {
        let mut k0 = std::mem::take(&mut self.k[0]);
        match method {
            Integrator::SemiImplicitEuler => {
                self.semi_implicit_euler_step(t, h, x, &mut k0, reference, ctrl)?;
            }
            Integrator::Rk4 => self.rk4_step(t, h, x, &mut k0, reference, ctrl)?,
            Integrator::Implicit => self.implicit_step(t, h, x, &mut k0, reference, ctrl)?,
        }
        self.k[0] = k0;
        Ok(())
    }

    /// Semi-implicit Euler: the motor side in the velocity form, the link side in the
    /// canonical momentum ([`Simulator::symplectic_link_step`]).
    fn semi_implicit_euler_step(
        &mut self,
        t: f64,
        h: f64,
        x: &mut [f64],
        k0: &mut [f64],
        reference: &dyn Reference,
        ctrl: &Controller,
    ) -> Result<(), SimError> {
        let n = self.n;
        self.rhs(t, x, k0, reference, ctrl)?;
        // Motor side (constant inertia B): velocities first, then positions with
        // the new velocities — the momentum form, since p = B θ̇.
        if self.elastic {
            for i in 0..n {
                x[3 * n + i] += h * k0[3 * n + i];
                x[2 * n + i] += h * x[3 * n + i];
            }
        }
        self.symplectic_link_step(t, h, x, &k0[n..2 * n])
    }

    /// Classic RK4: four evaluations of `f`, weighted 1, 2, 2, 1.
    fn rk4_step(
        &mut self,
        t: f64,
        h: f64,
        x: &mut [f64],
        k0: &mut [f64],
        reference: &dyn Reference,
        ctrl: &Controller,
    ) -> Result<(), SimError> {
        let dim = x.len();
        let [_, k1, k2, k3] = &mut self.k;
        let (mut k1, mut k2, mut k3) = (std::mem::take(k1), std::mem::take(k2), std::mem::take(k3));
        let mut xt = std::mem::take(&mut self.xt);
        self.rhs(t, x, k0, reference, ctrl)?;
        rk4_stage(&mut xt, x, 0.5 * h, k0);
        self.rhs(t + 0.5 * h, &xt, &mut k1, reference, ctrl)?;
        rk4_stage(&mut xt, x, 0.5 * h, &k1);
        self.rhs(t + 0.5 * h, &xt, &mut k2, reference, ctrl)?;
        rk4_stage(&mut xt, x, h, &k2);
        self.rhs(t + h, &xt, &mut k3, reference, ctrl)?;
        for i in 0..dim {
            x[i] += h / 6.0 * (k0[i] + 2.0 * k1[i] + 2.0 * k2[i] + k3[i]);
        }
        self.xt = xt;
        self.k[1] = k1;
        self.k[2] = k2;
        self.k[3] = k3;
        Ok(())
    }

    /// Linearly implicit Euler: `(I − h J) Δx = h f(x)`, `J` by forward differences of
    /// the closed loop; `dx` receives `Δx`.
    fn implicit_step(
        &mut self,
        t: f64,
        h: f64,
        x: &mut [f64],
        dx: &mut [f64],
        reference: &dyn Reference,
        ctrl: &Controller,
    ) -> Result<(), SimError> {
        let dim = x.len();
        let mut fx = std::mem::take(&mut self.fx);
        let mut fp = std::mem::take(&mut self.fp);
        let mut xt = std::mem::take(&mut self.xt);
        self.rhs(t + h, x, &mut fx, reference, ctrl)?;
        xt.copy_from_slice(x);
        for j in 0..dim {
            let eps = 1e-7 * x[j].abs().max(1.0);
            xt[j] = x[j] + eps;
            self.rhs(t + h, &xt, &mut fp, reference, ctrl)?;
            xt[j] = x[j];
            for i in 0..dim {
                self.jac[(i, j)] = -h * (fp[i] - fx[i]) / eps;
            }
            self.jac[(j, j)] += 1.0;
        }
        for i in 0..dim {
            dx[i] = h * fx[i];
        }
        solve_in_place(&mut self.jac, dx);
        for i in 0..dim {
            x[i] += dx[i];
        }
        self.fx = fx;
        self.fp = fp;
        self.xt = xt;
        Ok(())
    }
}

/// `a y = b` by Gaussian elimination with partial pivoting, in place: `b` becomes `y`,
/// `a` its upper triangle (a zero pivot leaves its column alone).
fn solve_in_place(a: &mut DMatrix<f64>, b: &mut [f64]) {
    let dim = b.len();
    for c in 0..dim {
        let p = (c..dim)
            .max_by(|&r1, &r2| a[(r1, c)].abs().total_cmp(&a[(r2, c)].abs()))
            .unwrap_or(c);
        if p != c {
            a.swap_rows(p, c);
            b.swap(p, c);
        }
        let d = a[(c, c)];
        if d == 0.0 {
            continue;
        }
        for r in c + 1..dim {
            let f = a[(r, c)] / d;
            if f != 0.0 {
                for cc in c..dim {
                    a[(r, cc)] -= f * a[(c, cc)];
                }
                b[r] -= f * b[c];
            }
        }
    }
    for c in (0..dim).rev() {
        let mut s = b[c];
        for cc in c + 1..dim {
            s -= a[(c, cc)] * b[cc];
        }
        b[c] = s / a[(c, c)];
    }
}

/// An RK4 stage's state `x_t = x + c k`.
fn rk4_stage(xt: &mut [f64], x: &[f64], c: f64, k: &[f64]) {
    for ((xt, &x), &k) in xt.iter_mut().zip(x).zip(k) {
        *xt = x + c * k;
    }
}
