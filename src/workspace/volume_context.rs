//! What the volume and Jacobian passes share ([`Ctx`]: the model, the tool, the sampling
//! box, the grids and the FK), and the randomly shifted grids of the replicates
//! ([`shifted_grid`]).

use crate::core::spatial::Vec3;
use crate::kinematics::fk_lanes::{Isa, ToolChain};
use crate::model::Model;
use crate::workspace::grid::Grid;
use crate::workspace::sample_stream::{derive_seed, JointBox};
use crate::workspace::workspace_options::Sampling;

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
    /// The caller's stop flag ([`crate::workspace::WorkspaceOptions::stop`]).
    pub stop: Option<&'a std::sync::atomic::AtomicBool>,
}

impl Ctx<'_> {
    /// Whether the caller asked the run to stop.
    pub fn stopped(&self) -> bool {
        self.stop
            .is_some_and(|s| s.load(std::sync::atomic::Ordering::Relaxed))
    }
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
