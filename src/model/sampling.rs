//! Configurations inside the joint limits: neutral and uniformly random.

use crate::model::Model;
use rand::Rng;

impl Model {
    /// Sampling interval of coordinate `k`: its limits, `[-π, π]` for continuous joints,
    /// and `[-1, 1]` (m) for a prismatic joint without limits.
    pub fn sampling_bounds(&self, k: usize) -> (f64, f64) {
        let (lo, hi) = (self.lower[k], self.upper[k]);
        if lo.is_finite() && hi.is_finite() {
            (lo, hi)
        } else if self.is_continuous(k)
            || self.dof_joint(k).jtype != crate::model::JointType::Prismatic
        {
            (-std::f64::consts::PI, std::f64::consts::PI)
        } else {
            (-1.0, 1.0)
        }
    }

    /// The middle of each coordinate's sampling interval (0 for unlimited joints).
    pub fn neutral(&self) -> Vec<f64> {
        (0..self.nv)
            .map(|k| {
                let (lo, hi) = self.sampling_bounds(k);
                0.5 * (lo + hi)
            })
            .collect()
    }

    /// A configuration drawn uniformly inside the limits.
    pub fn random_q(&self, rng: &mut impl Rng) -> Vec<f64> {
        (0..self.nv)
            .map(|k| {
                let (lo, hi) = self.sampling_bounds(k);
                if hi > lo {
                    rng.random_range(lo..=hi)
                } else {
                    lo
                }
            })
            .collect()
    }

    /// Whether `q` lies inside the position limits (with tolerance `tol`).
    pub fn within_limits(&self, q: &[f64], tol: f64) -> bool {
        q.iter()
            .enumerate()
            .all(|(k, &x)| x >= self.lower[k] - tol && x <= self.upper[k] + tol)
    }
}
