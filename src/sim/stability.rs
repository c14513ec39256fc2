//! Divergence: the stiffest joint-spring mode and the error that names the step, the mode
//! and the fix.

use crate::dynamics;
use crate::sim::{Integrator, SimError, Simulator};
use nalgebra::DMatrix;

/// `x > 0` rounded down to three significant digits, so that a printed step limit is
/// never above the limit.
fn floor_3_digits(x: f64) -> f64 {
    let scale = 10f64.powi(x.log10().floor() as i32 - 2);
    (x / scale).floor() * scale
}

/// Whether the state blew up (non-finite, or beyond any physical value).
pub(super) fn diverged(x: &[f64]) -> bool {
    x.iter().any(|v| !v.is_finite() || v.abs() > 1e8)
}

impl Simulator<'_> {
    /// The fastest natural frequency (rad/s) of the joint springs: the flexible-joint model
    /// linearised at rest at `q`, `diag(M(q), B) ẍ + [[K, −K], [−K, K]] x = 0` (gravity's
    /// stiffness and the velocity terms are small next to springs stiff enough to matter).
    /// `ω²` is the largest eigenvalue of `A = L_f⁻¹ K_f L_f⁻ᵀ` with
    /// `L_f = diag(L, B^½)`, `M = L Lᵀ`: `A = [[L⁻¹ K L⁻ᵀ, −L⁻¹ K B^-½], [·ᵀ, K B⁻¹]]`.
    /// (A per-joint `√(k (1/B + 1/M_ii))` underestimates it: the link side of a spring
    /// moves with the effective inertia `1/(M⁻¹)_ii ≤ M_ii`.) Runs once, on divergence,
    /// so it may allocate. Where `M` is not positive definite, `max √(k/B)` (a lower
    /// bound).
    fn stiffest_mode(&mut self, q: &[f64]) -> Option<f64> {
        let el = self.effects.elasticity.as_ref()?;
        let n = self.n;
        let (k, b) = (&el.stiffness, &el.motor_inertia);
        let motor_only = (0..n).map(|i| (k[i] / b[i]).sqrt()).reduce(f64::max);
        let m = dynamics::crba(self.model, &mut self.data, q).clone();
        let Some(linv) = m.cholesky().and_then(|c| c.l().try_inverse()) else {
            return motor_only;
        };
        let mut a = DMatrix::zeros(2 * n, 2 * n);
        for i in 0..n {
            for j in 0..n {
                let a11: f64 = (0..n).map(|c| linv[(i, c)] * k[c] * linv[(j, c)]).sum();
                a[(i, j)] = a11;
                let a12 = -linv[(i, j)] * k[j] / b[j].sqrt();
                a[(i, n + j)] = a12;
                a[(n + j, i)] = a12;
            }
            a[(n + i, n + i)] = k[i] / b[i];
        }
        let w2 = a.symmetric_eigenvalues().max();
        if w2.is_finite() && w2 > 0.0 {
            Some(w2.sqrt())
        } else {
            motor_only
        }
    }

    /// The error for a run that diverged at `t1` with step `h`: with joint springs, the
    /// fastest mode and the largest stable step.
    pub(super) fn divergence_error(
        &mut self,
        q0: &[f64],
        t1: f64,
        h: f64,
        integrator: Integrator,
    ) -> SimError {
        // Linear stability limits on the imaginary axis (undamped springs):
        // symplectic Euler ω h < 2, classic RK4 ω h < 2√2.
        let limit = match integrator {
            Integrator::Rk4 => 2.0 * std::f64::consts::SQRT_2,
            _ => 2.0,
        };
        // The spring modes depend on the configuration through M(q). An unstable
        // mode grows geometrically, so by the time it is detected the last
        // configurations already carry it: take the faster of the modes at the start
        // and before the last step, which keeps the advice on the safe side.
        let q_before = std::mem::take(&mut self.q_before);
        let mode = match (self.stiffest_mode(q0), self.stiffest_mode(&q_before)) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        };
        self.q_before = q_before;
        let hint = match mode {
            Some(w) if integrator != Integrator::Implicit => format!(
                ": the joint springs make the scene stiff (fastest mode ≈ {w:.1} rad/s, h·ω = {:.2}, stable below {limit:.2}); use integrator = \"implicit\" or a step below {:.2e} s",
                w * h,
                floor_3_digits(limit / w)
            ),
            _ => ": reduce the step".to_string(),
        };
        SimError::Diverged {
            t: t1,
            integrator: integrator.as_str(),
            dt: h,
            hint,
        }
    }
}
