//! The estimator and its interval, from the counts of the volume pass at each doubling
//! of the sample budget (see `docs/workspace.md`, "The estimate and its interval").
//!
//! At every stage `k` (all samples so far, `N_k = R · 2^k`), on the pooled estimation grid
//! (all samples, one grid shifted by a seeded random offset):
//! - the **closed occupancy**: the occupied cells plus the cells of their morphological
//!   closing by the `3^D` cube that touch a sparsely hit cell (hit once or twice).
//!   Joint-space sampling leaves low-density cells empty in the bulk and along the
//!   boundary long after the occupied set has taken the workspace's shape; closing fills
//!   them, never grows a digital half-space, and (restricted to sparse neighbourhoods)
//!   leaves alone the concave corners that well-hit cells surround. Its cells that no
//!   sample hit (the *unhit* fraction) measure how much of it is inferred;
//! - the **corrected measure** `C_k = c · (O − E/2 + (1 + D) H)` of the closed occupancy:
//!   `O` cells, `E` exposed faces (the first-order voxel bias is `E c / 2`), `H` isolated
//!   holes (counted as filled);
//! - Richardson's `2 O(h) − O(2h)` of the closed occupancy: `so = |C − richardson|` is the
//!   scale of what the first-order correction leaves;
//! - each replicate's `C` on its own grid (its own samples, its own random shift): their
//!   spread is the noise scale `s` of the pooled `C` (one grid too, so the lattice noise
//!   does not average out; the sampling noise makes it conservative).
//!
//! What closing cannot fill are the boundary *slivers*, cells the workspace meets in a
//! corner of depth `δ` (measure `∝ δ^D`): they are found like `n^(−1/D)`, so the
//! increments of `C_k` shrink by `ρ = 2^(−1/D)` per doubling, and the growth still to come
//! is the geometric [`tail`] `G = ΔC_K ρ / (1 − ρ)`. The headline is `V = C_K + G`, and,
//! once fewer than [`INTERVAL_UNHIT`] of the closed cells are unhit, the 95 % interval is
//! `[C_K − t s − so, C_K + U + t s + so]` (`t` Student's 97.5 % quantile for `R − 1`
//! degrees of freedom), the slivers' bound `U = max(TAIL_SPAN · G, D f₁ c)` with `f₁` the
//! boundary cells of the closed occupancy hit once (Good–Turing: a sliver of depth `δ`
//! holds `∝ δ^D` of a cell, so `E f₀ ≤ D E f₁`; the increments alone are noisy when the
//! cells are coarse). Before that only a lower bound is given, with the samples
//! an interval would need; while more than [`TAIL_UNHIT`] of the closed cells are unhit
//! (the bulk still filling, its increments not yet the slivers') the headline is `C_K`.

use serde::Serialize;

/// Counts of one stage.
#[derive(Clone, Debug)]
pub(crate) struct Stage {
    /// Total samples so far.
    pub samples: u64,
    /// Pooled estimation grid: occupied cells, and the cells hit exactly once and twice.
    pub occupied: u64,
    pub singles: u64,
    pub doubles: u64,
    /// Inner (eroded) and dilated occupancy of the pooled grid.
    pub inner: u64,
    pub dilated: u64,
    /// The closing of the pooled occupancy: its scan, its occupied cells of `2h`, and its
    /// cells that no sample hit.
    pub closed: crate::workspace::grid::Scan,
    pub closed_coarse: u64,
    pub closed_unhit: u64,
    /// Boundary cells of the closed occupancy (occupied, with an empty face neighbour)
    /// hit exactly once.
    pub edge_singles: u64,
    /// Each replicate's corrected measure of its closed occupancy, on its own grid.
    pub replicate_estimates: Vec<f64>,
}

/// Unhit fraction of the closed cells up to which the sliver tail is extrapolated.
pub(crate) const TAIL_UNHIT: f64 = 0.25;

/// Unhit fraction of the closed cells up to which a two-sided interval is given.
pub(crate) const INTERVAL_UNHIT: f64 = 0.05;

/// The interval's upper end allows this many times the extrapolated tail (a deficit
/// falling like `n^(−1/(2D))` instead of `n^(−1/D)`, roughly).
pub(crate) const TAIL_SPAN: f64 = 2.0;

/// Whether the interval is two-sided.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum IntervalKind {
    /// Coverage has converged: a 95 % interval.
    Interval,
    /// Too few samples: only a lower bound (the upper end is `null`).
    LowerBound,
}

/// The estimate of one stage.
#[derive(Clone, Debug, Serialize)]
pub struct Estimate {
    /// Total samples.
    pub samples: u64,
    /// The headline measure (m³, or m² when planar).
    pub measure: f64,
    /// Its noise scale: the standard deviation of the replicates' corrected measures.
    pub stderr: f64,
    /// 95 % interval `[lo, hi]`; `hi` is `None` (null) for a lower bound.
    pub interval: [Option<f64>; 2],
    /// Two-sided interval or lower bound.
    pub kind: IntervalKind,
    /// Pooled corrected measure `C_K` of the closed occupancy.
    pub corrected: f64,
    /// Pooled Richardson measure.
    pub richardson: f64,
    /// Fraction of the closed cells that no sample hit (filled by the closing).
    pub unhit_fraction: f64,
    /// Pooled raw occupancy `O c`.
    pub raw: f64,
    /// First-order voxel bias `E c / 2` of the closed occupancy.
    pub voxel_bias: f64,
    /// The slivers' measure still to come, the extrapolated tail `G` (`None` while the
    /// bulk is still filling).
    pub remaining: Option<f64>,
    /// Its bounds `[0, max(TAIL_SPAN G, D f₁ c)]` (`f₁` the boundary cells of the closed
    /// occupancy hit once).
    pub remaining_bounds: Option<[f64; 2]>,
    /// Cells hit exactly once and exactly twice (pooled grid).
    pub singles: u64,
    /// Cells hit exactly twice (pooled grid).
    pub doubles: u64,
    /// Inner cells × `c` and dilated occupancy × `c`: brackets under regularity (see the
    /// docs).
    pub inner: f64,
    /// Dilated occupancy × `c`: the upper bracket.
    pub outer: f64,
    /// Samples per occupied cell.
    pub samples_per_cell: f64,
    /// Samples a two-sided interval needs at least (when only a lower bound is given).
    pub samples_needed: Option<u64>,
}

impl Estimate {
    /// Half the interval's width relative to the headline (∞ for a lower bound).
    pub fn rel_half_width(&self) -> f64 {
        match self.interval {
            [Some(lo), Some(hi)] if self.measure > 0.0 => 0.5 * (hi - lo) / self.measure,
            _ => f64::INFINITY,
        }
    }
}

/// Student's t 97.5 % quantile for `dof` degrees of freedom.
pub(crate) fn t975(dof: usize) -> f64 {
    const T: [f64; 30] = [
        12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160,
        2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056,
        2.052, 2.048, 2.045, 2.042,
    ];
    match dof {
        0 => f64::INFINITY,
        d if d <= 30 => T[d - 1],
        _ => 1.96 + 2.4 / dof as f64,
    }
}

/// Mean and sample standard deviation of `x`.
pub(crate) fn mean_sd(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    if x.len() < 2 {
        return (mean, f64::NAN);
    }
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var.sqrt())
}

/// Corrected measure `c (O − E/2 + (1 + D) H)` of a scanned occupancy.
pub(crate) fn corrected_scan(s: &crate::workspace::grid::Scan, cm: f64, dims: i32) -> f64 {
    (s.occupied as f64 - 0.5 * s.exposed as f64 + (1 + dims) as f64 * s.holes as f64) * cm
}

/// Pooled corrected measure of a stage (of its closed occupancy).
pub(crate) fn corrected(s: &Stage, cm: f64, dims: i32) -> f64 {
    corrected_scan(&s.closed, cm, dims)
}

/// The growth of `series` (the corrected measure after each doubling) still to come:
/// the last increment continued geometrically with ratio `2^(−1/D)` (the slivers' law),
/// `ΔC ρ / (1 − ρ)`; 0 before two stages or when the last increment is not positive.
pub(crate) fn tail(series: &[f64], dims: i32) -> f64 {
    let k = series.len();
    if k < 2 {
        return 0.0;
    }
    let d = (series[k - 1] - series[k - 2]).max(0.0);
    let rho = 2f64.powf(-1.0 / dims as f64);
    d * rho / (1.0 - rho)
}

/// Samples that would bring the unhit fraction of the closed cells from `unhit` (at
/// `samples`) under [`INTERVAL_UNHIT`], reading it as the Poisson `e^(−λ)` of a cell's
/// hits, with a margin of half as many again for the non-uniform density: at least two
/// more doublings.
fn samples_needed(samples: u64, unhit: f64) -> u64 {
    let lambda = -unhit.clamp(1e-9, 0.999).ln();
    let target = -INTERVAL_UNHIT.ln();
    let need = 1.5 * samples as f64 * target / lambda;
    need.max(4.0 * samples as f64).ceil() as u64
}

/// The estimate after the last of `stages` (cell measure `cm`, dimension `dims`).
pub(crate) fn estimate(stages: &[Stage], cm: f64, dims: i32) -> Estimate {
    let last = stages.last().expect("at least one stage");
    let series: Vec<f64> = stages.iter().map(|s| corrected(s, cm, dims)).collect();
    let c = *series.last().expect("one stage");
    let raw = last.occupied as f64 * cm;
    let rich =
        2.0 * last.closed.occupied as f64 * cm - last.closed_coarse as f64 * cm * 2f64.powi(dims);
    let so = (c - rich).abs();
    let r = last.replicate_estimates.len();
    let (_, sd) = mean_sd(&last.replicate_estimates);
    // The pooled C is measured on one grid, like each replicate's: its lattice noise is
    // that of one replicate, so the replicates' spread is not divided by √R.
    let s = sd;
    let noise = t975(r.saturating_sub(1)) * s;
    let unhit = last.closed_unhit as f64 / last.closed.occupied.max(1) as f64;
    let per_cell = last.samples as f64 / last.occupied.max(1) as f64;
    let in_tail = unhit <= TAIL_UNHIT && stages.len() >= 3;
    let g = tail(&series, dims);
    let two_sided = in_tail && unhit <= INTERVAL_UNHIT && noise.is_finite();
    // The slivers still to come: the tail's span, or (Good–Turing) at most D cells per
    // boundary cell hit once (a sliver of depth δ holds ∝ δ^D of a cell: E f0 ≤ D E f1).
    let to_come = (TAIL_SPAN * g).max(dims as f64 * last.edge_singles as f64 * cm);
    let mut e = Estimate {
        samples: last.samples,
        measure: if in_tail { c + g } else { c },
        stderr: s,
        interval: [None, None],
        kind: IntervalKind::LowerBound,
        corrected: c,
        richardson: rich,
        unhit_fraction: unhit,
        raw,
        voxel_bias: 0.5 * last.closed.exposed as f64 * cm,
        remaining: in_tail.then_some(g),
        remaining_bounds: in_tail.then_some([0.0, to_come]),
        singles: last.singles,
        doubles: last.doubles,
        inner: last.inner as f64 * cm,
        outer: last.dilated as f64 * cm,
        samples_per_cell: per_cell,
        samples_needed: None,
    };
    let lower = c - noise - so;
    if two_sided {
        e.interval = [Some(lower), Some(c + to_come + noise + so)];
        e.kind = IntervalKind::Interval;
    } else {
        let lower = if lower.is_finite() { lower } else { e.inner }.max(0.0);
        e.interval = [Some(lower), None];
        // Never below the lower bound (nor 0: the staircase term of a sparse closed
        // occupancy can exceed its cells).
        e.measure = e.measure.max(lower);
        e.samples_needed = Some(samples_needed(last.samples, unhit));
    }
    e
}

#[cfg(test)]
mod tests {
    use crate::workspace::estimate::*;

    #[test]
    fn tail_extrapolation_and_quantiles() {
        // Last increment 1 continued with ρ = 2^(−1/3): ρ/(1 − ρ) = 3.847….
        let rho = 2f64.powf(-1.0 / 3.0);
        assert!((tail(&[0.0, 5.0, 6.0], 3) - rho / (1.0 - rho)).abs() < 1e-12);
        assert!((tail(&[0.0, 5.0, 6.0], 3) - 3.847_322).abs() < 1e-6);
        // In a plane ρ = 2^(−1/2): 1 + √2 = 2.414… per unit increment; here 2.
        assert!((tail(&[1.0, 3.0], 2) - 2.0 * (1.0 + 2f64.sqrt())).abs() < 1e-12);
        // Shrinking measures or a single stage: nothing to come.
        assert_eq!(tail(&[2.0, 1.0], 3), 0.0);
        assert_eq!(tail(&[2.0], 3), 0.0);
        // e^(−λ) = 0.9 (λ = 0.105): 0.05 needs λ = ln 20, 28.4 times as many samples, and
        // half as many again: 42 650 after 1000.
        let n = samples_needed(1000, 0.9) as f64;
        assert!(
            (n - 1500.0 * 20f64.ln() / (1.0 / 0.9f64).ln()).abs() <= 1.0,
            "{n}"
        );
        assert!((n - 42_650.0).abs() < 1.0, "{n}");
        // Close to the target: at least two more doublings.
        assert_eq!(samples_needed(1000, 0.06), 4000);
        assert_eq!(t975(7), 2.365);
        assert!(t975(0).is_infinite());
        let (m, sd) = mean_sd(&[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(m, 2.5);
        assert!((sd - (5.0f64 / 3.0).sqrt()).abs() < 1e-12);
    }
}
