//! Study 5, effects: what each physical effect costs when switched on alone, against the
//! bare rigid model (no gravity), on the iiwa 14:
//!
//! - **inverse dynamics**: one [`inverse_dynamics`] call at a random `(q, q̇, q̈)`;
//! - **simulation step**: one semi-implicit Euler step, i.e. one forward-dynamics
//!   evaluation ([`forward_dynamics_with`], or [`elastic_forward_dynamics`] with joint
//!   springs, whose state also carries the motor angles) and the state update. Each step
//!   starts from a stored random state and writes the next state aside, so the timing
//!   does not drift with a trajectory.
//!
//! Every effect set is measured in several interleaved passes (so a burst of load on the
//! shared machine hits all of them alike); the figures are the median and p99 over all
//! rounds, and the ratio of medians to the bare model's. Inverse dynamics with elastic
//! joints is the rigid link-side computation (the springs enter through the motor
//! states): it is listed for completeness and costs what the bare model does.

use crate::core::spatial::{Inertia, Mat3, Vec3};
use crate::dynamics::{
    elastic_forward_dynamics, forward_dynamics_with, inverse_dynamics, Effects, Elasticity,
    ExternalWrench, Friction, Payload, Rotor,
};
use crate::model::data::Data;
use crate::model::Model;
use crate::studies::bench::{random_states, random_unit_states, STATES};
use crate::studies::tradeoffs::study_options::Options;
use crate::studies::tradeoffs::study_timing::{time_rounds, Stats};
use serde::Serialize;
use std::hint::black_box;

/// Sizes of the effects study.
#[derive(Clone, Debug)]
pub struct EffectConfig {
    /// Interleaved passes over the effect sets.
    pub passes: usize,
    /// Timing rounds per set and pass.
    pub rounds: usize,
    /// Target length of a round (ns).
    pub round_ns: f64,
}

impl EffectConfig {
    /// The sizes of `mode`.
    pub fn for_mode(mode: crate::studies::tradeoffs::study_options::StudyMode) -> Self {
        match mode {
            crate::studies::tradeoffs::study_options::StudyMode::Tiny => EffectConfig {
                passes: 2,
                rounds: 9,
                round_ns: 5e4,
            },
            crate::studies::tradeoffs::study_options::StudyMode::Quick => EffectConfig {
                passes: 5,
                rounds: 41,
                round_ns: 1e5,
            },
            crate::studies::tradeoffs::study_options::StudyMode::Full => EffectConfig {
                passes: 11,
                rounds: 101,
                round_ns: 2e5,
            },
        }
    }
}

/// One effect set.
#[derive(Clone, Debug, Serialize)]
pub struct EffectRow {
    /// Name ("bare", "gravity", …, "all").
    pub name: String,
    /// What is switched on.
    pub description: String,
    /// Inverse dynamics time per call (ns).
    pub inverse_ns: Stats,
    /// Simulation step time (ns).
    pub step_ns: Stats,
    /// `inverse_ns.median / bare`.
    pub inverse_ratio: f64,
    /// `step_ns.median / bare`.
    pub step_ratio: f64,
}

/// Result of the effects study.
#[derive(Clone, Debug, Serialize)]
pub struct EffectStudy {
    /// Robot.
    pub robot: String,
    /// Rows; the first is the bare model.
    pub rows: Vec<EffectRow>,
}

/// The effect sets, bare first, each effect alone, then all of them.
pub fn effect_sets(m: &Model) -> Result<Vec<(&'static str, String, Effects)>, String> {
    let n = m.nv;
    let tool = m
        .link_id("tool0")
        .or_else(|| m.links.iter().rposition(|l| l.body != crate::model::WORLD))
        .ok_or("the model has no moving link")?;
    let g = Some(m.gravity);
    let friction = Friction {
        viscous: vec![0.5; n],
        coulomb: vec![1.0; n],
        stiction: vec![1.5; n],
        stribeck_velocity: vec![0.1; n],
        smoothing: 1e-3,
    };
    let rotor = Rotor {
        inertia: vec![1e-4; n],
        gear_ratio: vec![100.0; n],
        efficiency: vec![0.9; n],
    };
    let elasticity = Elasticity {
        stiffness: vec![1e4; n],
        damping: vec![2.0; n],
        motor_inertia: vec![0.1; n],
    };
    let payload = Payload::new(
        m,
        tool,
        Inertia::new(3.0, Vec3::new(0.0, 0.0, 0.08), Mat3::identity() * 5e-3),
    )
    .map_err(|e| e.to_string())?;
    let wrench = vec![ExternalWrench {
        link: tool,
        force: Vec3::new(0.0, 0.0, -20.0),
        moment: Vec3::new(0.0, 1.0, 0.0),
    }];
    let bare = Effects::default();
    let tool_name = &m.links[tool].name;
    Ok(vec![
        ("bare", "rigid bodies, no gravity".into(), bare.clone()),
        (
            "gravity",
            "gravity (0, 0, −9.81)".into(),
            Effects {
                gravity: g,
                ..bare.clone()
            },
        ),
        (
            "friction",
            "viscous + Coulomb + Stribeck (tanh-regularised) per joint".into(),
            Effects {
                friction: Some(friction.clone()),
                ..bare.clone()
            },
        ),
        (
            "rotor",
            "rotor inertia 1e-4 kg m², gear ratio 100, efficiency 0.9".into(),
            Effects {
                rotor: Some(rotor.clone()),
                ..bare.clone()
            },
        ),
        (
            "elasticity",
            "joint springs K = 1e4 N m/rad, D = 2 N m s/rad, B = 0.1 kg m² (motor states)".into(),
            Effects {
                elasticity: Some(elasticity.clone()),
                ..bare.clone()
            },
        ),
        (
            "payload",
            format!("3 kg payload on {tool_name}"),
            Effects {
                payload: Some(payload.clone()),
                ..bare.clone()
            },
        ),
        (
            "external",
            format!("one wrench on {tool_name}"),
            Effects {
                external: wrench.clone(),
                ..bare.clone()
            },
        ),
        (
            "all",
            "every effect above at once".into(),
            Effects {
                gravity: g,
                friction: Some(friction),
                rotor: Some(rotor),
                elasticity: Some(elasticity),
                payload: Some(payload),
                external: wrench,
            },
        ),
    ])
}

/// Runs the study on the iiwa 14.
pub fn run(opts: &Options, cfg: &EffectConfig) -> Result<EffectStudy, String> {
    let model = crate::studies::tradeoffs::bundled_robots::bundled_robot("iiwa14.urdf")?;
    let n = model.nv;
    let sets = effect_sets(&model)?;
    for (name, _, e) in &sets {
        e.validate(&model)
            .map_err(|m| format!("effects '{name}': {m}"))?;
    }
    let qs = random_states(&model, opts.seed);
    let vs = random_unit_states(n, opts.seed ^ 0x44);
    let as_ = random_unit_states(n, opts.seed ^ 0x55);
    let ths: Vec<f64> = qs
        .iter()
        .zip(random_unit_states(n, opts.seed ^ 0x66))
        .map(|(q, d)| q + 0.01 * d)
        .collect();
    let thds = random_unit_states(n, opts.seed ^ 0x77);
    let taus: Vec<f64> = random_unit_states(n, opts.seed ^ 0x88)
        .iter()
        .map(|x| 20.0 * x)
        .collect();
    let h = 1e-3;
    let mut data = Data::new(&model);
    let (mut q1, mut v1, mut th1, mut thd1, mut thdd) = (
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
    );
    let mut inv: Vec<Vec<f64>> = vec![Vec::new(); sets.len()];
    let mut step: Vec<Vec<f64>> = vec![Vec::new(); sets.len()];
    for pass in 0..cfg.passes.max(1) {
        opts.say(format!("effects: pass {}/{}", pass + 1, cfg.passes.max(1)));
        for (i, (_, _, e)) in sets.iter().enumerate() {
            let r = |k: usize| (k % STATES) * n..(k % STATES + 1) * n;
            inv[i].extend(time_rounds(cfg.rounds, cfg.round_ns, |k| {
                let s = r(k);
                inverse_dynamics(
                    &model,
                    &mut data,
                    e,
                    black_box(&qs[s.clone()]),
                    &vs[s.clone()],
                    &as_[s],
                );
                black_box(&data.tau);
            }));
            let elastic = e.elasticity.is_some();
            step[i].extend(time_rounds(cfg.rounds, cfg.round_ns, |k| {
                let s = r(k);
                let (q, v, tau) = (black_box(&qs[s.clone()]), &vs[s.clone()], &taus[s.clone()]);
                if elastic {
                    let (th, thd) = (&ths[s.clone()], &thds[s]);
                    if let Ok(qdd) = elastic_forward_dynamics(
                        &model, &mut data, e, q, v, th, thd, tau, &mut thdd,
                    ) {
                        for j in 0..n {
                            v1[j] = v[j] + h * qdd[j];
                            q1[j] = q[j] + h * v1[j];
                            thd1[j] = thd[j] + h * thdd[j];
                            th1[j] = th[j] + h * thd1[j];
                        }
                    }
                } else if let Ok(qdd) = forward_dynamics_with(&model, &mut data, e, q, v, tau) {
                    for j in 0..n {
                        v1[j] = v[j] + h * qdd[j];
                        q1[j] = q[j] + h * v1[j];
                    }
                }
                black_box((&q1, &v1, &th1, &thd1));
            }));
        }
    }
    let bare_inv = Stats::of(&inv[0]).median;
    let bare_step = Stats::of(&step[0]).median;
    let rows = sets
        .iter()
        .enumerate()
        .map(|(i, (name, desc, _))| {
            let (a, b) = (Stats::of(&inv[i]), Stats::of(&step[i]));
            EffectRow {
                name: (*name).into(),
                description: desc.clone(),
                inverse_ns: a,
                step_ns: b,
                inverse_ratio: a.median / bare_inv,
                step_ratio: b.median / bare_step,
            }
        })
        .collect();
    Ok(EffectStudy {
        robot: model.name.clone(),
        rows,
    })
}
