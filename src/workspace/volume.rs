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

use crate::core::spatial::Vec3;
use crate::kinematics::fk_lanes::{Isa, ToolChain};
use crate::model::Model;
use crate::workspace::estimate::Stage;
use crate::workspace::grid::{Grid, Hits};
use crate::workspace::sample_stream::{derive_seed, JointBox, RandomStream, SobolStream};
use crate::workspace::volume_kernel::Marks;
use crate::workspace::Sampling;
use indicatif::ProgressBar;
use rayon::prelude::*;

/// What the passes share.
pub(crate) struct Ctx<'a> {
    pub model: &'a Model,
    pub tool: usize,
    pub jb: JointBox,
    /// The common (unshifted) grid of the outputs.
    pub grid: Grid,
    /// The pooled estimation grid (shifted by an offset drawn from the seed).
    pub est: Grid,
    pub sampling: Sampling,
    pub seed: u64,
    /// Whether the replicate and estimation grids are randomly shifted.
    pub shift: bool,
    /// Centre and radius of the reach bound.
    pub center: Vec3,
    pub radius: f64,
    /// Batched FK of the tool origin.
    pub chain: ToolChain,
    /// Whether to use it (otherwise the scalar FK, one configuration at a time).
    pub batched: bool,
    /// The instruction set of the hot loop ([`crate::workspace::volume_kernel`]).
    pub isa: Isa,
}

/// A grid like `ctx.grid`, shifted by a uniform offset in `[0, 2h)` per axis drawn from
/// `(seed, stream)` (or unshifted when shifts are off).
pub(crate) fn shifted_grid(
    grid: &Grid,
    center: &Vec3,
    radius: f64,
    seed: u64,
    stream: u64,
    shift: bool,
) -> Grid {
    if !shift {
        return grid.clone();
    }
    let h = grid.h;
    let s = [0u64, 1, 2].map(|k| {
        let x = derive_seed(seed, stream, 7000 + k);
        2.0 * h * ((x >> 11) as f64 * (1.0 / 9_007_199_254_740_992.0))
    });
    Grid::new(h, center, radius, grid.plane, s)
        .expect("a shifted grid is no larger than the common one, give or take two cells")
}

/// A replicate's stream (the Sobol' one, 5 KiB of direction numbers, boxed).
pub(super) enum Stream {
    Random(RandomStream),
    Sobol(Box<SobolStream>),
}

/// One replicate between stages.
pub(crate) struct Replicate {
    pub(super) stream: Stream,
    /// Samples drawn so far.
    pub(super) done: u64,
    pub marks: Marks,
}

impl Replicate {
    /// Replicate `r` of `ctx`, before its first sample.
    pub fn new(ctx: &Ctx, r: usize) -> Self {
        let d = ctx.model.nv;
        let stream = match ctx.sampling {
            Sampling::Random => Stream::Random(RandomStream::new(ctx.seed, r as u64, d, 0)),
            Sampling::Sobol => Stream::Sobol(Box::new(SobolStream::new(ctx.seed, r as u64, d, 0))),
        };
        let grid = shifted_grid(
            &ctx.grid,
            &ctx.center,
            ctx.radius,
            ctx.seed,
            r as u64,
            ctx.shift,
        );
        Replicate {
            stream,
            done: 0,
            marks: Marks::new(grid, &ctx.est, &ctx.grid),
        }
    }
}

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
