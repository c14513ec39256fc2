//! Study 7, dynamics derivatives: the analytical derivatives
//! ([`rnea_derivatives`]: `∂τ/∂q`, `∂τ/∂q̇`, `M`; [`aba_derivatives`]: `∂q̈/∂q`,
//! `∂q̈/∂q̇`, `M⁻¹`) against forward and central finite differences of the kernels they
//! differentiate (RNEA; forward dynamics, which is ABA except on models with mimic joints)
//! over a range of steps `h`, on the UR5, the Panda, the iiwa 14 and generated chains
//! ([`crate::model::chain::chain_spec`]).
//!
//! **Accuracy**: the relative error of each scheme's `nv × 2nv` Jacobian `[∂/∂q | ∂/∂q̇]`
//! against the analytical one ([`relative_error`]: max-abs norm per block, relative to the
//! analytical block), the largest over the states; and, as the cross-check of the
//! analytical matrices themselves, their error against Ridders' extrapolation of central
//! differences ([`ridders_jacobian`]) next to that reference's own error estimate.
//! **Time**: per-call medians of the analytical call, the forward and central Jacobians and
//! the reference, in interleaved passes (the machine is shared). The analytical calls also
//! return `M` (resp. `M⁻¹`), which the difference schemes do not compute: the ratios
//! favour the differences.
//!
//! Complex-step differentiation is not measured: armsim's kernels are written for `f64`
//! only (no kernel is generic over the scalar), see [`COMPLEX_STEP_NOTE`].

use crate::dynamics::{aba_derivatives, rnea, rnea_derivatives};
use crate::model::data::Data;
use crate::model::{chain, Model};
use crate::studies::bench::{random_states, random_unit_states, STATES};
use crate::studies::tradeoffs::difference_quotients::{
    fd_jacobian, relative_error, relative_estimate, ridders_jacobian, FdWork, Kernel, KernelInput,
    Scheme,
};
use crate::studies::tradeoffs::study_options::{Options, StudyMode};
use crate::studies::tradeoffs::study_timing::{time_rounds, Stats};
use nalgebra::DMatrix;
use serde::Serialize;
use std::hint::black_box;

/// Why the study has no complex-step column (quoted in the report).
pub const COMPLEX_STEP_NOTE: &str = "Complex-step differentiation (`Im f(x + ih) / h`, no \
subtractive cancellation, so exact to rounding at any tiny h) needs the kernel evaluated in \
complex arithmetic. armsim's RNEA, ABA and CRBA (and the Lagrange forms) are written for `f64` \
only (`core::spatial` types and `Data` buffers are `f64`), so it does not apply to them; it \
would take a scalar-generic kernel (spatial algebra, model constants and work buffers generic \
over a `RealField`, as Pinocchio's templates are), i.e. a second RNEA, which the study does \
not add.";

/// Sizes of the derivatives study.
#[derive(Clone, Debug)]
pub struct DerivativeConfig {
    /// Bundled robot files.
    pub robots: Vec<&'static str>,
    /// Generated chain lengths.
    pub chains: Vec<usize>,
    /// Difference steps, largest first.
    pub steps: Vec<f64>,
    /// Random states per robot (accuracy: the worst; timing: cycled).
    pub states: usize,
    /// Interleaved timing passes.
    pub passes: usize,
    /// Timing rounds per method and pass.
    pub rounds: usize,
    /// Target length of a round (ns).
    pub round_ns: f64,
}

/// `10^(−k/per_decade)` for `k = first..=last`, computed from integer powers so that the
/// decades are exact (`1e-5`, not `1.0000000000000001e-5`).
fn log_steps(per_decade: i32, first: i32, last: i32) -> Vec<f64> {
    (first..=last)
        .map(|k| {
            let (dec, rem) = (k.div_euclid(per_decade), k.rem_euclid(per_decade));
            10f64.powi(-dec) * 10f64.powf(-f64::from(rem) / f64::from(per_decade))
        })
        .collect()
}

impl DerivativeConfig {
    /// The sizes of `mode`.
    pub fn for_mode(mode: StudyMode) -> Self {
        let robots = vec!["ur5.urdf", "panda.urdf", "iiwa14.urdf"];
        match mode {
            StudyMode::Tiny => DerivativeConfig {
                robots,
                chains: vec![8],
                steps: log_steps(1, 1, 12),
                states: 2,
                passes: 1,
                rounds: 5,
                round_ns: 5e4,
            },
            StudyMode::Quick => DerivativeConfig {
                robots,
                chains: vec![8, 32],
                steps: log_steps(2, 2, 24),
                states: 8,
                passes: 3,
                rounds: 21,
                round_ns: 1e5,
            },
            StudyMode::Full => DerivativeConfig {
                robots,
                chains: vec![8, 16, 32, 64],
                steps: log_steps(2, 2, 24),
                states: 32,
                passes: 5,
                rounds: 41,
                round_ns: 2e5,
            },
        }
    }
}

/// One kernel on one robot.
#[derive(Clone, Debug, Serialize)]
pub struct KernelResult {
    /// Which kernel.
    pub kernel: Kernel,
    /// Forward-difference error at each step of [`DerivativeStudy::steps`].
    pub forward_error: Vec<f64>,
    /// Central-difference error at each step.
    pub central_error: Vec<f64>,
    /// Analytical against the Ridders reference.
    pub analytical_error: f64,
    /// The reference's own error estimate (relative, as the errors).
    pub reference_estimate: f64,
    /// Time per analytical call (ns).
    pub analytical_ns: Stats,
    /// Time per forward-difference Jacobian (ns).
    pub forward_ns: Stats,
    /// Time per central-difference Jacobian (ns).
    pub central_ns: Stats,
    /// Time per Ridders Jacobian (ns).
    pub reference_ns: Stats,
}

impl KernelResult {
    /// The errors of `scheme`, by step.
    pub fn errors(&self, scheme: Scheme) -> &[f64] {
        match scheme {
            Scheme::Forward => &self.forward_error,
            Scheme::Central => &self.central_error,
        }
    }

    /// The time of `scheme` (ns).
    pub fn ns(&self, scheme: Scheme) -> Stats {
        match scheme {
            Scheme::Forward => self.forward_ns,
            Scheme::Central => self.central_ns,
        }
    }
}

/// One robot.
#[derive(Clone, Debug, Serialize)]
pub struct DerivativeCase {
    /// Robot name (`chain N` for the generated chains).
    pub name: String,
    /// Velocity coordinates.
    pub nv: usize,
    /// Whether forward dynamics went through CRBA + Cholesky (mimic joints) instead of ABA.
    pub mimic: bool,
    /// RNEA, then ABA.
    pub kernels: Vec<KernelResult>,
}

/// Result of the derivatives study.
#[derive(Clone, Debug, Serialize)]
pub struct DerivativeStudy {
    /// Difference steps, largest first.
    pub steps: Vec<f64>,
    /// States per robot.
    pub states: usize,
    /// Robots.
    pub cases: Vec<DerivativeCase>,
}

impl DerivativeStudy {
    /// The smallest error of `scheme` in `k` and its step.
    pub fn best(&self, k: &KernelResult, scheme: Scheme) -> (f64, f64) {
        self.steps
            .iter()
            .zip(k.errors(scheme))
            .filter(|(_, e)| e.is_finite())
            .map(|(h, e)| (*h, *e))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((f64::NAN, f64::NAN))
    }

    /// The error of `scheme` in `k` at the step nearest `h` (log scale).
    pub fn error_at(&self, k: &KernelResult, scheme: Scheme, h: f64) -> f64 {
        self.steps
            .iter()
            .zip(k.errors(scheme))
            .min_by(|a, b| {
                (a.0.ln() - h.ln())
                    .abs()
                    .total_cmp(&(b.0.ln() - h.ln()).abs())
            })
            .map_or(f64::NAN, |(_, e)| *e)
    }
}

/// Random states of `model`: `q`, `q̇`, `q̈` and `τ = RNEA(q, q̇, q̈)`, flattened.
struct States {
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    tau: Vec<f64>,
    nv: usize,
    count: usize,
}

impl States {
    fn new(model: &Model, count: usize, seed: u64) -> Self {
        let nv = model.nv;
        let (q, v, a) = (
            random_states(model, seed),
            random_unit_states(nv, seed ^ 0xd1),
            random_unit_states(nv, seed ^ 0xd2),
        );
        let mut data = Data::new(model);
        let mut tau = vec![0.0; count * nv];
        for s in 0..count {
            let r = s * nv..(s + 1) * nv;
            tau[r.clone()].copy_from_slice(rnea(
                model,
                &mut data,
                &q[r.clone()],
                &v[r.clone()],
                &a[r.clone()],
            ));
        }
        States {
            q,
            v,
            a,
            tau,
            nv,
            count,
        }
    }

    /// State `s mod count` as the input of kernel `k`.
    fn point(&self, k: Kernel, s: usize) -> KernelInput<'_> {
        let r = (s % self.count) * self.nv..(s % self.count + 1) * self.nv;
        let u = match k {
            Kernel::Rnea => &self.a[r.clone()],
            Kernel::Aba => &self.tau[r.clone()],
        };
        KernelInput {
            q: &self.q[r.clone()],
            v: &self.v[r],
            u,
        }
    }
}

/// The analytical `nv × 2nv` Jacobian of `k` at `x` into `out`.
fn analytical(
    k: Kernel,
    model: &Model,
    data: &mut Data,
    x: KernelInput,
    out: &mut DMatrix<f64>,
) -> Result<(), String> {
    let nv = model.nv;
    let (dq, dv) = match k {
        Kernel::Rnea => {
            let p = rnea_derivatives(model, data, x.q, x.v, x.u);
            (p.dtau_dq, p.dtau_dv)
        }
        Kernel::Aba => {
            let p = aba_derivatives(model, data, x.q, x.v, x.u).map_err(|e| e.to_string())?;
            (p.ddq_dq, p.ddq_dv)
        }
    };
    out.columns_mut(0, nv).copy_from(dq);
    out.columns_mut(nv, nv).copy_from(dv);
    Ok(())
}

/// Accuracy of kernel `k`: the worst over the states of each scheme's error at each step,
/// of the analytical error against the reference and of the reference's estimate.
fn accuracy(k: Kernel, model: &Model, st: &States, steps: &[f64]) -> Result<KernelResult, String> {
    let nv = model.nv;
    let mut data = Data::new(model);
    let mut w = FdWork::new(model);
    let (mut an, mut fd, mut rf, mut re) = (
        DMatrix::zeros(nv, 2 * nv),
        DMatrix::zeros(nv, 2 * nv),
        DMatrix::zeros(nv, 2 * nv),
        DMatrix::zeros(nv, 2 * nv),
    );
    let worst = |acc: &mut f64, e: f64| {
        *acc = if e.is_nan() || acc.is_nan() {
            f64::NAN
        } else {
            acc.max(e)
        }
    };
    let mut out = KernelResult {
        kernel: k,
        forward_error: vec![0.0; steps.len()],
        central_error: vec![0.0; steps.len()],
        analytical_error: 0.0,
        reference_estimate: 0.0,
        analytical_ns: Stats::default(),
        forward_ns: Stats::default(),
        central_ns: Stats::default(),
        reference_ns: Stats::default(),
    };
    for s in 0..st.count {
        let x = st.point(k, s);
        analytical(k, model, &mut data, x, &mut an)?;
        ridders_jacobian(k, model, &mut data, x, &mut w, &mut rf, &mut re);
        worst(&mut out.analytical_error, relative_error(&an, &rf));
        worst(&mut out.reference_estimate, relative_estimate(&re, &rf));
        for (i, &h) in steps.iter().enumerate() {
            fd_jacobian(k, Scheme::Forward, h, model, &mut data, x, &mut w, &mut fd);
            worst(&mut out.forward_error[i], relative_error(&fd, &an));
            fd_jacobian(k, Scheme::Central, h, model, &mut data, x, &mut w, &mut fd);
            worst(&mut out.central_error[i], relative_error(&fd, &an));
        }
    }
    Ok(out)
}

/// What is timed, in [`timings`]' order.
#[derive(Clone, Copy)]
enum Method {
    Analytical,
    Fd(Scheme),
    Reference,
}

const METHODS: [Method; 4] = [
    Method::Analytical,
    Method::Fd(Scheme::Forward),
    Method::Fd(Scheme::Central),
    Method::Reference,
];

/// Per-call times (ns) of the analytical call, the forward and central Jacobians (at the
/// classic steps ε^½ and ε^⅓; the time does not depend on the step) and the reference,
/// for kernel `k`, in interleaved passes.
fn timings(k: Kernel, model: &Model, st: &States, cfg: &DerivativeConfig) -> [Stats; 4] {
    let nv = model.nv;
    let mut data = Data::new(model);
    let mut w = FdWork::new(model);
    let (mut jac, mut err) = (DMatrix::zeros(nv, 2 * nv), DMatrix::zeros(nv, 2 * nv));
    let mut all: [Vec<f64>; 4] = Default::default();
    for _ in 0..cfg.passes.max(1) {
        for (m, times) in METHODS.iter().zip(all.iter_mut()) {
            times.extend(time_rounds(cfg.rounds, cfg.round_ns, |c| {
                let x = st.point(k, c);
                match *m {
                    Method::Analytical => {
                        let _ = analytical(k, model, &mut data, black_box(x), &mut jac);
                    }
                    Method::Fd(s) => {
                        let h = match s {
                            Scheme::Forward => f64::EPSILON.sqrt(),
                            Scheme::Central => f64::EPSILON.cbrt(),
                        };
                        fd_jacobian(k, s, h, model, &mut data, black_box(x), &mut w, &mut jac);
                    }
                    Method::Reference => {
                        ridders_jacobian(
                            k,
                            model,
                            &mut data,
                            black_box(x),
                            &mut w,
                            &mut jac,
                            &mut err,
                        );
                    }
                }
                black_box(&jac);
            }));
        }
    }
    all.map(|t| Stats::of(&t))
}

/// One robot: accuracy and timing of both kernels.
fn case(
    name: String,
    model: &Model,
    cfg: &DerivativeConfig,
    seed: u64,
) -> Result<DerivativeCase, String> {
    let st = States::new(model, cfg.states.clamp(1, STATES), seed);
    let mut kernels = Vec::new();
    for k in Kernel::ALL {
        let mut r = accuracy(k, model, &st, &cfg.steps).map_err(|e| format!("{name}: {e}"))?;
        [r.analytical_ns, r.forward_ns, r.central_ns, r.reference_ns] = timings(k, model, &st, cfg);
        kernels.push(r);
    }
    Ok(DerivativeCase {
        name,
        nv: model.nv,
        mimic: model.has_mimic,
        kernels,
    })
}

/// Runs the study.
pub fn run(opts: &Options, cfg: &DerivativeConfig) -> Result<DerivativeStudy, String> {
    let mut models = Vec::new();
    for file in &cfg.robots {
        let m = crate::studies::tradeoffs::bundled_robots::bundled_robot(file)?;
        models.push((m.name.clone(), m));
    }
    for &n in &cfg.chains {
        let m = Model::build(chain::chain_spec(n))
            .map_err(|e| e.to_string())?
            .0;
        models.push((format!("chain {n}"), m));
    }
    let mut cases = Vec::new();
    for (name, model) in &models {
        opts.say(format!("derivatives: {name} ({} DOF)", model.nv));
        cases.push(case(name.clone(), model, cfg, opts.seed ^ 0xde)?);
    }
    Ok(DerivativeStudy {
        steps: cfg.steps.clone(),
        states: cfg.states.clamp(1, STATES),
        cases,
    })
}
