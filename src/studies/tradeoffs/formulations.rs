//! Study 3, dynamics formulations: time per call against DOF on the generated chains
//! ([`crate::model::chain::chain_spec`], 2 to 64 joints) for
//!
//! - **RNEA** (inverse dynamics, O(n));
//! - **CRBA + Cholesky** (forward dynamics through the mass matrix, O(n²) to build `M` on
//!   a chain plus O(n³) to factor it; [`forward_dynamics_crba`]);
//! - **ABA** (forward dynamics, O(n));
//! - **Lagrange, trace form** (inverse dynamics, the textbook's O(n⁴) reference; it
//!   allocates) and **Lagrange, energy form** (Christoffel symbols, O(n⁴)), both capped in
//!   DOF because of their growth;
//!
//! all at the same answer: every state `(q, q̇, q̈)` is random, `τ = RNEA(q, q̇, q̈)`, and the
//! forward methods are fed that `τ`. The agreement columns are the largest differences
//! over the states: `|q̈_ABA − q̈_CRBA|` (absolute, rad/s², and relative to `max |q̈|`),
//! `|q̈_ABA − q̈|` (the round trip through RNEA), and `|τ_RNEA − τ_Lagrange|` relative to
//! `max |τ|`.

use crate::dynamics::{aba, forward_dynamics_crba, lagrange_energy, lagrange_trace, rnea};
use crate::model::data::Data;
use crate::model::{chain, Model};
use crate::studies::bench::{random_states, random_unit_states, STATES};
use crate::studies::tradeoffs::study_options::Options;
use crate::studies::tradeoffs::study_timing::{time_calls, Stats};
use serde::Serialize;
use std::hint::black_box;

/// Sizes of the formulation study.
#[derive(Clone, Debug)]
pub struct FormulationConfig {
    /// Chain lengths.
    pub dofs: Vec<usize>,
    /// Largest chain the trace-form Lagrange runs on.
    pub max_dof_trace: usize,
    /// Largest chain the energy-form Lagrange runs on.
    pub max_dof_energy: usize,
    /// Timing rounds per measurement.
    pub rounds: usize,
    /// Target length of a round (ns).
    pub round_ns: f64,
    /// States compared for the agreement columns.
    pub agreement_states: usize,
}

impl FormulationConfig {
    /// The sizes of `mode`.
    pub fn for_mode(mode: crate::studies::tradeoffs::study_options::StudyMode) -> Self {
        match mode {
            crate::studies::tradeoffs::study_options::StudyMode::Tiny => FormulationConfig {
                dofs: vec![2, 4, 8],
                max_dof_trace: 4,
                max_dof_energy: 4,
                rounds: 15,
                round_ns: 5e4,
                agreement_states: 8,
            },
            crate::studies::tradeoffs::study_options::StudyMode::Quick => FormulationConfig {
                dofs: vec![2, 4, 6, 8, 12, 16, 24, 32, 48, 64],
                max_dof_trace: 12,
                max_dof_energy: 12,
                rounds: 101,
                round_ns: 1e5,
                agreement_states: 32,
            },
            crate::studies::tradeoffs::study_options::StudyMode::Full => FormulationConfig {
                dofs: vec![2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64],
                max_dof_trace: 32,
                max_dof_energy: 32,
                rounds: 301,
                round_ns: 2e5,
                agreement_states: 64,
            },
        }
    }
}

/// Formulation names as they appear in the report.
pub const NAMES: [&str; 5] = [
    "RNEA",
    "CRBA + Cholesky",
    "ABA",
    "Lagrange (trace)",
    "Lagrange (energy)",
];

/// One chain length.
#[derive(Clone, Debug, Serialize)]
pub struct FormulationRow {
    /// Degrees of freedom.
    pub dof: usize,
    /// Time per call (ns) of each formulation in [`NAMES`] order; `None` above its cap.
    pub ns: [Option<Stats>; 5],
    /// `max |q̈_ABA − q̈_CRBA|` (rad/s²).
    pub aba_vs_crba_abs: f64,
    /// The same relative to `max |q̈|`.
    pub aba_vs_crba_rel: f64,
    /// `max |q̈_ABA − q̈|` relative to `max |q̈|` (round trip through RNEA).
    pub roundtrip_rel: f64,
    /// `max |τ_RNEA − τ_trace| / max |τ|`, when the trace form ran.
    pub rnea_vs_trace_rel: Option<f64>,
    /// `max |τ_RNEA − τ_energy| / max |τ|`, when the energy form ran.
    pub rnea_vs_energy_rel: Option<f64>,
}

/// Result of the formulation study.
#[derive(Clone, Debug, Serialize)]
pub struct FormulationStudy {
    /// Rows by DOF.
    pub rows: Vec<FormulationRow>,
    /// States compared per row.
    pub agreement_states: usize,
    /// Trace-form cap.
    pub max_dof_trace: usize,
    /// Energy-form cap.
    pub max_dof_energy: usize,
}

impl FormulationStudy {
    /// `(dof, median ns)` of formulation `k` ([`NAMES`] index).
    pub fn series(&self, k: usize) -> Vec<(f64, f64)> {
        self.rows
            .iter()
            .filter_map(|r| r.ns[k].map(|s| (r.dof as f64, s.median)))
            .collect()
    }
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn max_abs(a: &[f64]) -> f64 {
    a.iter().map(|x| x.abs()).fold(0.0, f64::max)
}

/// Agreement figures of `model` over `states` random states.
fn agreement(model: &Model, states: usize, seed: u64, trace: bool, energy: bool) -> [f64; 5] {
    let nv = model.nv;
    let mut data = Data::new(model);
    let g = model.gravity;
    let qs = random_states(model, seed);
    let vs = random_unit_states(nv, seed ^ 1);
    let as_ = random_unit_states(nv, seed ^ 2);
    let (mut d_abs, mut d_rel, mut rt, mut tr, mut en) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for s in 0..states.min(STATES) {
        let r = s * nv..(s + 1) * nv;
        let (q, v, a) = (&qs[r.clone()], &vs[r.clone()], &as_[r]);
        let tau = rnea(model, &mut data, q, v, a).to_vec();
        let qdd_aba = aba(model, &mut data, q, v, &tau).to_vec();
        let qdd_crba = match forward_dynamics_crba(model, &mut data, q, v, &tau) {
            Ok(x) => x.to_vec(),
            Err(_) => vec![f64::NAN; nv],
        };
        let scale = max_abs(&qdd_aba).max(f64::MIN_POSITIVE);
        let d = max_abs_diff(&qdd_aba, &qdd_crba);
        d_abs = d_abs.max(d);
        d_rel = d_rel.max(d / scale);
        rt = rt.max(max_abs_diff(&qdd_aba, a) / max_abs(a).max(f64::MIN_POSITIVE));
        let tscale = max_abs(&tau).max(f64::MIN_POSITIVE);
        if trace {
            let t = lagrange_trace(model, &mut data, q, v, a, &g);
            tr = tr.max(max_abs_diff(&t, &tau) / tscale);
        }
        if energy {
            let t = lagrange_energy(model, &mut data, q, v, a, &g);
            en = en.max(max_abs_diff(&t, &tau) / tscale);
        }
    }
    [d_abs, d_rel, rt, tr, en]
}

/// Median ns per call of RNEA, CRBA + Cholesky, ABA and (when asked) the two Lagrange
/// forms on `model`, cycling over the same random states (τ from RNEA, so the forward
/// methods solve for the same answer).
fn timings(
    model: &Model,
    cfg: &FormulationConfig,
    seed: u64,
    trace: bool,
    energy: bool,
) -> [Option<Stats>; 5] {
    let nv = model.nv;
    let g = model.gravity;
    let mut data = Data::new(model);
    let qs = random_states(model, seed);
    let vs = random_unit_states(nv, seed ^ 0x11);
    let as_ = random_unit_states(nv, seed ^ 0x22);
    // τ per state, so the forward methods solve for the same answer.
    let mut taus = vec![0.0; STATES * nv];
    for s in 0..STATES {
        let r = s * nv..(s + 1) * nv;
        let t = rnea(
            model,
            &mut data,
            &qs[r.clone()],
            &vs[r.clone()],
            &as_[r.clone()],
        );
        taus[r].copy_from_slice(t);
    }
    // State `k mod STATES` of the flattened inputs.
    let slice = |k: usize| (k % STATES) * nv..(k % STATES + 1) * nv;
    let mut ns: [Option<Stats>; 5] = [None; 5];
    ns[0] = Some(time_calls(cfg.rounds, cfg.round_ns, |k| {
        let r = slice(k);
        rnea(
            model,
            &mut data,
            black_box(&qs[r.clone()]),
            &vs[r.clone()],
            &as_[r],
        );
        black_box(&data.tau);
    }));
    ns[1] = Some(time_calls(cfg.rounds, cfg.round_ns, |k| {
        let r = slice(k);
        let _ = black_box(forward_dynamics_crba(
            model,
            &mut data,
            black_box(&qs[r.clone()]),
            &vs[r.clone()],
            &taus[r],
        ));
    }));
    ns[2] = Some(time_calls(cfg.rounds, cfg.round_ns, |k| {
        let r = slice(k);
        aba(
            model,
            &mut data,
            black_box(&qs[r.clone()]),
            &vs[r.clone()],
            &taus[r],
        );
        black_box(&data.qdd);
    }));
    if trace {
        ns[3] = Some(time_calls(cfg.rounds, cfg.round_ns, |k| {
            let r = slice(k);
            black_box(lagrange_trace(
                model,
                &mut data,
                black_box(&qs[r.clone()]),
                &vs[r.clone()],
                &as_[r],
                &g,
            ));
        }));
    }
    if energy {
        ns[4] = Some(time_calls(cfg.rounds, cfg.round_ns, |k| {
            let r = slice(k);
            black_box(lagrange_energy(
                model,
                &mut data,
                black_box(&qs[r.clone()]),
                &vs[r.clone()],
                &as_[r],
                &g,
            ));
        }));
    }
    ns
}

/// Runs the study.
pub fn run(opts: &Options, cfg: &FormulationConfig) -> Result<FormulationStudy, String> {
    let mut rows = Vec::new();
    for &n in &cfg.dofs {
        opts.say(format!("formulations: {n} DOF"));
        let model = Model::build(chain::chain_spec(n))
            .map_err(|e| e.to_string())?
            .0;
        let trace = n <= cfg.max_dof_trace;
        let energy = n <= cfg.max_dof_energy;
        let ns = timings(&model, cfg, opts.seed, trace, energy);
        let [d_abs, d_rel, rt, tr, en] = agreement(
            &model,
            cfg.agreement_states,
            opts.seed ^ 0x33,
            trace,
            energy,
        );
        rows.push(FormulationRow {
            dof: n,
            ns,
            aba_vs_crba_abs: d_abs,
            aba_vs_crba_rel: d_rel,
            roundtrip_rel: rt,
            rnea_vs_trace_rel: trace.then_some(tr),
            rnea_vs_energy_rel: energy.then_some(en),
        });
    }
    Ok(FormulationStudy {
        rows,
        agreement_states: cfg.agreement_states.min(STATES),
        max_dof_trace: cfg.max_dof_trace,
        max_dof_energy: cfg.max_dof_energy,
    })
}
