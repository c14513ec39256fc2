//! Study 2, integrators: step size × method (semi-implicit Euler, RK4, linearly implicit
//! Euler) on two arms, against
//!
//! - **energy error**: free motion under gravity (no controller, nothing dissipates), the
//!   simulator's energy audit `max |E(t) − E(0)|` relative to the energy scale;
//! - **tracking error**: computed torque (`K_p = 100`, `K_d = 20`) following the smooth
//!   reference `q_d(t) = q₀ + a (1 − cos ωt)` ([`Wave`]), the largest `|q − q_d|` over
//!   joints and time. On the rigid arm the controller's model is exact and the reference
//!   starts at rest on `q₀`, so the exact closed loop tracks perfectly and the whole
//!   error is integration error; on the elastic arm the link also lags the motor through
//!   the springs, a physical error the step size cannot remove;
//! - **wall time** of the tracking run (the simulator's energy audit included).
//!
//! Arms: the rigid iiwa 14 (7 DOF), and the same arm with stiff, undamped joint springs
//! (Spong's model, [`Elasticity`]): the fastest mode (spring against the light wrist)
//! makes explicit methods blow up above a critical step, reported as **diverged** (the
//! simulator's [`SimError::Diverged`]).

use crate::dynamics::{Effects, Elasticity};
use crate::model::Model;
use crate::sim::{Controller, Hold, Integrator, Reference, SimConfig, SimError, Simulator};
use crate::studies::tradeoffs::study_options::Options;
use crate::studies::tradeoffs::study_timing::Stats;
use serde::Serialize;

/// Sizes of the integrator study.
#[derive(Clone, Debug)]
pub struct IntegratorConfig {
    /// Steps to try (s), largest first.
    pub dts: Vec<f64>,
    /// Simulated duration of each run (s).
    pub duration: f64,
    /// Joint stiffness of the elastic arm (N m/rad).
    pub stiffness: f64,
    /// Motor-side inertia of the elastic arm (kg m²).
    pub motor_inertia: f64,
}

impl IntegratorConfig {
    /// The sizes of `mode`.
    pub fn for_mode(mode: crate::studies::tradeoffs::study_options::StudyMode) -> Self {
        let (dts, duration) = match mode {
            crate::studies::tradeoffs::study_options::StudyMode::Tiny => {
                (vec![4e-3, 2e-3, 1e-3], 0.2)
            }
            crate::studies::tradeoffs::study_options::StudyMode::Quick => (
                vec![1e-2, 3e-3, 1e-3, 7e-4, 5e-4, 3e-4, 1e-4, 3e-5, 1e-5],
                0.5,
            ),
            crate::studies::tradeoffs::study_options::StudyMode::Full => (
                vec![
                    1e-2, 5e-3, 2e-3, 1e-3, 7e-4, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5,
                ],
                1.0,
            ),
        };
        IntegratorConfig {
            dts,
            duration,
            stiffness: 1e4,
            motor_inertia: 0.1,
        }
    }
}

/// The tracked reference `q_d = q₀ + a (1 − cos ωt)`: at rest on `q₀` at `t = 0`.
pub struct Wave {
    /// Start configuration.
    pub q0: Vec<f64>,
    /// Amplitude per joint (rad).
    pub amplitude: Vec<f64>,
    /// Angular frequency (rad/s).
    pub omega: f64,
}

impl Reference for Wave {
    fn sample(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        let (s, c) = (self.omega * t).sin_cos();
        let w = self.omega;
        for i in 0..q.len() {
            let a = self.amplitude[i];
            q[i] = self.q0[i] + a * (1.0 - c);
            qd[i] = a * w * s;
            qdd[i] = a * w * w * c;
        }
    }
}

/// What one run gave.
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum IntegratorOutcome {
    /// Finished: the figure of merit.
    Value {
        /// Relative energy error or tracking error (rad).
        value: f64,
    },
    /// [`SimError::Diverged`] at time `t`.
    Diverged {
        /// Simulated time of the divergence (s).
        t: f64,
    },
    /// Another simulator error.
    Failed {
        /// Its message.
        message: String,
    },
}

impl IntegratorOutcome {
    /// The figure, when the run finished.
    pub fn value(&self) -> Option<f64> {
        match self {
            IntegratorOutcome::Value { value } => Some(*value),
            _ => None,
        }
    }

    /// Whether the run diverged.
    pub fn diverged(&self) -> bool {
        matches!(self, IntegratorOutcome::Diverged { .. })
    }
}

/// One (arm, method, step) cell.
#[derive(Clone, Debug, Serialize)]
pub struct IntegratorCell {
    /// Arm ("rigid" or "elastic").
    pub case: String,
    /// Integrator.
    pub method: &'static str,
    /// Step (s).
    pub dt: f64,
    /// Relative energy error of the free run.
    pub energy: IntegratorOutcome,
    /// Largest tracking error of the computed-torque run (rad).
    pub tracking: IntegratorOutcome,
    /// Wall time of the tracking run (s), when it finished.
    pub wall_s: Option<f64>,
    /// Wall time per step of the tracking run (µs).
    pub us_per_step: Option<f64>,
}

/// One arm of the study.
#[derive(Clone, Debug, Serialize)]
pub struct IntegratorCase {
    /// Short name ("rigid", "elastic").
    pub name: String,
    /// What it is.
    pub description: String,
    /// Fastest natural frequency estimate (rad/s) for the elastic arm.
    pub fastest_mode: Option<f64>,
}

/// Result of the integrator study.
#[derive(Clone, Debug, Serialize)]
pub struct IntegratorStudy {
    /// Robot.
    pub robot: String,
    /// Simulated duration of each run (s).
    pub duration: f64,
    /// The arms.
    pub cases: Vec<IntegratorCase>,
    /// Cells, case-major, then method, then step (largest first).
    pub cells: Vec<IntegratorCell>,
}

impl IntegratorStudy {
    /// Cells of one arm and method, largest step first.
    pub fn series(&self, case: &str, method: &str) -> Vec<&IntegratorCell> {
        self.cells
            .iter()
            .filter(|c| c.case == case && c.method == method)
            .collect()
    }

    /// The smallest step at which `method` diverged on `case` (either run), if any.
    pub fn smallest_diverged_dt(&self, case: &str, method: &str) -> Option<f64> {
        self.series(case, method)
            .iter()
            .filter(|c| c.energy.diverged() || c.tracking.diverged())
            .map(|c| c.dt)
            .reduce(f64::min)
    }

    /// The largest step at which neither run of `method` diverged on `case`, if any.
    pub fn largest_stable_dt(&self, case: &str, method: &str) -> Option<f64> {
        self.series(case, method)
            .iter()
            .filter(|c| !c.energy.diverged() && !c.tracking.diverged())
            .map(|c| c.dt)
            .reduce(f64::max)
    }
}

/// Tracking runs shorter than this (wall, s) are repeated for a median of three.
const REPEAT_BELOW_S: f64 = 0.2;

/// The methods compared, in report order.
pub const METHODS: [Integrator; 3] = [
    Integrator::SemiImplicitEuler,
    Integrator::Rk4,
    Integrator::Implicit,
];

fn outcome(
    r: &Result<crate::sim::SimReport, SimError>,
    f: impl Fn(&crate::sim::SimReport) -> f64,
) -> IntegratorOutcome {
    match r {
        Ok(rep) => IntegratorOutcome::Value { value: f(rep) },
        Err(SimError::Diverged { t, .. }) => IntegratorOutcome::Diverged { t: *t },
        Err(e) => IntegratorOutcome::Failed {
            message: e.to_string(),
        },
    }
}

/// Fastest mode estimate `max_i √(K (1/B + 1/M_ii))` at `q`.
fn fastest_mode(model: &Model, q: &[f64], k: f64, b: f64) -> f64 {
    let mut data = crate::model::data::Data::new(model);
    let m = crate::dynamics::crba(model, &mut data, q);
    (0..model.nv)
        .map(|i| (k * (1.0 / b + 1.0 / m[(i, i)])).sqrt())
        .fold(0.0, f64::max)
}

/// The two cases: rigid joints with gravity, and undamped joint springs (with the
/// fastest spring mode at `q0`).
fn cases(model: &Model, q0: &[f64], cfg: &IntegratorConfig) -> Vec<(IntegratorCase, Effects)> {
    let n = model.nv;
    let gravity = Effects::gravity(model.gravity);
    let elastic = Effects {
        elasticity: Some(Elasticity {
            stiffness: vec![cfg.stiffness; n],
            damping: vec![0.0; n],
            motor_inertia: vec![cfg.motor_inertia; n],
        }),
        ..gravity.clone()
    };
    let w = fastest_mode(model, q0, cfg.stiffness, cfg.motor_inertia);
    vec![
        (
            IntegratorCase {
                name: "rigid".into(),
                description: format!("{} ({n} DOF), rigid joints, gravity", model.name),
                fastest_mode: None,
            },
            gravity,
        ),
        (
            IntegratorCase {
                name: "elastic".into(),
                description: format!(
                    "{} with undamped joint springs K = {:.0e} N m/rad and motor inertia B = {} kg m² per joint (state 4 × {n})",
                    model.name, cfg.stiffness, cfg.motor_inertia
                ),
                fastest_mode: Some(w),
            },
            elastic,
        ),
    ]
}

/// Runs the study on the iiwa 14.
pub fn run(opts: &Options, cfg: &IntegratorConfig) -> Result<IntegratorStudy, String> {
    let model = crate::studies::tradeoffs::bundled_robots::bundled_robot("iiwa14.urdf")?;
    let n = model.nv;
    let q0: Vec<f64> = [0.3, 0.6, -0.4, -1.2, 0.5, 0.8, 0.2]
        .iter()
        .copied()
        .take(n)
        .collect();
    let cases = cases(&model, &q0, cfg);
    let reference = Wave {
        q0: q0.clone(),
        amplitude: vec![0.3; n],
        omega: std::f64::consts::PI,
    };
    let ct = Controller::ComputedTorque {
        kp: vec![100.0; n],
        kd: vec![20.0; n],
    };
    let mut cells = Vec::new();
    for (case, effects) in &cases {
        for method in METHODS {
            for &dt in &cfg.dts {
                opts.say(format!(
                    "integrators: {} {} dt {dt:.0e}",
                    case.name,
                    method.as_str()
                ));
                let run = |controller: &Controller, reference: &dyn Reference| {
                    let mut sim = Simulator::new(&model, effects.clone())
                        .map_err(|e| format!("integrators: {e}"))?;
                    let c = SimConfig {
                        dt,
                        duration: cfg.duration,
                        integrator: method,
                        controller: controller.clone(),
                        record_every: usize::MAX,
                    };
                    Ok::<_, String>(sim.run(&q0, &c, reference, |_| {}))
                };
                let free = run(&Controller::None, &Hold(q0.clone()))?;
                let track = run(&ct, &reference)?;
                let energy = outcome(&free, |r| {
                    r.energy.as_ref().map_or(f64::NAN, |e| e.max_relative_drift)
                });
                let tracking = outcome(&track, |r| {
                    r.max_tracking_error.iter().copied().fold(0.0, f64::max)
                });
                let (wall_s, us_per_step) = match &track {
                    Ok(r) => {
                        // Short runs are repeated: the median of three walls.
                        let mut walls = vec![r.wall_time_s];
                        if r.wall_time_s < REPEAT_BELOW_S {
                            for _ in 0..2 {
                                if let Ok(Ok(again)) = run(&ct, &reference) {
                                    walls.push(again.wall_time_s);
                                }
                            }
                        }
                        let w = Stats::of(&walls).median;
                        (Some(w), Some(w * 1e6 / r.steps.max(1) as f64))
                    }
                    Err(_) => (None, None),
                };
                cells.push(IntegratorCell {
                    case: case.name.clone(),
                    method: method.as_str(),
                    dt,
                    energy,
                    tracking,
                    wall_s,
                    us_per_step,
                });
            }
        }
    }
    Ok(IntegratorStudy {
        robot: model.name.clone(),
        duration: cfg.duration,
        cases: cases.into_iter().map(|(c, _)| c).collect(),
        cells,
    })
}

/// Median wall time per step (µs) of `method` over the cells of `case` that finished.
pub fn median_step_us(study: &IntegratorStudy, case: &str, method: &str) -> Option<f64> {
    let v: Vec<f64> = study
        .series(case, method)
        .iter()
        .filter_map(|c| c.us_per_step)
        .collect();
    (!v.is_empty()).then(|| Stats::of(&v).median)
}
