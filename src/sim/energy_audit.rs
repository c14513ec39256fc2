//! The energy audit: the total energy `T + V` (+ springs and motors), whether a run
//! conserves it, and the running balance `E(t) − E(0) − W(t)` against the actuator work.

use crate::dynamics;
use crate::sim::{EnergyAudit, Simulator};

impl Simulator<'_> {
    /// Energy `T + V` (+ spring and motor energy with elastic joints).
    pub(super) fn energy(&mut self, x: &[f64]) -> f64 {
        let n = self.n;
        let (q, qd) = (&x[..n], &x[n..2 * n]);
        let mut e = dynamics::kinetic_energy(self.model, &mut self.data, q, qd);
        if let Some(g) = &self.effects.gravity {
            e += dynamics::potential_energy(self.model, &mut self.data, q, g);
        }
        if let Some(el) = &self.effects.elasticity {
            for i in 0..n {
                let d = x[2 * n + i] - q[i];
                e += 0.5 * el.stiffness[i] * d * d
                    + 0.5 * el.motor_inertia[i] * x[3 * n + i] * x[3 * n + i];
            }
        }
        e
    }

    /// Whether nothing in the effects dissipates or injects energy (the audit applies).
    pub(super) fn conservative(&self) -> bool {
        let e = &self.effects;
        e.friction.is_none()
            && e.external.is_empty()
            && e.rotor.is_none()
            && e.payload.is_none()
            && e.elasticity
                .as_ref()
                .is_none_or(|el| el.damping.iter().all(|d| *d == 0.0))
    }

    /// The actuator power `τ·q̇` (motor side `τ·θ̇` with elastic joints) at `x`.
    pub(super) fn actuator_power(&self, x: &[f64]) -> f64 {
        let n = self.n;
        let rate = if self.elastic {
            &x[3 * n..]
        } else {
            &x[n..2 * n]
        };
        self.tau.iter().zip(rate).map(|(a, b)| a * b).sum::<f64>()
    }
}

/// The running balance `E(t) − E(0) − W(t)` of a conservative run, the work `W` by the
/// trapezoidal rule on the actuator power.
pub(super) struct EnergyBalance {
    e0: f64,
    work: f64,
    max_drift: f64,
    scale: f64,
    p_prev: f64,
}

impl EnergyBalance {
    /// Starts from the energy `e0` and the actuator power `p0` at `t = 0`.
    pub(super) fn start(e0: f64, p0: f64) -> Self {
        Self {
            e0,
            work: 0.0,
            max_drift: 0.0,
            scale: e0.abs().max(1.0),
            p_prev: p0,
        }
    }

    /// After a step of length `h` that ends with actuator power `p` and energy `e`.
    pub(super) fn record(&mut self, h: f64, p: f64, e: f64) {
        self.work += 0.5 * h * (self.p_prev + p);
        self.p_prev = p;
        self.scale = self.scale.max(e.abs()).max(self.work.abs());
        self.max_drift = self.max_drift.max((e - self.e0 - self.work).abs());
    }

    /// The largest drift, absolute and relative to the energy scale.
    pub(super) fn audit(&self) -> EnergyAudit {
        EnergyAudit {
            max_drift_j: self.max_drift,
            max_relative_drift: self.max_drift / self.scale,
        }
    }
}
