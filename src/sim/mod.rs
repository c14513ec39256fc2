//! Simulation: integrate the forward dynamics with exactly the selected effects under a
//! controller tracking a reference, audit the energy when nothing dissipates, and report
//! the real-time factor.
//!
//! - The state is `x = [q, q̇]`, or `x = [q, q̇, θ, θ̇]` with elastic joints (motor angles θ
//!   are states, [`crate::dynamics::elastic_forward_dynamics`]).
//! - Integrators ([`Integrator`]): semi-implicit (symplectic) Euler in the canonical
//!   momentum (so that it stays symplectic with a configuration-dependent mass matrix),
//!   classic RK4, and the
//!   linearly implicit (Rosenbrock–)Euler `(I − h J) Δx = h f(x)` with `J = ∂f/∂x` by
//!   finite differences, which stays stable on stiff joint springs where the explicit
//!   methods blow up. A diverging state stops the run with [`SimError::Diverged`], which
//!   names the step, the stiffest mode it can estimate, and the fix.
//! - Controllers ([`Controller`]): computed torque `τ = ID(q, q̇, q̈_d + K_d ė + K_p e)`
//!   (with the scene's effects, so the model is exact), PD with gravity compensation
//!   `τ = K_p e + K_d ė + g(q)`, or none. With elastic joints the controller acts on the
//!   motor side: `τ_m = τ_ff + B q̈_d + K_p B (θ_d − θ) + K_d B (q̇_d − θ̇)` with
//!   `τ_ff = ID(q_d, q̇_d, q̈_d)` and the motor reference `θ_d = q_d + K⁻¹ τ_ff` (so the
//!   springs carry the link torques without sag) for computed torque, `K_p (q_d − θ) + K_d (q̇_d − θ̇) + g(q_d)`
//!   for PD (gravity compensated at the desired configuration, Tomei's controller).
//! - Energy audit: with no friction, no joint damping and no external wrench,
//!   `E(t) − E(0) = ∫ τ·q̇ dt` (actuator work; motor side with elastic joints); the report
//!   gives the largest violation relative to the energy scale.
//!
//! Nothing allocates per step: every buffer lives in [`Simulator`].

use crate::data::Data;
use crate::dynamics::{self, Effects, Payload, SingularMassMatrix};
use crate::model::Model;
use nalgebra::DMatrix;
use std::time::Instant;

/// Time integration method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Integrator {
    /// Semi-implicit (symplectic) Euler in the canonical momentum `p = M(q) q̇`:
    /// `pₙ₊₁ = pₙ + h [Q − g(qₙ) + ∂T/∂q(qₙ, q̇')]`, `qₙ₊₁ = qₙ + h q̇'` with
    /// `q̇' = M(qₙ)⁻¹ pₙ₊₁` (implicit in `q̇'`, solved by fixed-point iteration), then
    /// `q̇ₙ₊₁ = M(qₙ₊₁)⁻¹ pₙ₊₁`. For a constant mass matrix (and the motor side of elastic
    /// joints) this is `q̇ₙ₊₁ = q̇ₙ + h q̈ₙ`, `qₙ₊₁ = qₙ + h q̇ₙ₊₁`; that velocity form is
    /// not symplectic when `M` depends on `q` and lets the energy drift secularly (the
    /// planar double pendulum drifted by 7 J of its 10 J in 100 s at h = 1 ms), where
    /// this form keeps the energy error bounded and `O(h)` (0.08 J there).
    SemiImplicitEuler,
    /// Classic fourth-order Runge–Kutta.
    Rk4,
    /// Linearly implicit Euler (one Newton step of backward Euler per step).
    Implicit,
}

impl Integrator {
    /// Name used in files and reports.
    pub fn as_str(&self) -> &'static str {
        match self {
            Integrator::SemiImplicitEuler => "semi_implicit_euler",
            Integrator::Rk4 => "rk4",
            Integrator::Implicit => "implicit",
        }
    }
}

/// Joint-space controller.
#[derive(Clone, Debug, PartialEq)]
pub enum Controller {
    /// Zero torque (free motion).
    None,
    /// Computed torque with gains per joint.
    ComputedTorque {
        /// Position gains (1/s²).
        kp: Vec<f64>,
        /// Velocity gains (1/s).
        kd: Vec<f64>,
    },
    /// PD plus gravity compensation with gains per joint.
    PdGravity {
        /// Position gains (N m/rad).
        kp: Vec<f64>,
        /// Velocity gains (N m s/rad).
        kd: Vec<f64>,
    },
}

/// A reference the controller tracks: `(q_d, q̇_d, q̈_d)` at time `t`.
pub trait Reference {
    /// Writes the reference at `t` (held at the end after the duration).
    fn sample(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]);
}

/// Called before every step of [`Simulator::run_with_hook`]: sees the state, may set
/// wrenches that act on the plant only (contact forces: the controller does not know
/// them), and stops the run by returning `false` (an interrupt).
pub trait StepHook {
    /// `t`, `q`, `q̇` before the step; `plant_wrenches` holds the previous step's wrenches.
    fn before_step(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        plant_wrenches: &mut Vec<crate::dynamics::ExternalWrench>,
    ) -> bool;

    /// Whether the hook's wrenches keep the energy balance (no: it skips the audit).
    fn conservative(&self) -> bool {
        true
    }
}

/// The hook that does nothing.
pub struct NoHook;

impl StepHook for NoHook {
    fn before_step(
        &mut self,
        _t: f64,
        _q: &[f64],
        _qd: &[f64],
        _w: &mut Vec<crate::dynamics::ExternalWrench>,
    ) -> bool {
        true
    }
}

/// A constant configuration as reference.
pub struct Hold(pub Vec<f64>);

impl Reference for Hold {
    fn sample(&self, _t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        q.copy_from_slice(&self.0);
        qd.fill(0.0);
        qdd.fill(0.0);
    }
}

/// Why a simulation stopped early.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// The state became non-finite or exploded.
    #[error("the simulation diverged at t = {t:.6} s with the {integrator} integrator at step {dt:e} s{hint}")]
    Diverged {
        /// Time of divergence.
        t: f64,
        /// Integrator name.
        integrator: &'static str,
        /// Step.
        dt: f64,
        /// Advice (stiffness estimate and the fix).
        hint: String,
    },
    /// The mass matrix was singular.
    #[error("forward dynamics failed at t = {t:.6} s: {source}")]
    Dynamics {
        /// Time.
        t: f64,
        /// Cause.
        source: SingularMassMatrix,
    },
    /// Bad settings.
    #[error("{0}")]
    Config(String),
}

/// One recorded sample.
#[derive(Clone, Debug)]
pub struct Sample<'a> {
    /// Time.
    pub t: f64,
    /// Joint positions.
    pub q: &'a [f64],
    /// Joint velocities.
    pub qd: &'a [f64],
    /// Applied joint (or motor) torques.
    pub tau: &'a [f64],
    /// Reference positions.
    pub q_ref: &'a [f64],
}

/// The summary of a run.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SimReport {
    /// Integrator used.
    pub integrator: &'static str,
    /// Step (s).
    pub dt: f64,
    /// Steps taken.
    pub steps: usize,
    /// Simulated time (s).
    pub sim_time_s: f64,
    /// Wall-clock time (s).
    pub wall_time_s: f64,
    /// Simulated time / wall-clock time.
    pub real_time_factor: f64,
    /// Largest |q − q_d| per joint over the run (rad or m).
    pub max_tracking_error: Vec<f64>,
    /// Energy audit, when nothing dissipates.
    pub energy: Option<EnergyAudit>,
    /// Final joint positions.
    pub final_q: Vec<f64>,
    /// The hook stopped the run before its duration (an interrupt).
    pub interrupted: bool,
}

/// Energy balance `E(t) − E(0) − W(t)` over the run.
#[derive(Clone, Debug, serde::Serialize)]
pub struct EnergyAudit {
    /// Largest |E − E₀ − W| (J).
    pub max_drift_j: f64,
    /// The same relative to the energy scale max(|E|, |W|, 1 J).
    pub max_relative_drift: f64,
}

/// Settings of a run.
#[derive(Clone, Debug)]
pub struct SimConfig {
    /// Step (s).
    pub dt: f64,
    /// Duration (s).
    pub duration: f64,
    /// Integrator.
    pub integrator: Integrator,
    /// Controller.
    pub controller: Controller,
    /// Call the sample callback every this many steps.
    pub record_every: usize,
}

/// Preallocated simulation state for one model and effect set.
pub struct Simulator<'m> {
    model: &'m Model,
    effects: Effects,
    /// The effects without the joint springs (feed-forward with elastic joints).
    rigid_fx: Effects,
    /// Gravity and payload only (gravity compensation).
    static_fx: Effects,
    data: Data,
    elastic: bool,
    n: usize,
    x: Vec<f64>,
    k: [Vec<f64>; 4],
    xt: Vec<f64>,
    tau: Vec<f64>,
    qr: Vec<f64>,
    qdr: Vec<f64>,
    qddr: Vec<f64>,
    acc: Vec<f64>,
    thdd: Vec<f64>,
    jac: DMatrix<f64>,
    fx: Vec<f64>,
    fp: Vec<f64>,
    /// Wrenches on the plant only (set by a [`StepHook`]).
    plant: Vec<crate::dynamics::ExternalWrench>,
    q_before: Vec<f64>,
    se_w: Vec<f64>,
    se_c: Vec<f64>,
    se_p: Vec<f64>,
    /// The payload and the interval `[from, to]` (s) in which it is carried; outside it
    /// the effects have no payload (see [`Simulator::set_payload_window`]).
    payload_window: Option<(Payload, f64, f64)>,
}

/// `x > 0` rounded down to three significant digits, so that a printed step limit is
/// never above the limit.
fn floor_3_digits(x: f64) -> f64 {
    let scale = 10f64.powi(x.log10().floor() as i32 - 2);
    (x / scale).floor() * scale
}

impl<'m> Simulator<'m> {
    /// Carries the effects' payload only for `from ≤ t ≤ to` (a part grasped and
    /// released); switched at step boundaries, for the plant and the controller alike.
    /// `None` carries it throughout. Does nothing without a payload.
    pub fn set_payload_window(&mut self, window: Option<(f64, f64)>) {
        if let Some((p, _, _)) = self.payload_window.take() {
            self.set_payload(Some(p));
        }
        if let (Some((from, to)), Some(p)) = (window, self.effects.payload.clone()) {
            self.payload_window = Some((p, from, to));
        }
    }

    fn set_payload(&mut self, p: Option<Payload>) {
        self.effects.payload = p.clone();
        self.rigid_fx.payload = p.clone();
        self.static_fx.payload = p;
    }

    fn apply_payload_window(&mut self, t: f64) {
        let Some((p, from, to)) = &self.payload_window else {
            return;
        };
        let on = t >= *from && t <= *to;
        if on != self.effects.payload.is_some() {
            let p = on.then(|| p.clone());
            self.set_payload(p);
        }
    }

    /// A simulator for `model` with exactly `effects`.
    pub fn new(model: &'m Model, effects: Effects) -> Result<Self, SimError> {
        effects.validate(model).map_err(SimError::Config)?;
        let n = model.nv;
        let elastic = effects.elasticity.is_some();
        let dim = if elastic { 4 * n } else { 2 * n };
        let v = |len: usize| vec![0.0; len];
        let rigid_fx = Effects {
            elasticity: None,
            ..effects.clone()
        };
        let static_fx = Effects {
            gravity: effects.gravity,
            payload: effects.payload.clone(),
            ..Default::default()
        };
        Ok(Self {
            model,
            effects,
            rigid_fx,
            static_fx,
            data: Data::new(model),
            elastic,
            n,
            x: v(dim),
            k: [v(dim), v(dim), v(dim), v(dim)],
            xt: v(dim),
            tau: v(n),
            qr: v(n),
            qdr: v(n),
            qddr: v(n),
            acc: v(n),
            thdd: v(n),
            jac: DMatrix::zeros(dim, dim),
            fx: v(dim),
            fp: v(dim),
            plant: Vec::new(),
            q_before: v(n),
            se_w: v(n),
            se_c: v(n),
            se_p: v(n),
            payload_window: None,
        })
    }

    /// Controller output at `(t, x)` into `self.tau` (joint torques, or motor torques with
    /// elastic joints).
    fn control(&mut self, t: f64, x: &[f64], reference: &dyn Reference, ctrl: &Controller) {
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

    /// How often each effect's code ran so far (a left-out effect stays at zero).
    pub fn effect_runs(&self) -> crate::dynamics::EffectRuns {
        self.data.effect_runs
    }

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

    /// Energy `T + V` (+ spring and motor energy with elastic joints).
    fn energy(&mut self, x: &[f64]) -> f64 {
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

    fn conservative(&self) -> bool {
        let e = &self.effects;
        e.friction.is_none()
            && e.external.is_empty()
            && e.rotor.is_none()
            && e.payload.is_none()
            && e.elasticity
                .as_ref()
                .is_none_or(|el| el.damping.iter().all(|d| *d == 0.0))
    }

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

    /// Runs from `(q0, q̇ = 0)` (motor angles at rest on the link angles plus the static
    /// spring deflection under gravity, with elastic joints).
    pub fn run(
        &mut self,
        q0: &[f64],
        cfg: &SimConfig,
        reference: &dyn Reference,
        on_sample: impl FnMut(&Sample<'_>),
    ) -> Result<SimReport, SimError> {
        self.run_with_hook(q0, cfg, reference, &mut NoHook, on_sample)
    }

    /// [`Simulator::run`] with a [`StepHook`] called before every step.
    pub fn run_with_hook(
        &mut self,
        q0: &[f64],
        cfg: &SimConfig,
        reference: &dyn Reference,
        hook: &mut dyn StepHook,
        mut on_sample: impl FnMut(&Sample<'_>),
    ) -> Result<SimReport, SimError> {
        let n = self.n;
        self.plant.clear();
        if q0.len() != n {
            return Err(SimError::Config(format!(
                "initial state: {} values for {n} joints",
                q0.len()
            )));
        }
        let positive_finite = |x: f64| x > 0.0 && x.is_finite();
        if !positive_finite(cfg.dt) || !(positive_finite(cfg.duration) || cfg.duration == 0.0) {
            return Err(SimError::Config(
                "simulation: step and duration must be positive and finite".into(),
            ));
        }
        let gains_ok = |v: &Vec<f64>| v.len() == n && v.iter().all(|x| x.is_finite());
        match &cfg.controller {
            Controller::ComputedTorque { kp, kd } | Controller::PdGravity { kp, kd }
                if !(gains_ok(kp) && gains_ok(kd)) =>
            {
                return Err(SimError::Config(format!(
                    "controller: gains need {n} finite values"
                )));
            }
            _ => {}
        }
        self.x.fill(0.0);
        self.x[..n].copy_from_slice(q0);
        if self.elastic {
            // Start in static equilibrium: θ = q + K⁻¹ g(q).
            self.acc.fill(0.0);
            let g = dynamics::inverse_dynamics(
                self.model,
                &mut self.data,
                &self.static_fx,
                q0,
                &self.acc,
                &self.acc,
            )
            .to_vec();
            let k = self
                .effects
                .elasticity
                .as_ref()
                .expect("elastic")
                .stiffness
                .clone();
            for i in 0..n {
                self.x[2 * n + i] = q0[i] + g[i] / k[i];
            }
        }
        self.apply_payload_window(0.0);
        let steps = (cfg.duration / cfg.dt).round() as usize;
        let audit = self.conservative() && hook.conservative();
        let e0 = if audit {
            self.energy(&self.x.clone())
        } else {
            0.0
        };
        let (mut work, mut max_drift, mut scale) = (0.0f64, 0.0f64, e0.abs().max(1.0));
        let mut max_err = vec![0.0f64; n];
        let start = Instant::now();
        let h = cfg.dt;
        let record_every = cfg.record_every.max(1);
        // Power at the start of the step (actuator side).
        let mut x = std::mem::take(&mut self.x);
        self.control(0.0, &x, reference, &cfg.controller);
        on_sample(&Sample {
            t: 0.0,
            q: &x[..n],
            qd: &x[n..2 * n],
            tau: &self.tau,
            q_ref: &self.qr,
        });
        let power = |s: &Self, x: &[f64]| {
            let rate = if s.elastic { &x[3 * n..] } else { &x[n..2 * n] };
            s.tau.iter().zip(rate).map(|(a, b)| a * b).sum::<f64>()
        };
        let mut p_prev = power(self, &x);
        let mut taken = steps;
        let mut interrupted = false;
        for step in 0..steps {
            let t = step as f64 * h;
            self.apply_payload_window(t);
            if !hook.before_step(t, &x[..n], &x[n..2 * n], &mut self.plant) {
                taken = step;
                interrupted = true;
                break;
            }
            // The configuration before the step, one of the two where the hint below is
            // evaluated (the state after a diverging step is garbage).
            self.q_before.copy_from_slice(&x[..n]);
            self.step(t, h, &mut x, reference, &cfg.controller, cfg.integrator)?;
            let t1 = t + h;
            let big = x.iter().any(|v| !v.is_finite() || v.abs() > 1e8);
            if big {
                // Linear stability limits on the imaginary axis (undamped springs):
                // symplectic Euler ω h < 2, classic RK4 ω h < 2√2.
                let limit = match cfg.integrator {
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
                    Some(w) if cfg.integrator != Integrator::Implicit => format!(
                        ": the joint springs make the scene stiff (fastest mode ≈ {w:.1} rad/s, h·ω = {:.2}, stable below {limit:.2}); use integrator = \"implicit\" or a step below {:.2e} s",
                        w * h,
                        floor_3_digits(limit / w)
                    ),
                    _ => ": reduce the step".to_string(),
                };
                self.x = x;
                return Err(SimError::Diverged {
                    t: t1,
                    integrator: cfg.integrator.as_str(),
                    dt: h,
                    hint,
                });
            }
            self.control(t1, &x, reference, &cfg.controller);
            for i in 0..n {
                max_err[i] = max_err[i].max((x[i] - self.qr[i]).abs());
            }
            if audit {
                let p = power(self, &x);
                work += 0.5 * h * (p_prev + p);
                p_prev = p;
                let e = self.energy(&x);
                scale = scale.max(e.abs()).max(work.abs());
                max_drift = max_drift.max((e - e0 - work).abs());
            }
            if (step + 1) % record_every == 0 || step + 1 == steps {
                // (the last step is always recorded)
                on_sample(&Sample {
                    t: t1,
                    q: &x[..n],
                    qd: &x[n..2 * n],
                    tau: &self.tau,
                    q_ref: &self.qr,
                });
            }
        }
        let wall = start.elapsed().as_secs_f64();
        let final_q = x[..n].to_vec();
        self.x = x;
        Ok(SimReport {
            integrator: cfg.integrator.as_str(),
            dt: h,
            steps: taken,
            sim_time_s: taken as f64 * h,
            wall_time_s: wall,
            real_time_factor: if wall > 0.0 {
                taken as f64 * h / wall
            } else {
                f64::INFINITY
            },
            max_tracking_error: max_err,
            energy: audit.then_some(EnergyAudit {
                max_drift_j: max_drift,
                max_relative_drift: max_drift / scale,
            }),
            final_q,
            interrupted,
        })
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

    fn step(
        &mut self,
        t: f64,
        h: f64,
        x: &mut [f64],
        reference: &dyn Reference,
        ctrl: &Controller,
        method: Integrator,
    ) -> Result<(), SimError> {
        let dim = x.len();
        let n = self.n;
        let mut k0 = std::mem::take(&mut self.k[0]);
        match method {
            Integrator::SemiImplicitEuler => {
                self.rhs(t, x, &mut k0, reference, ctrl)?;
                // Motor side (constant inertia B): velocities first, then positions with
                // the new velocities — the momentum form, since p = B θ̇.
                if self.elastic {
                    for i in 0..n {
                        x[3 * n + i] += h * k0[3 * n + i];
                        x[2 * n + i] += h * x[3 * n + i];
                    }
                }
                self.symplectic_link_step(t, h, x, &k0[n..2 * n])?;
            }
            Integrator::Rk4 => {
                let [_, k1, k2, k3] = &mut self.k;
                let (mut k1, mut k2, mut k3) =
                    (std::mem::take(k1), std::mem::take(k2), std::mem::take(k3));
                let mut xt = std::mem::take(&mut self.xt);
                self.rhs(t, x, &mut k0, reference, ctrl)?;
                for i in 0..dim {
                    xt[i] = x[i] + 0.5 * h * k0[i];
                }
                self.rhs(t + 0.5 * h, &xt, &mut k1, reference, ctrl)?;
                for i in 0..dim {
                    xt[i] = x[i] + 0.5 * h * k1[i];
                }
                self.rhs(t + 0.5 * h, &xt, &mut k2, reference, ctrl)?;
                for i in 0..dim {
                    xt[i] = x[i] + h * k2[i];
                }
                self.rhs(t + h, &xt, &mut k3, reference, ctrl)?;
                for i in 0..dim {
                    x[i] += h / 6.0 * (k0[i] + 2.0 * k1[i] + 2.0 * k2[i] + k3[i]);
                }
                self.xt = xt;
                self.k[1] = k1;
                self.k[2] = k2;
                self.k[3] = k3;
            }
            Integrator::Implicit => {
                // (I − h J) Δx = h f(x), J by forward differences of the closed loop.
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
                    k0[i] = h * fx[i];
                }
                // Gaussian elimination with partial pivoting, in place.
                let a = &mut self.jac;
                for c in 0..dim {
                    let p = (c..dim)
                        .max_by(|&r1, &r2| a[(r1, c)].abs().total_cmp(&a[(r2, c)].abs()))
                        .unwrap_or(c);
                    if p != c {
                        a.swap_rows(p, c);
                        k0.swap(p, c);
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
                            k0[r] -= f * k0[c];
                        }
                    }
                }
                for c in (0..dim).rev() {
                    let mut s = k0[c];
                    for cc in c + 1..dim {
                        s -= a[(c, cc)] * k0[cc];
                    }
                    k0[c] = s / a[(c, c)];
                }
                for i in 0..dim {
                    x[i] += k0[i];
                }
                self.fx = fx;
                self.fp = fp;
                self.xt = xt;
            }
        }
        self.k[0] = k0;
        Ok(())
    }
}
