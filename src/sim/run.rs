//! A run: check the settings, start in static equilibrium, then step, control, audit
//! the energy and record samples until the duration, an interrupt or a divergence.

use crate::dynamics;
use crate::sim::energy_audit::EnergyBalance;
use crate::sim::stability::diverged;
use crate::sim::{
    Controller, NoHook, Reference, Sample, SimConfig, SimError, SimReport, Simulator, StepHook,
};
use std::time::Instant;

impl Simulator<'_> {
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
        self.check_settings(q0, cfg)?;
        self.start_at_rest(q0);
        self.apply_payload_window(0.0);
        let steps = (cfg.duration / cfg.dt).round() as usize;
        let audit = self.conservative() && hook.conservative();
        let e0 = audit.then(|| self.energy(&self.x.clone()));
        let mut max_err = vec![0.0f64; n];
        let start = Instant::now();
        let h = cfg.dt;
        let record_every = cfg.record_every.max(1);
        let mut x = std::mem::take(&mut self.x);
        self.control(0.0, &x, reference, &cfg.controller);
        on_sample(&self.sample(0.0, &x));
        // Power at the start of the step (actuator side).
        let mut balance = e0.map(|e0| EnergyBalance::start(e0, self.actuator_power(&x)));
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
            // The configuration before the step, one of the two where the hint is
            // evaluated (the state after a diverging step is garbage).
            self.q_before.copy_from_slice(&x[..n]);
            self.step(t, h, &mut x, reference, &cfg.controller, cfg.integrator)?;
            let t1 = t + h;
            if diverged(&x) {
                let err = self.divergence_error(q0, t1, h, cfg.integrator);
                self.x = x;
                return Err(err);
            }
            self.control(t1, &x, reference, &cfg.controller);
            for i in 0..n {
                max_err[i] = max_err[i].max((x[i] - self.qr[i]).abs());
            }
            if let Some(balance) = &mut balance {
                let p = self.actuator_power(&x);
                let e = self.energy(&x);
                balance.record(h, p, e);
            }
            if (step + 1) % record_every == 0 || step + 1 == steps {
                // (the last step is always recorded)
                on_sample(&self.sample(t1, &x));
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
            energy: balance.map(|b| b.audit()),
            final_q,
            interrupted,
        })
    }

    /// The initial state's length, a positive finite step and duration, and finite gains
    /// for every joint.
    fn check_settings(&self, q0: &[f64], cfg: &SimConfig) -> Result<(), SimError> {
        let n = self.n;
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
                Err(SimError::Config(format!(
                    "controller: gains need {n} finite values"
                )))
            }
            _ => Ok(()),
        }
    }

    /// `x = (q0, 0)`, with elastic joints the motors in static equilibrium:
    /// `θ = q + K⁻¹ g(q)`.
    fn start_at_rest(&mut self, q0: &[f64]) {
        let n = self.n;
        self.x.fill(0.0);
        self.x[..n].copy_from_slice(q0);
        if self.elastic {
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
    }

    /// The sample at `(t, x)` after the controller ran there.
    fn sample<'a>(&'a self, t: f64, x: &'a [f64]) -> Sample<'a> {
        let n = self.n;
        Sample {
            t,
            q: &x[..n],
            qd: &x[n..2 * n],
            tau: &self.tau,
            q_ref: &self.qr,
        }
    }
}
