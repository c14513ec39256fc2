//! The finite-difference side of the derivatives study: Jacobians of inverse dynamics
//! (RNEA) and forward dynamics with respect to `(q, q̇)` by forward and central
//! differences ([`fd_jacobian`]), Ridders' extrapolation of central differences as the
//! careful reference ([`ridders_jacobian`]) and the relative error of one Jacobian
//! against another ([`relative_error`]). Everything works in preallocated buffers
//! ([`FdWork`]), so the study can time it without timing the allocator.
//!
//! A Jacobian here is `nv × 2nv`: `[∂f/∂q | ∂f/∂q̇]`, with `f = τ = RNEA(q, q̇, q̈)` or
//! `f = q̈ = FD(q, q̇, τ)`. Steps are absolute (rad, m, rad/s, m/s; the inputs are O(1)),
//! and the divisor is the step actually taken, `(x + h) − x` (or `(x + h) − (x − h)`).

use crate::dynamics::{forward_dynamics, rnea};
use crate::model::data::Data;
use crate::model::Model;
use nalgebra::DMatrix;
use serde::Serialize;

/// The function differentiated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Kernel {
    /// `τ = RNEA(q, q̇, q̈)`, against [`crate::dynamics::rnea_derivatives`].
    Rnea,
    /// `q̈ = forward_dynamics(q, q̇, τ)` (ABA; CRBA + Cholesky with mimic joints), against
    /// [`crate::dynamics::aba_derivatives`].
    Aba,
}

impl Kernel {
    /// Both kernels, RNEA first.
    pub const ALL: [Kernel; 2] = [Kernel::Rnea, Kernel::Aba];

    /// Name in the report.
    pub fn as_str(&self) -> &'static str {
        match self {
            Kernel::Rnea => "RNEA",
            Kernel::Aba => "ABA",
        }
    }
}

/// A difference quotient.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Scheme {
    /// `(f(x + h e_k) − f(x)) / h`: `2nv + 1` evaluations, error O(h).
    Forward,
    /// `(f(x + h e_k) − f(x − h e_k)) / 2h`: `4nv` evaluations, error O(h²).
    Central,
}

impl Scheme {
    /// Both schemes, forward first.
    pub const ALL: [Scheme; 2] = [Scheme::Forward, Scheme::Central];

    /// Name in the report.
    pub fn as_str(&self) -> &'static str {
        match self {
            Scheme::Forward => "forward",
            Scheme::Central => "central",
        }
    }

    /// Kernel evaluations per `nv × 2nv` Jacobian.
    pub fn evaluations(&self, nv: usize) -> usize {
        match self {
            Scheme::Forward => 2 * nv + 1,
            Scheme::Central => 4 * nv,
        }
    }
}

/// First steps of the Ridders tableaux, largest first. An entry takes a smaller start's
/// estimate only when that start's error estimate is [`RIDDERS_SWITCH`] times smaller:
/// a large start alone fails near configurations where the forward dynamics change fast
/// (its tableau never reaches the asymptotic range), while at the rounding level the
/// estimates are noisy and the largest start, least exposed to rounding, is the better
/// one.
pub const RIDDERS_STARTS: [f64; 3] = [0.1, 0.02, 0.004];
/// How much smaller a smaller start's error estimate must be to replace an entry.
pub const RIDDERS_SWITCH: f64 = 10.0;
/// Step ratio between Ridders levels (Numerical Recipes' `CON`).
pub const RIDDERS_CON: f64 = 1.4;
/// Levels of the Ridders tableau (central differences per column).
pub const RIDDERS_LEVELS: usize = 10;

/// Kernel evaluations of one Ridders Jacobian.
pub fn ridders_evaluations(nv: usize) -> usize {
    RIDDERS_STARTS.len() * 2 * RIDDERS_LEVELS * 2 * nv
}

/// Buffers of one model's difference quotients.
#[derive(Clone, Debug)]
pub struct FdWork {
    q: Vec<f64>,
    v: Vec<f64>,
    f0: Vec<f64>,
    fp: Vec<f64>,
    fm: Vec<f64>,
    /// Ridders tableau, `RIDDERS_LEVELS² × nv`.
    table: Vec<f64>,
    best: Vec<f64>,
    err: Vec<f64>,
    done: Vec<bool>,
}

impl FdWork {
    /// Buffers for `model`.
    pub fn new(model: &Model) -> Self {
        let n = model.nv;
        FdWork {
            q: vec![0.0; n],
            v: vec![0.0; n],
            f0: vec![0.0; n],
            fp: vec![0.0; n],
            fm: vec![0.0; n],
            table: vec![0.0; RIDDERS_LEVELS * RIDDERS_LEVELS * n],
            best: vec![0.0; n],
            err: vec![0.0; n],
            done: vec![false; n],
        }
    }
}

/// One state: `q`, `q̇` and the kernel's third input (`q̈` for RNEA, `τ` for ABA).
#[derive(Clone, Copy, Debug)]
pub struct KernelInput<'a> {
    /// Configuration.
    pub q: &'a [f64],
    /// Velocity.
    pub v: &'a [f64],
    /// `q̈` (RNEA) or `τ` (ABA).
    pub u: &'a [f64],
}

/// `f(q, v, u)` into `out` (NaN when the mass matrix is singular).
fn eval(
    k: Kernel,
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    u: &[f64],
    out: &mut [f64],
) {
    match k {
        Kernel::Rnea => out.copy_from_slice(rnea(model, data, q, v, u)),
        Kernel::Aba => match forward_dynamics(model, data, q, v, u) {
            Ok(x) => out.copy_from_slice(x),
            Err(_) => out.fill(f64::NAN),
        },
    }
}

/// The input perturbed by column `col` of the Jacobian: `q_col` for `col < nv`, else
/// `q̇_{col−nv}`.
fn input(w: &mut FdWork, nv: usize, col: usize) -> &mut f64 {
    if col < nv {
        &mut w.q[col]
    } else {
        &mut w.v[col - nv]
    }
}

/// Central difference of column `col` at step `h` into `w.fp` (`w.q`, `w.v` hold the
/// state and are restored).
fn central_column(
    k: Kernel,
    model: &Model,
    data: &mut Data,
    x: KernelInput,
    w: &mut FdWork,
    col: usize,
    h: f64,
) {
    let x0 = *input(w, model.nv, col);
    let (xp, xm) = (x0 + h, x0 - h);
    *input(w, model.nv, col) = xp;
    eval(k, model, data, &w.q, &w.v, x.u, &mut w.fp);
    *input(w, model.nv, col) = xm;
    eval(k, model, data, &w.q, &w.v, x.u, &mut w.fm);
    *input(w, model.nv, col) = x0;
    let step = xp - xm;
    for (p, m) in w.fp.iter_mut().zip(&w.fm) {
        *p = (*p - m) / step;
    }
}

/// The `nv × 2nv` Jacobian of kernel `k` at `x` by `scheme` with step `h`, into `jac`.
#[allow(clippy::too_many_arguments)]
pub fn fd_jacobian(
    k: Kernel,
    scheme: Scheme,
    h: f64,
    model: &Model,
    data: &mut Data,
    x: KernelInput,
    w: &mut FdWork,
    jac: &mut DMatrix<f64>,
) {
    let nv = model.nv;
    w.q.copy_from_slice(x.q);
    w.v.copy_from_slice(x.v);
    if scheme == Scheme::Central {
        for col in 0..2 * nv {
            central_column(k, model, data, x, w, col, h);
            jac.column_mut(col).copy_from_slice(&w.fp);
        }
        return;
    }
    eval(k, model, data, x.q, x.v, x.u, &mut w.f0);
    for col in 0..2 * nv {
        let x0 = *input(w, nv, col);
        *input(w, nv, col) = x0 + h;
        let step = *input(w, nv, col) - x0;
        eval(k, model, data, &w.q, &w.v, x.u, &mut w.fp);
        *input(w, nv, col) = x0;
        for (r, (p, f)) in w.fp.iter().zip(&w.f0).enumerate() {
            jac[(r, col)] = (p - f) / step;
        }
    }
}

/// Ridders' extrapolation of column `col` from the first step `h0` (Numerical Recipes'
/// `dfridr`, entry by entry: steps `h0 / RIDDERS_CON^i`, Neville's tableau, the estimate
/// with the smallest error estimate, stopped when the error grows twofold) into `w.best`,
/// its error estimate into `w.err`.
fn ridders_column(
    k: Kernel,
    h0: f64,
    model: &Model,
    data: &mut Data,
    x: KernelInput,
    w: &mut FdWork,
    col: usize,
) {
    let nv = model.nv;
    let con2 = RIDDERS_CON * RIDDERS_CON;
    let at = |i: usize, j: usize| (i * RIDDERS_LEVELS + j) * nv;
    w.err.fill(f64::INFINITY);
    w.done.fill(false);
    let mut h = h0;
    for i in 0..RIDDERS_LEVELS {
        central_column(k, model, data, x, w, col, h);
        let base = at(0, i);
        w.table[base..base + nv].copy_from_slice(&w.fp);
        let mut fac = con2;
        for j in 1..=i {
            for r in 0..nv {
                let (cur, left) = (w.table[at(j - 1, i) + r], w.table[at(j - 1, i - 1) + r]);
                let t = (cur * fac - left) / (fac - 1.0);
                w.table[at(j, i) + r] = t;
                let e = (t - cur).abs().max((t - left).abs());
                if !w.done[r] && e <= w.err[r] {
                    w.err[r] = e;
                    w.best[r] = t;
                }
            }
            fac *= con2;
        }
        for r in 0..nv {
            if i == 0 {
                w.best[r] = w.table[at(0, 0) + r];
            } else if (w.table[at(i, i) + r] - w.table[at(i - 1, i - 1) + r]).abs()
                >= 2.0 * w.err[r]
            {
                w.done[r] = true;
            }
        }
        h /= RIDDERS_CON;
    }
}

/// The `nv × 2nv` Jacobian of kernel `k` at `x` by Ridders' extrapolation of central
/// differences from each of [`RIDDERS_STARTS`] (entry by entry the largest start's
/// estimate unless a smaller start's error estimate is [`RIDDERS_SWITCH`] times smaller),
/// into `jac`, and its error estimate into `err`.
pub fn ridders_jacobian(
    k: Kernel,
    model: &Model,
    data: &mut Data,
    x: KernelInput,
    w: &mut FdWork,
    jac: &mut DMatrix<f64>,
    err: &mut DMatrix<f64>,
) {
    w.q.copy_from_slice(x.q);
    w.v.copy_from_slice(x.v);
    err.fill(f64::INFINITY);
    for col in 0..2 * model.nv {
        for h0 in RIDDERS_STARTS {
            ridders_column(k, h0, model, data, x, w, col);
            for (r, (b, e)) in w.best.iter().zip(&w.err).enumerate() {
                if RIDDERS_SWITCH * *e < err[(r, col)] {
                    err[(r, col)] = *e;
                    jac[(r, col)] = *b;
                }
            }
        }
    }
}

/// The largest relative error of `approx` against `exact` over the two `nv × nv` blocks
/// (`∂/∂q` and `∂/∂q̇`), each `max |approx − exact| / max |exact|` (max-abs norms,
/// relative to the block of `exact`). NaN when `approx` has a NaN.
pub fn relative_error(approx: &DMatrix<f64>, exact: &DMatrix<f64>) -> f64 {
    let nv = exact.nrows();
    let mut worst = 0.0f64;
    for b in 0..2 {
        let (a, e) = (approx.columns(b * nv, nv), exact.columns(b * nv, nv));
        let scale = e.amax().max(f64::MIN_POSITIVE);
        let d = (a - e).amax();
        if d.is_nan() || a.iter().any(|x| x.is_nan()) {
            return f64::NAN;
        }
        worst = worst.max(d / scale);
    }
    worst
}

/// `max |err| / max |exact|` per block, the largest over the two blocks: an error
/// estimate (absolute, entry by entry) made relative as [`relative_error`] does.
pub fn relative_estimate(err: &DMatrix<f64>, exact: &DMatrix<f64>) -> f64 {
    let nv = exact.nrows();
    (0..2)
        .map(|b| {
            err.columns(b * nv, nv).amax() / exact.columns(b * nv, nv).amax().max(f64::MIN_POSITIVE)
        })
        .fold(0.0, f64::max)
}
