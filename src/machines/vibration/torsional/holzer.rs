//! Holzer's method with transfer matrices (docs/reference_data.md §S3, textbook extras).
//!
//! The state at a station is `(φ, M)`: the disk angle and the torque in the shaft that
//! leaves it, `M_k = c_k (φ_{k+1} − φ_k)`. Across disk `k` at frequency `W` (point matrix)
//! `M ← M − W² J_k φ`; along shaft `k` (field matrix) `φ ← φ + M / c_k`; together the
//! textbook's `[[1 − W² J/c, 1/c], [−W² J, 1]]`. A rigid gear mesh of ratio `i` maps
//! `(φ, M) → (i φ, M / i)`. Starting from the free end `(1, 0)`, the torque left after
//! the last disk is the **residual torque** `R(W)`; it vanishes at the natural
//! frequencies.
//!
//! Roots are bracketed by counting: the angles `φ_1 = 1, φ_2, …, φ_n` and `R` are, up to
//! positive factors, the leading principal minors of `K − W² J` (the Holzer recurrence
//! `c_k φ_{k+1} = (c_{k−1} + c_k − W² J_k) φ_k − c_{k−1} φ_{k−1}` is their three-term
//! recurrence), so by Sturm's theorem the number of sign changes in `(φ_1, …, φ_n, R)` —
//! the node count of the Holzer table — is the number of natural frequencies below `W`.
//! Bisection on that count finds each frequency separately (no root can be skipped),
//! and needs every shaft stiffness positive.

use crate::machines::vibration::torsional::gear_stages::GearedChain;

/// A Holzer table at one frequency.
#[derive(Clone, Debug, PartialEq)]
pub struct HolzerTable {
    /// Frequency `W` (rad/s).
    pub omega: f64,
    /// Angle of every physical disk (input disks first), `φ_1 = 1`.
    pub angles: Vec<f64>,
    /// Torque in every physical shaft (N m per rad of `φ_1`).
    pub shaft_torques: Vec<f64>,
    /// Residual torque after the last disk.
    pub residual: f64,
}

/// The Holzer table of `chain` at `omega`.
pub fn holzer_table(chain: &GearedChain, omega: f64) -> HolzerTable {
    let w2 = omega * omega;
    let (mut phi, mut m) = (1.0, 0.0);
    let mut angles = Vec::new();
    let mut shaft_torques = Vec::new();
    for (s, (seg, _)) in chain.segments().into_iter().enumerate() {
        if s > 0 {
            let i = chain.stages[s - 1].ratio;
            phi *= i;
            m /= i;
        }
        for k in 0..seg.len() {
            angles.push(phi);
            m -= w2 * seg.inertia[k] * phi; // point matrix
            if k + 1 < seg.len() {
                shaft_torques.push(m);
                phi += m / seg.stiffness[k]; // field matrix
            }
        }
    }
    HolzerTable {
        omega,
        angles,
        shaft_torques,
        residual: m,
    }
}

/// The residual torque `R(W)` (module docs).
pub fn residual_torque(chain: &GearedChain, omega: f64) -> f64 {
    holzer_table(chain, omega).residual
}

/// Number of natural frequencies below `omega`: sign changes in `(φ_1, …, φ_n, R)`.
pub fn frequencies_below(chain: &GearedChain, omega: f64) -> usize {
    let t = holzer_table(chain, omega);
    let mut count = 0;
    let mut prev = true; // φ_1 = 1 > 0
    for &v in t.angles.iter().skip(1).chain(std::iter::once(&t.residual)) {
        let pos = v >= 0.0;
        if pos != prev {
            count += 1;
        }
        prev = pos;
    }
    count
}

/// All natural frequencies (rad/s, ascending; one per referred disk, the rigid-body
/// mode ≈ 0 first) by bisection on [`frequencies_below`].
pub fn holzer_frequencies(chain: &GearedChain) -> Vec<f64> {
    let r = chain.refer().chain;
    let n = r.len();
    // Gershgorin bound on J^{-1/2} K J^{-1/2}.
    let mut top: f64 = 0.0;
    for k in 0..n {
        let left = if k > 0 { r.stiffness[k - 1] } else { 0.0 };
        let right = if k + 1 < n { r.stiffness[k] } else { 0.0 };
        let mut row = (left + right) / r.inertia[k];
        if k > 0 {
            row += left / (r.inertia[k - 1] * r.inertia[k]).sqrt();
        }
        if k + 1 < n {
            row += right / (r.inertia[k] * r.inertia[k + 1]).sqrt();
        }
        top = top.max(row);
    }
    let w_top = (1.01 * top).sqrt().max(1e-300);
    (0..n)
        .map(|mode| {
            let (mut lo, mut hi) = (0.0, w_top);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                if frequencies_below(chain, mid) > mode {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            0.5 * (lo + hi)
        })
        .collect()
}
