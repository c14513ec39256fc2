//! Projection onto the path constraints (the CBiRRT2 approach of Berenson, Srinivasa,
//! Ferguson & Kuffner, ICRA 2009, and Stilman's "first-order retraction", 2007): a
//! configuration is moved by damped Gauss–Newton steps on the violated functions until
//! every function is at least half its interior margin inside,
//!
//! `Δq = −Gᵀ (G Gᵀ + λ I)⁻¹ (h_A + m_A)`,
//!
//! `G` the gradients of the active functions `A` (those not yet `m` inside), each step
//! kept within the joint limits and no longer than 0.5 (joint-space L2).
//!
//! Buffers are fixed arrays ([`crate::planning::path_constraints::MAX_FUNCTIONS`] rows):
//! nothing allocates per projection.

use crate::model::Model;
use crate::planning::path_constraints::{ConstraintSet, MAX_FUNCTIONS};

/// Most Gauss–Newton iterations of one projection.
pub const MAX_PROJECTION_ITERATIONS: usize = 40;

/// The projector's buffers.
#[derive(Clone, Debug)]
pub struct Projector {
    h: [f64; MAX_FUNCTIONS],
    grad: Vec<f64>,
    active: [usize; MAX_FUNCTIONS],
    step: Vec<f64>,
}

/// Solves the `n × n` symmetric positive definite system `a x = b` in place (`b` becomes
/// `x`) by Cholesky; false if `a` is not positive definite.
fn solve_spd(a: &mut [f64; MAX_FUNCTIONS * MAX_FUNCTIONS], b: &mut [f64], n: usize) -> bool {
    let m = MAX_FUNCTIONS;
    for j in 0..n {
        let mut d = a[j * m + j];
        for k in 0..j {
            d -= a[j * m + k] * a[j * m + k];
        }
        if d <= 0.0 || !d.is_finite() {
            return false;
        }
        let d = d.sqrt();
        a[j * m + j] = d;
        for i in j + 1..n {
            let mut s = a[i * m + j];
            for k in 0..j {
                s -= a[i * m + k] * a[j * m + k];
            }
            a[i * m + j] = s / d;
        }
    }
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= a[i * m + k] * b[k];
        }
        b[i] = s / a[i * m + i];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= a[k * m + i] * b[k];
        }
        b[i] = s / a[i * m + i];
    }
    true
}

impl Projector {
    /// Buffers for `nv` coordinates.
    pub fn new(nv: usize) -> Projector {
        Projector {
            h: [0.0; MAX_FUNCTIONS],
            grad: vec![0.0; MAX_FUNCTIONS * nv],
            active: [0; MAX_FUNCTIONS],
            step: vec![0.0; nv],
        }
    }

    /// Moves `q` onto the constraints (inside the limits `lo`, `hi`); true when every
    /// function is at least half its margin inside. The values at the answer are left in
    /// [`Projector::values`].
    pub fn project(
        &mut self,
        model: &Model,
        set: &mut ConstraintSet,
        lo: &[f32],
        hi: &[f32],
        q: &mut [f64],
    ) -> bool {
        let nv = q.len();
        for _ in 0..MAX_PROJECTION_ITERATIONS {
            let n = set.eval(model, q, &mut self.h, Some(&mut self.grad));
            let mut na = 0;
            let mut done = true;
            for j in 0..n {
                let m = set.margin(j);
                if self.h[j] > -0.5 * m {
                    done = false;
                }
                if self.h[j] > -m {
                    self.active[na] = j;
                    na += 1;
                }
            }
            if done {
                return true;
            }
            if !self.gauss_newton_step(set, na, nv) {
                return false;
            }
            let len = self.step.iter().map(|x| x * x).sum::<f64>().sqrt();
            let s = if len > 0.5 { 0.5 / len } else { 1.0 };
            for k in 0..nv {
                q[k] = (q[k] + s * self.step[k]).clamp(lo[k] as f64, hi[k] as f64);
            }
        }
        false
    }

    /// `step = −Gᵀ (G Gᵀ + λ I)⁻¹ (h + m)` over the `na` active functions.
    fn gauss_newton_step(&mut self, set: &ConstraintSet, na: usize, nv: usize) -> bool {
        let mut a = [0.0; MAX_FUNCTIONS * MAX_FUNCTIONS];
        let mut r = [0.0; MAX_FUNCTIONS];
        for (x, &j) in self.active[..na].iter().enumerate() {
            r[x] = self.h[j] + set.margin(j);
            for (y, &i) in self.active[..na].iter().enumerate() {
                let (gj, gi) = (&self.grad[j * nv..][..nv], &self.grad[i * nv..][..nv]);
                a[x * MAX_FUNCTIONS + y] = gj.iter().zip(gi).map(|(p, q)| p * q).sum();
            }
        }
        let trace: f64 = (0..na).map(|x| a[x * MAX_FUNCTIONS + x]).sum();
        if trace.is_nan() || trace <= 1e-18 {
            // No joint moves the violated functions (a singular pose, or a constraint
            // on a link no joint moves).
            return false;
        }
        for x in 0..na {
            a[x * MAX_FUNCTIONS + x] += 1e-6 * trace / na as f64;
        }
        if !solve_spd(&mut a, &mut r, na) {
            return false;
        }
        self.step.fill(0.0);
        for (x, &j) in self.active[..na].iter().enumerate() {
            for k in 0..nv {
                self.step[k] -= self.grad[j * nv + k] * r[x];
            }
        }
        true
    }

    /// The function values of the last evaluation.
    pub fn values(&self) -> &[f64] {
        &self.h
    }
}
