//! TOPP by reachability analysis (TOPP-RA): Pham and Pham, "A new approach to
//! time-optimal path parameterization based on reachability analysis", *IEEE Trans.
//! Robotics* 34(3), 2018.
//!
//! On the grid `s_0 < … < s_N` (`Δ_i = s_{i+1} − s_i`), the state is `x_i = b_i = ṡ_i²` and
//! the control `u_i = a_i = s̈` on interval `i`, with the dynamics (their eq. 9)
//!
//! `x_{i+1} = x_i + 2 Δ_i u_i`.
//!
//! The stage constraints `Ω_i` are linear in `(u_i, x_i)`: with `e ∈ {i, i+1}` the two
//! ends of the interval and `x_{i+1}` substituted by the dynamics (the conservative
//! "both ends" form the conic solver uses too, see the module docs of `topp`):
//!
//! - velocity at knot `i`: `q'_j(s_i)² x_i ≤ v_j²`;
//! - acceleration: `|q'_j(s_e) u_i + q''_j(s_e) x_e| ≤ a_j`;
//! - torque: `|m_j(s_e) u_i + c_j(s_e) x_e + g_j(s_e) + f_j(s_e)| ≤ τ_j`, `f` the friction
//!   estimate at the knot;
//!
//! each limit less its tightening from the dense check. For `e = i + 1`,
//! `α u + β x_{i+1} = (α + 2Δ_i β) u + β x_i`.
//!
//! **Backward pass** (their eq. 14–15): the controllable sets, intervals of `x`,
//!
//! `K_N = {0}` (rest at the end),
//! `K_i = { x ≥ 0 : ∃u, (u, x) ∈ Ω_i, x + 2Δ_i u ∈ K_{i+1} }`,
//!
//! each end of `K_i` one two-variable LP in `(u, x)` (`min x` and `max x`), solved exactly by
//! [`crate::motion::topp::lp2`]. An empty `K_i`, or `0 ∉ K_0`, means no motion from rest to rest
//! exists.
//!
//! **Forward pass** (their eq. 16, greedy): `x_0 = 0`, then for each stage the largest
//! admissible control that keeps the state controllable,
//!
//! `u_i = max { u : (u, x_i) ∈ Ω_i, x_i + 2Δ_i u ∈ K_{i+1} }`,  `x_{i+1} = x_i + 2Δ_i u_i`,
//!
//! a one-dimensional LP (an intersection of intervals). `O(N)` LPs of a few dozen
//! half-planes; all buffers are allocated once per [`Reach`].
//!
//! Optimality. The traversal time `Σ 2Δ_i / (√x_i + √x_{i+1})` decreases in every `x_i`,
//! so a profile that is the largest admissible one at every stage is optimal. The greedy
//! profile is that when `R_i(x) = max { x + 2Δ_i u : (u, x) ∈ Ω_i } ∩ K_{i+1}`, the
//! largest state reachable in one step, does not decrease in `x` (by induction,
//! `x*_i ≤ x_i ⇒ x*_{i+1} ≤ R_i(x*_i) ≤ R_i(x_i) = x_{i+1}`). A near-end constraint
//! `α u + β x ≤ γ` gives `R_i` the slope `1 − 2Δ_i β/α`, negative where `2Δ_i q''` outweighs
//! `q'` — at the ends of a path that starts at rest, where `q' → 0`. There the greedy
//! profile may be slightly slower than the conic optimum: by 1e-5 to 3e-5 of the duration
//! in one solve on the test paths; after the check-and-repair loop, by 1.5e-5 to 1.2e-4
//! on the main job's three pieces (8e-5 of their total).

use crate::motion::topp::discretised::Problem;
use crate::motion::topp::lp2::{maximize, HalfPlane};
use crate::motion::trajectory_error::TrajectoryError;

/// Largest `b` when no velocity limit bounds a stage (the path is at rest in `s` there).
const B_CAP: f64 = 1e12;

/// Buffers of TOPP-RA for one grid: the stage constraints and the controllable sets.
pub(super) struct Reach {
    /// Half-planes per stage: two slots for `K_{i+1}`, then `Ω_i`.
    rows: Vec<HalfPlane>,
    /// Used rows per stage (slots included).
    used: Vec<usize>,
    /// Rows reserved per stage.
    per: usize,
    /// Upper bound of `x_i` from the velocity limits.
    b_max: Vec<f64>,
    /// `K_i = [k_lo_i, k_hi_i]`.
    k_lo: Vec<f64>,
    k_hi: Vec<f64>,
}

impl Reach {
    /// Buffers for `nn` intervals and `n` joints.
    pub(super) fn new(nn: usize, n: usize) -> Self {
        let per = 2 + 9 * n;
        Reach {
            rows: vec![HalfPlane::default(); nn * per],
            used: vec![0; nn],
            per,
            b_max: vec![0.0; nn + 1],
            k_lo: vec![0.0; nn + 1],
            k_hi: vec![0.0; nn + 1],
        }
    }

    /// Solves the discretised problem `p`: writes `b_i = x_i` (`N + 1` values).
    pub(super) fn solve(&mut self, p: &Problem, b: &mut [f64]) -> Result<(), TrajectoryError> {
        let nn = p.ds.len();
        for i in 0..nn {
            self.stage_rows(p, i);
        }
        self.backward(p)?;
        self.forward(p, b);
        Ok(())
    }

    /// Writes `Ω_i` into stage `i`'s rows (after the two slots), and `b_max[i]`.
    fn stage_rows(&mut self, p: &Problem, i: usize) {
        let n = p.torque_on.len();
        let two_d = 2.0 * p.ds[i];
        let base = i * self.per;
        let mut k = 2;
        let mut b_max = B_CAP;
        let mut push = |rows: &mut [HalfPlane], na: f64, nb: f64, h: f64| {
            rows[base + k] = HalfPlane { na, nb, h };
            k += 1;
        };
        let g = p.grid;
        for j in 0..n {
            let dq = g.dq[i * n + j];
            if dq != 0.0 {
                let v = (p.limits.velocity[j] - p.tight_v[i * n + j]).max(0.0);
                push(&mut self.rows, 0.0, dq * dq, v * v);
                b_max = b_max.min(v * v / (dq * dq));
            }
            let lim = (p.limits.acceleration[j] - p.tight_a[i * n + j]).max(0.0);
            for e in [i, i + 1] {
                let (dq, ddq) = (g.dq[e * n + j], g.ddq[e * n + j]);
                if dq == 0.0 && ddq == 0.0 {
                    continue;
                }
                // α u + β x_e with x_e = x_i (+ 2Δ u at the far end).
                let na = if e == i { dq } else { dq + two_d * ddq };
                push(&mut self.rows, na, ddq, lim);
                push(&mut self.rows, -na, -ddq, lim);
            }
            if p.torque_on[j] {
                let lim = (p.limits.effort[j] - p.tight_t[i * n + j]).max(0.0);
                for e in [i, i + 1] {
                    let (m, c) = (g.m[e * n + j], g.c[e * n + j]);
                    let off = g.g[e * n + j] + p.fric[e * n + j];
                    let na = if e == i { m } else { m + two_d * c };
                    push(&mut self.rows, na, c, lim - off);
                    push(&mut self.rows, -na, -c, lim + off);
                }
            }
        }
        self.used[i] = k;
        self.b_max[i] = b_max;
    }

    /// The controllable sets `K_N … K_0`.
    fn backward(&mut self, p: &Problem) -> Result<(), TrajectoryError> {
        let nn = p.ds.len();
        self.k_lo[nn] = 0.0;
        self.k_hi[nn] = 0.0;
        for i in (0..nn).rev() {
            let two_d = 2.0 * p.ds[i];
            let (lo1, hi1) = (self.k_lo[i + 1], self.k_hi[i + 1]);
            let base = i * self.per;
            // x + 2Δ u ∈ K_{i+1}.
            self.rows[base] = HalfPlane {
                na: two_d,
                nb: 1.0,
                h: hi1,
            };
            self.rows[base + 1] = HalfPlane {
                na: -two_d,
                nb: -1.0,
                h: -lo1,
            };
            let rows = &self.rows[base..base + self.used[i]];
            let bm = self.b_max[i];
            let lo = [(lo1 - bm) / two_d, 0.0];
            let hi = [hi1 / two_d, bm];
            let top = maximize([0.0, 1.0], rows, lo, hi);
            let bottom = maximize([0.0, -1.0], rows, lo, hi);
            match (bottom, top) {
                (Some(x0), Some(x1)) => {
                    self.k_lo[i] = x0[1].max(0.0);
                    self.k_hi[i] = x1[1].max(self.k_lo[i]);
                }
                _ => {
                    return Err(TrajectoryError::Topp(format!(
                        "the limits admit no motion along this path: from s = {:.4} on, no path \
                         speed can be brought to rest at the end (empty controllable set at \
                         interval {i} of {nn}); some torque limit is below what the path needs",
                        p.s[i]
                    )))
                }
            }
        }
        if self.k_lo[0] > 1e-12 * (1.0 + self.k_hi[0]) {
            return Err(TrajectoryError::Topp(
                "the limits admit no motion along this path: it cannot start from rest \
                 (0 is outside the first controllable set)"
                    .into(),
            ));
        }
        Ok(())
    }

    /// The greedy forward pass from rest: `b_0 = 0`, largest controllable `u_i`.
    fn forward(&self, p: &Problem, b: &mut [f64]) {
        let nn = p.ds.len();
        b[0] = 0.0;
        for i in 0..nn {
            let x = b[i];
            let two_d = 2.0 * p.ds[i];
            let (lo1, hi1) = (self.k_lo[i + 1], self.k_hi[i + 1]);
            let mut u_hi = (hi1 - x) / two_d;
            // Only the upper end of `u` is needed: the LP of K_i guarantees a feasible `u`,
            // and the greedy choice is the largest.
            let base = i * self.per;
            for r in &self.rows[base + 2..base + self.used[i]] {
                if r.na > 0.0 {
                    u_hi = u_hi.min((r.h - r.nb * x) / r.na);
                }
            }
            b[i + 1] = (x + two_d * u_hi).clamp(lo1, hi1).max(0.0);
        }
        b[nn] = 0.0;
    }
}
