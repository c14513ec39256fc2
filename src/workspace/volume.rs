//! The volume pass: `R` independent replicates of `n` joint-space samples each, forward
//! kinematics of the tool link only, occupancy bitsets per replicate; then the statistics
//! across replicates.
//!
//! Each replicate measures on its own grid, shifted by a uniform random offset in
//! `[0, 2h)` per axis: the expected occupancy over the offset is then exactly the measure
//! of `W ⊕ cell`, and the luck of the lattice position enters the replicate spread
//! instead of a hidden bias. Every sample also marks the common, unshifted grid that
//! pools all replicates (boundary voxels, per-voxel statistics, CSV).
//!
//! Per replicate `r` and checkpoint `n_k = 2^k` (cell measure `c = h³`, or `h²` for a
//! planar workspace):
//! - the raw estimate `M_r`: occupied cells × `c`;
//! - the first-order voxel bias `B_r = E_r c / 2`, `E_r` the exposed faces (edges) of the
//!   occupied set — see `docs/workspace.md`: at full coverage the occupied cells are those
//!   that meet the workspace `W`, whose measure is `|W ⊕ cell| ≈ |W| + (h/2) ∮ ‖n‖₁ dS`,
//!   and the staircase surface `E h^(D−1)` estimates `∮ ‖n‖₁ dS`;
//! - the bias-corrected estimate `M_r − B_r`;
//! - the Richardson estimate `2 M_r(h) − M_r(2h)` (the same samples on cells of `2h`).
//!
//! Each estimate is reported as the mean over replicates with standard error `sd / √R`:
//! the replicates are independent and identically distributed, so that error bar is exact
//! for the estimator at `n` samples per replicate (its remaining *bias* is reported apart).

use super::grid::{Grid, Scan};
use super::sampler::{derive_seed, JointBox, QStream, RandomStream, SobolStream};
use super::Sampling;
use crate::data::Data;
use crate::kinematics::{forward_kinematics, frame_placement};
use crate::model::Model;
use crate::spatial::Vec3;
use indicatif::ProgressBar;
use rayon::prelude::*;

/// Samples between progress-bar updates.
const PROGRESS_BLOCK: u64 = 1 << 16;

/// What the passes share.
pub(crate) struct Ctx<'a> {
    pub model: &'a Model,
    pub tool: usize,
    pub jb: JointBox,
    /// The common (unshifted) grid of the pooled occupancy.
    pub grid: Grid,
    pub sampling: Sampling,
    pub seed: u64,
    /// Whether each replicate measures on a randomly shifted grid.
    pub shift: bool,
    /// Centre and radius of the reach bound.
    pub center: Vec3,
    pub radius: f64,
}

/// Counts at one checkpoint of one replicate.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Check {
    /// Scan of the replicate's occupancy.
    pub scan: Scan,
    /// Occupied cells of `2h`.
    pub coarse: u64,
}

/// One replicate's results.
#[derive(Clone, Debug)]
pub(crate) struct Replicate {
    pub index: usize,
    /// Counts at each checkpoint.
    pub checks: Vec<Check>,
    pub lo: Vec3,
    pub hi: Vec3,
    pub outside: u64,
    pub max_off_plane: f64,
}

impl Replicate {
    /// Counts after all samples.
    pub fn last(&self) -> &Check {
        self.checks.last().expect("at least one checkpoint")
    }
}

/// The grid replicate `r` measures on: shifted by a uniform offset in `[0, 2h)` per axis
/// drawn from `(seed, r)`, or the common grid.
pub(crate) fn replicate_grid(ctx: &Ctx, r: usize) -> Grid {
    if !ctx.shift {
        return ctx.grid.clone();
    }
    let h = ctx.grid.h;
    let shift = [0u64, 1, 2].map(|k| {
        let x = derive_seed(ctx.seed, r as u64, 7000 + k);
        2.0 * h * ((x >> 11) as f64 * (1.0 / 9_007_199_254_740_992.0))
    });
    Grid::new(h, &ctx.center, ctx.radius, ctx.grid.plane, shift)
        .expect("a shifted grid is no larger than the common one, give or take two cells")
}

/// Runs replicate `index`'s stream through forward kinematics: the replicate's own
/// occupancy (on its grid and on the grid of `2h`) and the common-grid occupancy that
/// is pooled across replicates.
fn run_stream<S: QStream>(
    ctx: &Ctx,
    mut stream: S,
    index: usize,
    checkpoints: &[u64],
    pb: &ProgressBar,
) -> (Replicate, Vec<u64>) {
    let model = ctx.model;
    let common = &ctx.grid;
    let grid = replicate_grid(ctx, index);
    let coarse = grid.coarse();
    let mut data = Data::new(model);
    let mut q = vec![0.0; model.nv];
    let mut bits = grid.empty();
    let mut coarse_bits = coarse.empty();
    let mut pooled = common.empty();
    let mut checks = Vec::with_capacity(checkpoints.len());
    let (mut coarse_count, mut outside, mut max_off) = (0u64, 0u64, 0.0f64);
    let mut lo = Vec3::repeat(f64::INFINITY);
    let mut hi = Vec3::repeat(f64::NEG_INFINITY);
    let mut done = 0u64;
    for &cp in checkpoints {
        while done < cp {
            let end = cp.min((done / PROGRESS_BLOCK + 1) * PROGRESS_BLOCK);
            for _ in done..end {
                stream.next_q(&ctx.jb, &mut q);
                forward_kinematics(model, &mut data, &q);
                let p = frame_placement(model, &data, ctx.tool).trans;
                lo = lo.inf(&p);
                hi = hi.sup(&p);
                let (c, d) = grid.coords(&p);
                max_off = max_off.max(d.abs());
                match common.locate(&c) {
                    Some(i) => {
                        Grid::set(&mut pooled, i);
                    }
                    None => outside += 1,
                }
                if let Some(l) = grid.locate_local(&c) {
                    Grid::set(&mut bits, grid.index(l));
                    coarse_count += Grid::set(
                        &mut coarse_bits,
                        coarse.index([l[0] / 2, l[1] / 2, l[2] / 2]),
                    ) as u64;
                }
            }
            pb.inc(end - done);
            done = end;
        }
        checks.push(Check {
            scan: grid.scan(&bits),
            coarse: coarse_count,
        });
    }
    (
        Replicate {
            index,
            checks,
            lo,
            hi,
            outside,
            max_off_plane: max_off,
        },
        pooled,
    )
}

/// Replicate `r` from sample 0 to the last checkpoint.
fn run_replicate(
    ctx: &Ctx,
    r: usize,
    checkpoints: &[u64],
    pb: &ProgressBar,
) -> (Replicate, Vec<u64>) {
    let d = ctx.model.nv;
    match ctx.sampling {
        Sampling::Random => {
            let s = RandomStream::new(ctx.seed, r as u64, d, 0);
            run_stream(ctx, s, r, checkpoints, pb)
        }
        Sampling::Sobol => {
            let s = SobolStream::new(ctx.seed, r as u64, d, 0);
            run_stream(ctx, s, r, checkpoints, pb)
        }
    }
}

/// Runs every replicate (rayon, one task per replicate, each with its own `Data` and
/// bitset). Returns the replicates in order and the union of their occupancies.
pub(crate) fn run(
    ctx: &Ctx,
    replicates: usize,
    checkpoints: &[u64],
    pb: &ProgressBar,
) -> (Vec<Replicate>, Vec<u64>) {
    let (mut reps, union) = (0..replicates)
        .into_par_iter()
        .map(|r| {
            let (rep, bits) = run_replicate(ctx, r, checkpoints, pb);
            (vec![rep], Some(bits))
        })
        .reduce(
            || (Vec::new(), None),
            |(mut a, ab), (b, bb)| {
                a.extend(b);
                let u = match (ab, bb) {
                    (Some(mut x), Some(y)) => {
                        for (x, y) in x.iter_mut().zip(&y) {
                            *x |= y;
                        }
                        Some(x)
                    }
                    (x, None) => x,
                    (None, y) => y,
                };
                (a, u)
            },
        );
    reps.sort_by_key(|r| r.index);
    (reps, union.unwrap_or_else(|| ctx.grid.empty()))
}

/// Mean and standard error (`sd / √n`, sample sd) of `x`.
pub(crate) fn mean_stderr(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    if x.len() < 2 {
        return (mean, f64::NAN);
    }
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Estimate of the growth still to come from the last three points of a series sampled
/// at doubling sample counts, `Δ₂ ρ / (1 − ρ)`: the increments `Δ₁, Δ₂` of the last two
/// doublings continued geometrically with ratio `ρ = max(Δ₂ / Δ₁, 2^(−1/D))`.
///
/// The floor is the corner-sliver law: a cell that meets the workspace only in a corner
/// of depth `δ` holds a measure `∝ δ^D` of it, `δ` is uniform over such cells, so with a
/// sample density bounded below the cells still missed after `n` samples decay like
/// `n^(−1/D)` — more slowly than the bulk, which fills exponentially fast and would
/// otherwise make the last ratio look small. `None` when the increments are not
/// shrinking (coverage far from converged) — unless the last one is below `noise` (the
/// standard error of the last point), where the ratio means nothing and the floor is used.
pub(crate) fn remaining_growth(series: &[f64], dims: i32, noise: f64) -> Option<f64> {
    let k = series.len();
    if k < 3 {
        return None;
    }
    let d1 = series[k - 2] - series[k - 3];
    let d2 = (series[k - 1] - series[k - 2]).max(0.0);
    if d2 == 0.0 {
        return Some(0.0);
    }
    let floor = 2f64.powf(-1.0 / dims as f64);
    let rho = if d1 > d2 {
        (d2 / d1).max(floor)
    } else if d2 <= noise {
        floor
    } else {
        return None;
    };
    Some(d2 * rho / (1.0 - rho))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tail_extrapolation() {
        // Increments halving: ρ = 1/2 is below the 2-D floor 2^(−1/2), which is used.
        let r = remaining_growth(&[0.0, 4.0, 6.0], 2, 0.0).expect("shrinking");
        let rho = 0.5f64.sqrt();
        assert!((r - 2.0 * rho / (1.0 - rho)).abs() < 1e-12);
        // Increments shrinking slowly: the measured ratio is used.
        let r = remaining_growth(&[0.0, 1.0, 1.9], 3, 0.0).expect("shrinking");
        assert!((r - 0.9 * 0.9 / 0.1).abs() < 1e-9);
        // Growing: not converged, unless the last step is noise.
        assert_eq!(remaining_growth(&[0.0, 1.0, 3.0], 3, 0.5), None);
        assert!(remaining_growth(&[0.0, 0.1, 0.3], 3, 0.5).is_some());
        assert_eq!(remaining_growth(&[0.0, 1.0, 1.0], 3, 0.0), Some(0.0));
        assert_eq!(remaining_growth(&[1.0, 2.0], 3, 0.0), None);
        let (m, se) = mean_stderr(&[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(m, 2.5);
        assert!((se - (5.0f64 / 12.0).sqrt() / 1.0).abs() < 1e-12);
    }
}
