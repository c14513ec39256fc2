//! The estimator and its interval, from the counts of the volume pass at each doubling
//! of the sample budget (see `docs/workspace.md`, "The estimate and its interval").
//!
//! At every stage `k` (all samples so far, `N_k = R · 2^k`):
//! - the **pooled corrected measure** `C_k = c · (O − E/2 + (1 + D) H)` on the pooled
//!   estimation grid (all samples, one grid shifted by a seeded random offset): `O`
//!   occupied cells, `E` exposed faces (the first-order voxel bias is `E c / 2`), `H`
//!   isolated holes (empty cells whose face neighbours are all occupied, counted as
//!   filled: a hole costs `1 + D` cells of `C` — itself and `2D` exposed faces);
//! - the same on each replicate's own grid (its own samples, its own random shift): their
//!   spread `s_R` is the noise scale of `C_k`, lattice position included;
//! - Richardson's `2 O(h) − O(2h)` on the pooled grid: `|C − richardson|` is the scale of
//!   what the first-order correction leaves (plus under-sampling while it lasts);
//! - the inner cells (occupied with all `3^D − 1` neighbours occupied) and the dilated
//!   occupancy: a lower and an upper bracket.
//!
//! The under-sampling left at stage `K` is the boundary layer's unseen cells: cells that
//! the workspace meets in a sliver, which samples rarely hit. Their number follows from
//! the cells hit once and twice ([`unseen`], a Good–Turing / capture–recapture argument):
//! at most `D f1` under independent sampling with a density bounded away from zero at the
//! boundary, centrally `f1/α̂`; no useful lower bound (stratified Sobol' points, or a
//! density that grows towards a fold of the workspace, leave fewer unseen cells than
//! independent points would). Each unseen cell adds one cell to `C` when found. The
//! headline is `V = C_K + c f1/α̂`; the interval
//! `[C_K − t s − so, C_K + c D f1 + t s + so]`, with `s` the standard deviation of
//! the replicates' own `V_r` and `t` Student's 97.5 % quantile for `R − 1` degrees of
//! freedom (the pooled `V` is one grid, like each `V_r`, with more samples: `s` bounds
//! its noise), `so = |C − richardson|`. While coverage has not converged (the doubling
//! increments of `C` not shrinking by [`MAX_RATIO`], or fewer than [`MIN_PER_CELL`]
//! samples per occupied cell) only a lower bound is given, with the samples that would
//! be needed.

use serde::Serialize;

/// Samples per occupied cell below which no two-sided interval is given.
pub(crate) const MIN_PER_CELL: f64 = 8.0;

/// Increments must shrink at least by this ratio per doubling for convergence.
const MAX_RATIO: f64 = 0.9;

/// Counts of one stage.
#[derive(Clone, Debug)]
pub(crate) struct Stage {
    /// Total samples so far.
    pub samples: u64,
    /// Pooled estimation grid: occupied, exposed faces, isolated holes, inner and dilated
    /// cells, occupied cells of `2h`.
    pub occupied: u64,
    pub exposed: u64,
    pub holes: u64,
    pub inner: u64,
    pub dilated: u64,
    pub coarse: u64,
    /// Cells of the pooled grid hit exactly once and exactly twice.
    pub singles: u64,
    pub doubles: u64,
    /// Each replicate's estimate (corrected measure plus unseen cells) on its own grid.
    pub replicate_estimates: Vec<f64>,
}

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
    /// Pooled corrected measure `C_K`.
    pub corrected: f64,
    /// Pooled Richardson measure.
    pub richardson: f64,
    /// Pooled raw occupancy `O c`.
    pub raw: f64,
    /// First-order voxel bias `E c / 2` of the pooled grid.
    pub voxel_bias: f64,
    /// The unseen cells' measure still to come, central estimate (`None` while coverage
    /// has not converged).
    pub remaining: Option<f64>,
    /// Its bounds `[0, D f₁ c]` (net of the isolated holes already filled).
    pub remaining_bounds: Option<[f64; 2]>,
    /// Cells hit exactly once and exactly twice (pooled grid).
    pub singles: u64,
    pub doubles: u64,
    /// Inner cells × `c` and dilated occupancy × `c`: brackets under regularity (see the
    /// docs).
    pub inner: f64,
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

/// Pooled corrected measure of a stage.
pub(crate) fn corrected(s: &Stage, cm: f64, dims: i32) -> f64 {
    (s.occupied as f64 - 0.5 * s.exposed as f64 + (1 + dims) as f64 * s.holes as f64) * cm
}

/// Remaining growth after the last of `series` (see the module docs): `None` when the
/// increments are not shrinking by [`MAX_RATIO`] per doubling — unless the last one is
/// within `noise` (the noise scale of one value), where the measured ratio means nothing
/// and the corner-law floor is used.
pub(crate) fn remaining_growth(series: &[f64], dims: i32, noise: f64) -> Option<f64> {
    let k = series.len();
    if k < 3 {
        return None;
    }
    let d1 = series[k - 2] - series[k - 3];
    let d2 = series[k - 1] - series[k - 2];
    let scale = series[k - 1].abs().max(f64::MIN_POSITIVE);
    if d2 <= 1e-9 * scale {
        return Some(0.0);
    }
    let floor = 2f64.powf(-1.0 / dims as f64);
    let rho = if d1 > 0.0 && d2 <= MAX_RATIO * d1 {
        (d2 / d1).max(floor)
    } else if d2 <= noise {
        floor
    } else {
        return None;
    };
    Some(d2 * rho / (1.0 - rho))
}

/// Unseen cells of the workspace's boundary layer, from the cells hit once (`f1`) and
/// twice (`f2`), net of the `holes` already counted as filled: `(low, central, high)`.
///
/// Cells cut by the boundary hold a fraction `φ` of a cell of the workspace; near
/// `φ = 0` its distribution follows `P(φ < ε) ∝ ε^α`, with `α = 1/D` for cells cut near a
/// corner, `1/2` near an edge, `1` across a face. With `λ ∝ φ` the expected hits, the
/// counts are Poisson mixtures and `E f0 / E f1 = Γ(α)/Γ(1 + α) = 1/α`,
/// `E f2 / E f1 = (1 + α)/2`: the unseen cells number between `f1` (`α = 1`) and `D f1`
/// (`α = 1/D`), centrally `f1/α̂` with `α̂ = 2 f2/f1 − 1` clamped to `[1/D, 1]`. (The
/// caller uses 0, not `f1`, as the low end: see the module docs.)
pub(crate) fn unseen(f1: u64, f2: u64, holes: u64, dims: i32) -> (f64, f64, f64) {
    let d = dims as f64;
    let (f1, f2, h) = (f1 as f64, f2 as f64, holes as f64);
    let alpha = if f1 > 0.0 {
        (2.0 * f2 / f1 - 1.0).clamp(1.0 / d, 1.0)
    } else {
        1.0
    };
    let net = |x: f64| (x - h).max(0.0);
    (net(f1), net(f1 / alpha), net(d * f1))
}

/// The estimate after the last of `stages` (cell measure `cm`, dimension `dims`).
pub(crate) fn estimate(stages: &[Stage], cm: f64, dims: i32) -> Estimate {
    let last = stages.last().expect("at least one stage");
    let series: Vec<f64> = stages.iter().map(|s| corrected(s, cm, dims)).collect();
    let c = *series.last().expect("one stage");
    let raw = last.occupied as f64 * cm;
    let rich = 2.0 * raw - last.coarse as f64 * cm * 2f64.powi(dims);
    let so = (c - rich).abs();
    let (_, sd) = mean_sd(&last.replicate_estimates);
    let r = last.replicate_estimates.len();
    let noise = t975(r.saturating_sub(1)) * sd;
    let per_cell = last.samples as f64 / last.occupied.max(1) as f64;
    let inner = last.inner as f64 * cm;
    let outer = last.dilated as f64 * cm;
    let converged = remaining_growth(&series, dims, sd).is_some() && per_cell >= MIN_PER_CELL;
    let (_, t_mid, t_hi) = unseen(last.singles, last.doubles, last.holes, dims);
    let remaining = converged.then_some(t_mid * cm);
    let mut e = Estimate {
        samples: last.samples,
        measure: c,
        stderr: sd,
        interval: [None, None],
        kind: IntervalKind::LowerBound,
        corrected: c,
        richardson: rich,
        raw,
        voxel_bias: 0.5 * last.exposed as f64 * cm,
        remaining,
        remaining_bounds: converged.then_some([0.0, t_hi * cm]),
        singles: last.singles,
        doubles: last.doubles,
        inner,
        outer,
        samples_per_cell: per_cell,
        samples_needed: None,
    };
    match remaining {
        Some(g) if noise.is_finite() => {
            e.measure = c + g;
            e.interval = [Some(c - noise - so), Some(c + t_hi * cm + noise + so)];
            e.kind = IntervalKind::Interval;
        }
        _ => {
            let lower = inner.max(if noise.is_finite() {
                c - noise - so
            } else {
                f64::NEG_INFINITY
            });
            e.measure = c.max(lower);
            e.interval = [Some(lower.max(0.0)), None];
            // At least MIN_PER_CELL samples per cell of the largest plausible set (the
            // dilated occupancy), and two more doublings than now.
            let cells = (outer / cm).max(last.occupied as f64);
            let need = (MIN_PER_CELL * 2.0 * cells).max(4.0 * last.samples as f64);
            e.samples_needed = Some(need.ceil() as u64);
        }
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tail_extrapolation_and_quantiles() {
        // Increments halving: ρ = 1/2 is below the 2-D floor 2^(−1/2), which is used.
        let r = remaining_growth(&[0.0, 4.0, 6.0], 2, 0.0).expect("shrinking");
        let rho = 0.5f64.sqrt();
        assert!((r - 2.0 * rho / (1.0 - rho)).abs() < 1e-12);
        // Shrinking more slowly than the floor: the measured ratio 0.85.
        let r = remaining_growth(&[0.0, 1.0, 1.85], 3, 0.0).expect("shrinking");
        assert!((r - 0.85 * 0.85 / 0.15).abs() < 1e-9);
        // Not shrinking enough, or growing: not converged, unless the step is noise.
        assert_eq!(remaining_growth(&[0.0, 1.0, 1.95], 3, 0.5), None);
        assert_eq!(remaining_growth(&[0.0, 1.0, 3.0], 3, 0.5), None);
        let floor = 2f64.powf(-1.0 / 3.0);
        let r = remaining_growth(&[0.0, -0.1, 0.2], 3, 0.5).expect("noise");
        assert!((r - 0.3 * floor / (1.0 - floor)).abs() < 1e-12);
        assert_eq!(remaining_growth(&[0.0, 1.0, 1.0], 3, 0.0), Some(0.0));
        assert_eq!(remaining_growth(&[1.0, 2.0], 3, 0.0), None);
        // Pure corner slivers in 3-D (α = 1/3: f2/f1 = 2/3): 3 f1 unseen, bounds f1 and 3 f1;
        // the holes already filled come off.
        assert_eq!(unseen(300, 200, 0, 3), (300.0, 900.0, 900.0));
        assert_eq!(unseen(300, 300, 100, 3), (200.0, 200.0, 800.0));
        assert_eq!(unseen(0, 0, 0, 2), (0.0, 0.0, 0.0));
        assert_eq!(t975(7), 2.365);
        assert!(t975(0).is_infinite());
        let (m, sd) = mean_sd(&[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(m, 2.5);
        assert!((sd - (5.0f64 / 3.0).sqrt()).abs() < 1e-12);
    }
}
