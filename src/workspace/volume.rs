//! The volume pass: `R` independent replicates, advanced together one doubling of the
//! sample budget at a time (a *stage*); forward kinematics of the tool origin eight
//! configurations at a time ([`ToolChain::positions`], `f64` SIMD lanes); occupancy
//! bitsets. After each stage the counts that [`super::estimate`] needs.
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

use super::estimate::Stage;
use super::grid::{Grid, Hits};
use super::sampler::{derive_seed, JointBox, QStream, RandomStream, SobolStream};
use super::Sampling;
use crate::data::Data;
use crate::kinematics::batch::{lanes_in_range, Lanes, ToolChain, LANES};
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

/// A replicate's stream.
enum Stream {
    Random(RandomStream),
    Sobol(SobolStream),
}

impl QStream for Stream {
    #[inline(always)]
    fn next_q(&mut self, b: &JointBox, q: &mut [f64]) {
        match self {
            Stream::Random(s) => s.next_q(b, q),
            Stream::Sobol(s) => s.next_q(b, q),
        }
    }
}

/// One replicate between stages.
pub(crate) struct Replicate {
    stream: Stream,
    /// Samples drawn so far.
    done: u64,
    /// Its own shifted grid and hit counts.
    grid: Grid,
    hits: Hits,
    /// Its hits on the pooled estimation grid, and its samples on the common grid.
    est_hits: Hits,
    common_bits: Vec<u64>,
    pub lo: Vec3,
    pub hi: Vec3,
    pub outside: u64,
    pub max_off_plane: f64,
}

impl Replicate {
    /// Replicate `r` of `ctx`, before its first sample.
    pub fn new(ctx: &Ctx, r: usize) -> Self {
        let d = ctx.model.nv;
        let stream = match ctx.sampling {
            Sampling::Random => Stream::Random(RandomStream::new(ctx.seed, r as u64, d, 0)),
            Sampling::Sobol => Stream::Sobol(SobolStream::new(ctx.seed, r as u64, d, 0)),
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
            hits: Hits::new(&grid),
            grid,
            est_hits: Hits::new(&ctx.est),
            common_bits: ctx.grid.empty(),
            lo: Vec3::repeat(f64::INFINITY),
            hi: Vec3::repeat(f64::NEG_INFINITY),
            outside: 0,
            max_off_plane: 0.0,
        }
    }

    /// Marks tool point `p` on the three grids.
    #[inline(always)]
    fn mark(&mut self, ctx: &Ctx, p: &Vec3) {
        self.lo = self.lo.inf(p);
        self.hi = self.hi.sup(p);
        let (c, d) = ctx.grid.coords(p);
        self.max_off_plane = self.max_off_plane.max(d.abs());
        match ctx.grid.locate(&c) {
            Some(i) => {
                Grid::set(&mut self.common_bits, i);
            }
            None => self.outside += 1,
        }
        if let Some(i) = ctx.est.locate(&c) {
            self.est_hits.hit(i);
        }
        if let Some(i) = self.grid.locate(&c) {
            self.hits.hit(i);
        }
    }

    /// Draws samples until `to`, eight at a time.
    #[allow(clippy::needless_range_loop)] // lanes index the configuration and output arrays
    fn advance(&mut self, ctx: &Ctx, to: u64, pb: &ProgressBar) {
        let model = ctx.model;
        let nq = model.nv;
        let mut q = vec![[0.0; LANES]; nq];
        let mut row = vec![0.0; nq];
        let mut out: [Lanes; 3] = [[0.0; LANES]; 3];
        let mut data: Option<Data> = None;
        let mut since = 0u64;
        while self.done < to {
            let m = (to - self.done).min(LANES as u64) as usize;
            for l in 0..LANES {
                if l < m {
                    self.stream.next_q(&ctx.jb, &mut row);
                }
                // Spare lanes repeat the last configuration; their results are dropped.
                for (k, v) in row.iter().enumerate() {
                    q[k][l] = *v;
                }
            }
            if ctx.batched && lanes_in_range(&q) {
                ctx.chain.positions(&q, &mut out);
            } else {
                let data = data.get_or_insert_with(|| Data::new(model));
                for l in 0..m {
                    for (k, v) in row.iter_mut().enumerate() {
                        *v = q[k][l];
                    }
                    forward_kinematics(model, data, &row);
                    let p = frame_placement(model, data, ctx.tool).trans;
                    for a in 0..3 {
                        out[a][l] = p[a];
                    }
                }
            }
            for l in 0..m {
                self.mark(ctx, &Vec3::new(out[0][l], out[1][l], out[2][l]));
            }
            self.done += m as u64;
            since += m as u64;
            if since >= PROGRESS_BLOCK {
                pb.inc(since);
                since = 0;
            }
        }
        pb.inc(since);
    }
}

/// The estimate of one replicate on its own grid: the corrected measure of its closed
/// occupancy (see [`super::estimate`]).
fn replicate_estimate(grid: &Grid, hits: &Hits) -> f64 {
    let s = grid.scan(&hits.closed_occupancy(grid));
    super::estimate::corrected_scan(&s, grid.cell_measure(), grid.dims())
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
            rep.advance(ctx, per_replicate, pb);
            replicate_estimate(&rep.grid, &rep.hits)
        })
        .collect();
    let mut pooled = Hits::new(&ctx.est);
    for r in reps.iter() {
        pooled.add(&r.est_hits);
    }
    let union = pooled.occupied();
    let (singles, doubles) = pooled.singles_doubles();
    let closed_bits = pooled.closed_occupancy(&ctx.est);
    Stage {
        samples: per_replicate * reps.len() as u64,
        occupied: super::grid::count_bits(union),
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
    union_of(reps.iter().map(|r| &r.common_bits[..]), ctx.grid.words())
}
