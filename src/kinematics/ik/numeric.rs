//! Numeric inverse kinematics: Levenberg–Marquardt with adaptive damping, joint limits
//! inside the iteration, and random restarts within an iteration and time budget.
//!
//! With the pose error `e = [p* − p(q); log(R* R(q)ᵀ)]` (world axes, the frame origin's
//! world-aligned Jacobian `J`) and `E = ½ eᵀ W e`, each iteration solves
//!
//! `(Jᵀ W J + λ I) Δq = Jᵀ W e`,  `λ = μ (E + λ₀)`
//!
//! (Sugihara's damping `W_N = E·I + W̄_N` of "Solvability-unconcerned inverse kinematics by
//! the Levenberg–Marquardt method", 2011, scaled by an adaptive `μ` as in Chan & Lawrence:
//! a step that lowers `E` is taken and `μ` shrinks, one that does not is retried with a
//! larger `μ`). The new configuration is projected onto the joint limits before `E` is
//! evaluated, so every iterate — and every answer — is inside the limits. An attempt ends
//! when the tolerance is met, when it stalls (a local minimum or a limit-blocked descent),
//! or after `max_iterations`; then the solver restarts from a uniformly random
//! configuration, until `max_restarts` or the time budget. It returns the best pose
//! found, with a status:
//! - `converged`: within both tolerances;
//! - `unreachable`: not converged, and every attempt stalled at a stationary point (the
//!   residual cannot be reduced locally): the target is out of reach (or out of the
//!   limits' reach); the closest pose found and its residual are returned;
//! - `best_effort`: not converged and some attempt was still improving when the budget
//!   ran out.
//!
//! Nothing allocates inside the iteration: all buffers live in [`IkSolver`].

use crate::core::linalg::{cholesky_in_place, cholesky_solve_in_place};
use crate::core::spatial::{Mat3, Se3, Vec3};
use crate::kinematics::{compute_joint_jacobians, frame_jacobian, frame_placement, Expressed};
use crate::model::data::Data;
use crate::model::Model;
use nalgebra::DMatrix;
use rand::rngs::SmallRng;
use rand::SeedableRng;
use std::time::{Duration, Instant};

/// Options of the numeric solver.
#[derive(Clone, Debug)]
pub struct IkOptions {
    /// Solve for the position only (3 equations).
    pub position_only: bool,
    /// Position tolerance (m).
    pub tol_position: f64,
    /// Rotation tolerance (rad).
    pub tol_rotation: f64,
    /// Iterations per attempt.
    pub max_iterations: usize,
    /// Random restarts after the first attempt.
    pub max_restarts: usize,
    /// Wall-clock budget per target.
    pub time_budget: Duration,
    /// Keep every iterate inside the joint limits (on by default).
    pub respect_limits: bool,
    /// Seed of the restart generator (results are deterministic for a seed).
    pub seed: u64,
    /// Weight of the rotation rows relative to the position rows (m/rad).
    pub rotation_weight: f64,
}

impl Default for IkOptions {
    fn default() -> Self {
        Self {
            position_only: false,
            tol_position: 1e-6,
            tol_rotation: 1e-6,
            max_iterations: 80,
            max_restarts: 200,
            time_budget: Duration::from_millis(50),
            respect_limits: true,
            seed: 0x1c_5eed,
            rotation_weight: 0.5,
        }
    }
}

/// Outcome class of a solve.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum IkStatus {
    /// Within both tolerances.
    Converged,
    /// The budget ran out while an attempt was still improving.
    BestEffort,
    /// Every attempt stalled away from the target: out of reach.
    Unreachable,
}

impl IkStatus {
    /// The JSON/CLI spelling.
    pub fn as_str(&self) -> &'static str {
        match self {
            IkStatus::Converged => "converged",
            IkStatus::BestEffort => "best_effort",
            IkStatus::Unreachable => "unreachable",
        }
    }
}

/// The answer for one target.
#[derive(Clone, Debug, serde::Serialize)]
pub struct IkResult {
    /// Joint values (inside the limits when `respect_limits`).
    pub q: Vec<f64>,
    /// Status.
    pub status: IkStatus,
    /// Position error of the returned pose (m).
    pub position_error: f64,
    /// Rotation error of the returned pose (rad; 0 for position-only solves).
    pub rotation_error: f64,
    /// Iterations over all attempts.
    pub iterations: usize,
    /// Restarts used.
    pub restarts: usize,
    /// Wall-clock time (µs).
    pub time_us: f64,
}

/// `log(R)` as a rotation vector (axis · angle), robust near 0 and π.
pub fn rotation_log(r: &Mat3) -> Vec3 {
    let v = Vec3::new(
        r[(2, 1)] - r[(1, 2)],
        r[(0, 2)] - r[(2, 0)],
        r[(1, 0)] - r[(0, 1)],
    ) * 0.5;
    let c = ((r.trace() - 1.0) * 0.5).clamp(-1.0, 1.0);
    let s = v.norm();
    let angle = s.atan2(c);
    if s > 1e-7 {
        return v * (angle / s);
    }
    if c > 0.0 {
        // Small angle: sin θ ≈ θ.
        return v;
    }
    // Near π: the axis from the symmetric part, R ≈ 2 a aᵀ − 1.
    let d = Vec3::new(r[(0, 0)], r[(1, 1)], r[(2, 2)]);
    let k = if d.x >= d.y && d.x >= d.z {
        0
    } else if d.y >= d.z {
        1
    } else {
        2
    };
    let mut a = Vec3::zeros();
    a[k] = ((d[k] + 1.0) * 0.5).max(0.0).sqrt();
    for i in 0..3 {
        if i != k {
            a[i] = (r[(i, k)] + r[(k, i)]) / (4.0 * a[k]);
        }
    }
    let a = a.normalize();
    // Resolve the sign with the (small) antisymmetric part, then θ = atan2(|v|, c).
    let sign = if a.dot(&v) < 0.0 { -1.0 } else { 1.0 };
    a * (sign * angle)
}

/// Reusable solver state for one model (all buffers preallocated).
pub struct IkSolver {
    data: Data,
    jac: DMatrix<f64>,
    normal: DMatrix<f64>,
    chol: DMatrix<f64>,
    grad: Vec<f64>,
    step: Vec<f64>,
    q: Vec<f64>,
    q_try: Vec<f64>,
    best_q: Vec<f64>,
    rng: SmallRng,
}

/// Pose error `[p* − p; log(R* Rᵀ)]` and its two norms.
fn pose_error(target: &Se3, current: &Se3) -> ([f64; 6], f64, f64) {
    let ep = target.trans - current.trans;
    let er = rotation_log(&(target.rot * current.rot.transpose()));
    ([ep.x, ep.y, ep.z, er.x, er.y, er.z], ep.norm(), er.norm())
}

impl IkSolver {
    /// Buffers for `model` (the `nv × nv` normal matrix and its factor up to
    /// [`crate::model::data::EAGER_DENSE_DOF`]; larger models get them at the first solve).
    pub fn new(model: &Model) -> Self {
        let n = model.nv;
        let dense = if n <= crate::model::data::EAGER_DENSE_DOF {
            n
        } else {
            0
        };
        Self {
            data: Data::new(model),
            jac: DMatrix::zeros(6, n),
            normal: DMatrix::zeros(dense, dense),
            chol: DMatrix::zeros(dense, dense),
            grad: vec![0.0; n],
            step: vec![0.0; n],
            q: vec![0.0; n],
            q_try: vec![0.0; n],
            best_q: vec![0.0; n],
            rng: SmallRng::seed_from_u64(0),
        }
    }

    fn project(model: &Model, q: &mut [f64], respect_limits: bool) {
        for (k, x) in q.iter_mut().enumerate() {
            if respect_limits {
                *x = x.clamp(model.lower[k], model.upper[k]);
            }
            if model.is_continuous(k) {
                // Keep angles of unlimited joints in [−π, π).
                let two_pi = std::f64::consts::TAU;
                *x -= two_pi * ((*x + std::f64::consts::PI) / two_pi).floor();
            }
        }
    }

    /// Weighted cost `E = ½ eᵀ W e`, and the error norms, of configuration `q`.
    fn cost(
        &mut self,
        model: &Model,
        link: usize,
        target: &Se3,
        q: &[f64],
        opts: &IkOptions,
    ) -> (f64, f64, f64, [f64; 6]) {
        crate::kinematics::forward_kinematics(model, &mut self.data, q);
        let cur = frame_placement(model, &self.data, link);
        let (e, ep, er) = pose_error(target, &cur);
        let w2 = opts.rotation_weight * opts.rotation_weight;
        let rot = if opts.position_only {
            0.0
        } else {
            w2 * (e[3] * e[3] + e[4] * e[4] + e[5] * e[5])
        };
        let cost = 0.5 * (e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + rot);
        (cost, ep, if opts.position_only { 0.0 } else { er }, e)
    }

    fn converged(ep: f64, er: f64, opts: &IkOptions) -> bool {
        ep <= opts.tol_position && (opts.position_only || er <= opts.tol_rotation)
    }

    /// Whether `best_q` is a stationary point of the weighted residual (restricted to the
    /// joints not pressed against a limit): `‖Jᵀ W e‖ ≤ 1e-4 ‖J‖ ‖e‖`. Then no local move
    /// reduces the error and, with the restarts behind it, the target is out of reach.
    // Index loops over the Jacobian's rows and columns read like `Jᵀ W e`.
    #[allow(clippy::needless_range_loop)]
    fn stationary(&mut self, model: &Model, link: usize, target: &Se3, opts: &IkOptions) -> bool {
        let q = std::mem::take(&mut self.best_q);
        let (_, _, _, e) = self.cost(model, link, target, &q, opts);
        self.world_jacobian(model, link, &q);
        let rows = if opts.position_only { 3 } else { 6 };
        let w2 = opts.rotation_weight * opts.rotation_weight;
        let (mut g2, mut j2, mut e2) = (0.0, 0.0, 0.0);
        for r in 0..rows {
            let w = if r < 3 { 1.0 } else { w2 };
            e2 += w * e[r] * e[r];
        }
        for (k, qk) in q.iter().enumerate() {
            let mut g = 0.0;
            for r in 0..rows {
                let w = if r < 3 { 1.0 } else { w2 };
                g += self.jac[(r, k)] * w * e[r];
                j2 += w * self.jac[(r, k)] * self.jac[(r, k)];
            }
            // A joint at a limit with the gradient pushing outwards cannot move.
            let at_lower = opts.respect_limits && *qk <= model.lower[k] && g < 0.0;
            let at_upper = opts.respect_limits && *qk >= model.upper[k] && g > 0.0;
            if !(at_lower || at_upper) {
                g2 += g * g;
            }
        }
        self.best_q = q;
        g2.sqrt() <= 1e-4 * j2.sqrt() * e2.sqrt()
    }

    /// Solves for `link` reaching `target`, starting from `seed_q` (or the middle of the
    /// limits) and then from random configurations.
    pub fn solve(
        &mut self,
        model: &Model,
        link: usize,
        target: &Se3,
        seed_q: Option<&[f64]>,
        opts: &IkOptions,
    ) -> IkResult {
        let start = Instant::now();
        let n = model.nv;
        if self.normal.nrows() != n {
            self.normal = DMatrix::zeros(n, n);
            self.chol = DMatrix::zeros(n, n);
        }
        let finite = target
            .rot
            .iter()
            .chain(target.trans.iter())
            .all(|x| x.is_finite());
        if !finite {
            // Nothing to aim at: report the start configuration as unreachable.
            let mut q = seed_q
                .map(<[f64]>::to_vec)
                .unwrap_or_else(|| model.neutral());
            Self::project(model, &mut q, opts.respect_limits);
            return IkResult {
                q,
                status: IkStatus::Unreachable,
                position_error: f64::INFINITY,
                rotation_error: f64::INFINITY,
                iterations: 0,
                restarts: 0,
                time_us: start.elapsed().as_secs_f64() * 1e6,
            };
        }
        self.rng = SmallRng::seed_from_u64(opts.seed);
        match seed_q {
            Some(s) => self.q.copy_from_slice(s),
            None => {
                for k in 0..n {
                    let (lo, hi) = model.sampling_bounds(k);
                    self.q[k] = 0.5 * (lo + hi);
                }
            }
        }
        let mut best = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
        let mut iterations = 0;
        let mut restarts = 0;
        // Attempts that stalled at (nearly) the best residual: once there are enough of
        // them, more restarts will not find a better pose.
        let mut same_minimum = 0;
        'attempts: loop {
            let mut q = std::mem::take(&mut self.q);
            Self::project(model, &mut q, opts.respect_limits);
            let Descent {
                cost,
                ep,
                er,
                stalled,
            } = self.descend(model, link, target, &mut q, opts, &mut iterations);
            if stalled && (cost - best.0).abs() <= 1e-6 * best.0.max(cost) {
                same_minimum += 1;
            }
            if cost < best.0 {
                if stalled && cost < best.0 * (1.0 - 1e-6) {
                    same_minimum = 1;
                }
                best = (cost, ep, er);
                self.best_q.copy_from_slice(&q);
            }
            self.q = q;
            if Self::converged(best.1, best.2, opts) {
                break 'attempts;
            }
            if same_minimum >= 10
                || restarts >= opts.max_restarts
                || start.elapsed() >= opts.time_budget
            {
                break;
            }
            restarts += 1;
            let mut q = std::mem::take(&mut self.q);
            for (k, x) in q.iter_mut().enumerate() {
                let (lo, hi) = model.sampling_bounds(k);
                *x = rand::Rng::random_range(&mut self.rng, lo..=hi);
            }
            self.q = q;
        }
        let status = if Self::converged(best.1, best.2, opts) {
            IkStatus::Converged
        } else if self.stationary(model, link, target, opts) {
            IkStatus::Unreachable
        } else {
            IkStatus::BestEffort
        };
        IkResult {
            q: self.best_q.clone(),
            status,
            position_error: best.1,
            rotation_error: best.2,
            iterations,
            restarts,
            time_us: start.elapsed().as_secs_f64() * 1e6,
        }
    }
    /// One damped least-squares (Levenberg–Marquardt) descent from `q`, in place, until
    /// it converges, stalls (no gradient, no improving step, or five steps of negligible
    /// gain) or runs out of iterations (counted in `iterations`).
    fn descend(
        &mut self,
        model: &Model,
        link: usize,
        target: &Se3,
        q: &mut Vec<f64>,
        opts: &IkOptions,
        iterations: &mut usize,
    ) -> Descent {
        let (mut cost, mut ep, mut er, mut e) = self.cost(model, link, target, q, opts);
        let mut mu = 1.0;
        let mut stalled = false;
        let mut since_progress = 0;
        for _ in 0..opts.max_iterations {
            if Self::converged(ep, er, opts) {
                break;
            }
            *iterations += 1;
            self.normal_equations(model, link, q, &e, opts);
            let gnorm = self.grad.iter().map(|g| g * g).sum::<f64>().sqrt();
            if gnorm < 1e-14 * (1.0 + cost.sqrt()) {
                stalled = true;
                break;
            }
            // Damped step with backtracking on μ.
            let mut improved = false;
            for _ in 0..8 {
                if !self.damped_step(mu * (cost + 1e-6)) {
                    mu *= 10.0;
                    continue;
                }
                for ((t, qk), s) in self.q_try.iter_mut().zip(q.iter()).zip(&self.step) {
                    *t = qk + s;
                }
                let mut qt = std::mem::take(&mut self.q_try);
                Self::project(model, &mut qt, opts.respect_limits);
                let (c2, ep2, er2, e2) = self.cost(model, link, target, &qt, opts);
                if c2 < cost {
                    let gain = (cost - c2) / cost.max(f64::MIN_POSITIVE);
                    std::mem::swap(q, &mut qt);
                    self.q_try = qt;
                    since_progress = if gain < 1e-6 { since_progress + 1 } else { 0 };
                    cost = c2;
                    ep = ep2;
                    er = er2;
                    e = e2;
                    mu = (mu * 0.3).max(1e-9);
                    improved = true;
                    break;
                }
                self.q_try = qt;
                mu *= 10.0;
            }
            if !improved || since_progress >= 5 {
                stalled = true;
                break;
            }
        }
        Descent {
            cost,
            ep,
            er,
            stalled,
        }
    }

    /// `self.jac`: the Jacobian of `link` at `q`, world-aligned.
    fn world_jacobian(&mut self, model: &Model, link: usize, q: &[f64]) {
        compute_joint_jacobians(model, &mut self.data, q);
        frame_jacobian(
            model,
            &self.data,
            link,
            Expressed::WorldAligned,
            &mut self.jac,
        );
    }

    /// The frame Jacobian `J` (world-aligned, frame origin) at `q`, then the gradient
    /// `g = Jᵀ W e` into `grad` and the normal matrix `N = Jᵀ W J` into `normal` (`W`
    /// weighs the rotation rows by the rotation weight squared; position only: three
    /// rows).
    // Index loops over the Jacobian's rows and columns read like `Jᵀ W J` and `Jᵀ W e`.
    #[allow(clippy::needless_range_loop)]
    fn normal_equations(
        &mut self,
        model: &Model,
        link: usize,
        q: &[f64],
        e: &[f64; 6],
        opts: &IkOptions,
    ) {
        let n = model.nv;
        let rows = if opts.position_only { 3 } else { 6 };
        let w2 = opts.rotation_weight * opts.rotation_weight;
        self.world_jacobian(model, link, q);
        for i in 0..n {
            let mut g = 0.0;
            for r in 0..rows {
                let w = if r < 3 { 1.0 } else { w2 };
                g += self.jac[(r, i)] * w * e[r];
            }
            self.grad[i] = g;
            for j in 0..=i {
                let mut s = 0.0;
                for r in 0..rows {
                    let w = if r < 3 { 1.0 } else { w2 };
                    s += self.jac[(r, i)] * w * self.jac[(r, j)];
                }
                self.normal[(i, j)] = s;
                self.normal[(j, i)] = s;
            }
        }
    }

    /// The step `(N + λ I)⁻¹ g` into `step`; `false` when the damped matrix is not
    /// positive definite.
    fn damped_step(&mut self, lambda: f64) -> bool {
        self.step.copy_from_slice(&self.grad);
        self.chol.copy_from(&self.normal);
        for i in 0..self.step.len() {
            self.chol[(i, i)] += lambda;
        }
        let ok = cholesky_in_place(&mut self.chol).is_ok();
        if ok {
            cholesky_solve_in_place(&self.chol, &mut self.step);
        }
        ok
    }
}

/// Where one descent ended: the cost, position and rotation errors, and whether it
/// stalled before converging.
struct Descent {
    cost: f64,
    ep: f64,
    er: f64,
    stalled: bool,
}

/// Solves many targets in parallel (rayon), one solver per worker; target `i` uses seed
/// `opts.seed + i`, so results do not depend on the thread count.
pub fn solve_batch(
    model: &Model,
    link: usize,
    targets: &[Se3],
    seed_q: Option<&[f64]>,
    opts: &IkOptions,
) -> Vec<IkResult> {
    use rayon::prelude::*;
    targets
        .par_iter()
        .enumerate()
        .map_init(
            || IkSolver::new(model),
            |solver, (i, t)| {
                let mut o = opts.clone();
                o.seed = opts.seed.wrapping_add(i as u64);
                solver.solve(model, link, t, seed_q, &o)
            },
        )
        .collect()
}
