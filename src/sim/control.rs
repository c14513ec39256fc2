//! The controllers' torque laws ([`Controller`]): computed torque and PD with gravity
//! compensation, on the link side for rigid joints and on the motor side for elastic ones.

use crate::dynamics;
use crate::sim::{Controller, Reference, Simulator};

impl Simulator<'_> {
    /// Controller output at `(t, x)` into `self.tau` (joint torques, or motor torques with
    /// elastic joints).
    pub(super) fn control(
        &mut self,
        t: f64,
        x: &[f64],
        reference: &dyn Reference,
        ctrl: &Controller,
    ) {
        let n = self.n;
        let (q, qd) = (&x[..n], &x[n..2 * n]);
        reference.sample(t, &mut self.qr, &mut self.qdr, &mut self.qddr);
        match ctrl {
            Controller::None => self.tau.fill(0.0),
            Controller::ComputedTorque { kp, kd } => {
                if self.elastic {
                    let (th, thd) = (&x[2 * n..3 * n], &x[3 * n..]);
                    let ff = dynamics::inverse_dynamics(
                        self.model,
                        &mut self.data,
                        &self.rigid_fx,
                        &self.qr,
                        &self.qdr,
                        &self.qddr,
                    );
                    let b = &self
                        .effects
                        .elasticity
                        .as_ref()
                        .expect("elastic")
                        .motor_inertia;
                    let k = &self.effects.elasticity.as_ref().expect("elastic").stiffness;
                    // Motor reference θ_d = q_d + K⁻¹ τ_ff: the springs carry the link
                    // torques without the link sagging by K⁻¹ g(q).
                    for i in 0..n {
                        let th_d = self.qr[i] + ff[i] / k[i];
                        self.tau[i] = ff[i]
                            + b[i] * self.qddr[i]
                            + kp[i] * b[i] * (th_d - th[i])
                            + kd[i] * b[i] * (self.qdr[i] - thd[i]);
                    }
                } else {
                    for i in 0..n {
                        self.acc[i] = self.qddr[i]
                            + kd[i] * (self.qdr[i] - qd[i])
                            + kp[i] * (self.qr[i] - q[i]);
                    }
                    let tau = dynamics::inverse_dynamics(
                        self.model,
                        &mut self.data,
                        &self.effects,
                        q,
                        qd,
                        &self.acc,
                    );
                    self.tau.copy_from_slice(tau);
                }
            }
            Controller::PdGravity { kp, kd } => {
                let static_fx = &self.static_fx;
                self.acc.fill(0.0);
                if self.elastic {
                    let (th, thd) = (&x[2 * n..3 * n], &x[3 * n..]);
                    let g = dynamics::inverse_dynamics(
                        self.model,
                        &mut self.data,
                        static_fx,
                        &self.qr,
                        &self.acc,
                        &self.acc,
                    );
                    for i in 0..n {
                        self.tau[i] =
                            kp[i] * (self.qr[i] - th[i]) + kd[i] * (self.qdr[i] - thd[i]) + g[i];
                    }
                } else {
                    let g = dynamics::inverse_dynamics(
                        self.model,
                        &mut self.data,
                        static_fx,
                        q,
                        &self.acc,
                        &self.acc,
                    );
                    for i in 0..n {
                        self.tau[i] =
                            kp[i] * (self.qr[i] - q[i]) + kd[i] * (self.qdr[i] - qd[i]) + g[i];
                    }
                }
            }
        }
    }
}
