//! The volume pass: `R` independent replicates, advanced together one doubling of the
//! sample budget at a time (a *stage*) by the hot loop of [`crate::workspace::volume_kernel`]
//! (eight configurations at a time in `f64` SIMD lanes); after each stage the counts that
//! [`crate::workspace::estimate`] needs.
//!
//! Every sample marks three grids:
//! - its replicate's own grid, shifted by a uniform random offset in `[0, 2h)` per axis
//!   drawn from `(seed, r)`: the replicates' corrected measures are independent, lattice
//!   position included, and their spread is the noise scale of the estimate;
//! - the pooled *estimation* grid, shifted by an offset drawn from the seed: all samples of
//!   all replicates, for the headline (a fixed, unshifted grid would carry a repeatable
//!   lattice bias: −31 pixels on the 2R disc at 2 cm);
//! - the common grid anchored at the origin, which pools all samples for the outputs
//!   (boundary voxels, per-voxel statistics, CSV), unchanged from before.
//!
//! Replicate `r`'s stream starts where the previous stage left it, so stage `k` uses
//! exactly the first `2^k` samples of every stream: the result depends on the seed only,
//! not on the thread count or on how the budget was reached (fixed or adaptive).

use crate::workspace::estimate::Stage;
use crate::workspace::grid::{Grid, Hits};
use crate::workspace::volume_context::Ctx;
use crate::workspace::volume_kernel::Replicate;
use indicatif::ProgressBar;
use rayon::prelude::*;

/// The estimate of one replicate on its own grid: the corrected measure of its closed
/// occupancy (see [`crate::workspace::estimate`]).
fn replicate_estimate(grid: &Grid, hits: &Hits) -> f64 {
    let s = grid.scan(&hits.closed_occupancy(grid));
    crate::workspace::estimate::corrected_scan(&s, grid.cell_measure(), grid.dims())
}

/// Advances every replicate to `per_replicate` samples (rayon, one task per replicate)
/// and returns the stage's counts.
pub(crate) fn run_stage(
    ctx: &Ctx,
    reps: &mut [Replicate],
    per_replicate: u64,
    pb: &ProgressBar,
) -> Stage {
    let replicate_estimates: Vec<f64> = reps
        .par_iter_mut()
        .map(|rep| {
            crate::workspace::volume_kernel::advance(rep, ctx, per_replicate, pb);
            replicate_estimate(&rep.marks.grid, &rep.marks.counts.hits())
        })
        .collect();
    let mut pooled = Hits::new(&ctx.est);
    for r in reps.iter() {
        pooled.add(&r.marks.est_counts.hits());
    }
    let union = pooled.occupied();
    let (singles, doubles) = pooled.singles_doubles();
    let closed_bits = pooled.closed_occupancy(&ctx.est);
    Stage {
        samples: per_replicate * reps.len() as u64,
        occupied: crate::workspace::grid::count_bits(union),
        singles,
        doubles,
        inner: ctx.est.morph_count(union, true),
        dilated: ctx.est.morph_count(union, false),
        closed: ctx.est.scan(&closed_bits),
        closed_coarse: ctx.est.coarse_count(&closed_bits),
        closed_unhit: pooled.counts_in(&closed_bits)[0],
        edge_singles: pooled.counts_in(&ctx.est.boundary_bits(&closed_bits))[1],
        replicate_estimates,
    }
}

/// Word-wise union of bitsets of `words` words.
fn union_of<'a>(sets: impl Iterator<Item = &'a [u64]>, words: usize) -> Vec<u64> {
    let mut u = vec![0u64; words];
    for s in sets {
        for (x, y) in u.iter_mut().zip(s) {
            *x |= y;
        }
    }
    u
}

/// The union of every replicate's samples on the common grid.
pub(crate) fn common_union(ctx: &Ctx, reps: &[Replicate]) -> Vec<u64> {
    union_of(
        reps.iter().map(|r| &r.marks.common_bits[..]),
        ctx.grid.words(),
    )
}
