//! How [`sample_workspace`](super::sample_workspace) is asked to run: the sampling
//! scheme ([`Sampling`], [`UnknownSampling`] for a name that is none) and the options
//! ([`WorkspaceOptions`]).

use crate::kinematics::fk_lanes::Isa;
use serde::Serialize;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// How joint space is sampled.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Sampling {
    /// Independent uniform samples (counter-mode SplitMix64).
    Random,
    /// Owen-scrambled Sobol' (randomised quasi-Monte Carlo), at most 31 coordinates.
    Sobol,
}

/// A sampling scheme name that is neither `random` nor `sobol`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown sampling '{0}': expected random or sobol")]
pub struct UnknownSampling(pub String);

impl std::str::FromStr for Sampling {
    type Err = UnknownSampling;
    fn from_str(s: &str) -> Result<Self, UnknownSampling> {
        match s {
            "random" => Ok(Sampling::Random),
            "sobol" => Ok(Sampling::Sobol),
            _ => Err(UnknownSampling(s.to_string())),
        }
    }
}

/// Options of [`sample_workspace`](super::sample_workspace).
#[derive(Clone, Debug)]
pub struct WorkspaceOptions {
    /// Total samples of the volume pass, split into `replicates` streams of a power of two
    /// each (the count per replicate is rounded to the nearest power of two). In
    /// adaptive mode, the first budget tried.
    pub samples: u64,
    /// Adaptive mode: keep doubling the samples until the interval's half-width is at
    /// most this fraction of the estimate (or `max_samples` is reached).
    pub target_rel_error: Option<f64>,
    /// Adaptive mode: the most samples to draw (default `2^30`).
    pub max_samples: Option<u64>,
    /// Independent replicates `R` (≥ 2); their spread is the noise scale of the estimate.
    pub replicates: usize,
    /// Random or Sobol'.
    pub sampling: Sampling,
    /// Seed: the same seed gives the same result, whatever the thread count.
    pub seed: u64,
    /// Voxel (pixel) edge, m.
    pub voxel: f64,
    /// Tool link (default: the deepest link, the last in tree order among ties).
    pub tool: Option<String>,
    /// `None`: detect a planar cloud and report an area; `Some(true)`: project onto the
    /// best-fit plane; `Some(false)`: always voxels.
    pub planar: Option<bool>,
    /// Run the Jacobian pass (manipulability, condition number, dexterity).
    pub extras: bool,
    /// Samples of the Jacobian pass (default `min(samples, 2^20)`; at most `samples`).
    pub extras_samples: Option<u64>,
    /// Orientation bins in 3-D: cells per cube-face edge `k` (`6 k²` directions of the
    /// tool z axis), 1 to 4.
    pub sphere_cells: usize,
    /// Orientation bins for a planar workspace: arcs of the in-plane tool axis, 1 to 128.
    pub circle_bins: usize,
    /// A voxel is dexterous when it reaches at least this fraction of the bins.
    pub dexterous_fraction: f64,
    /// Keep the first this many Jacobian-pass samples as points (for the points CSV).
    pub keep_points: usize,
    /// Measure each replicate on a grid shifted by a random offset (default): the
    /// lattice position's effect is then zero-mean and inside the standard error. When
    /// `false` every replicate uses the grid anchored at the origin and the standard
    /// error is the sampling noise alone.
    pub shift_grid: bool,
    /// No progress bar.
    pub quiet: bool,
    /// Forward kinematics eight configurations at a time in SIMD lanes (default); `false`
    /// runs the scalar FK one configuration at a time (same results; for benchmarks).
    pub batched_fk: bool,
    /// Run the volume pass on at most this instruction set (default: the best the CPU
    /// has). Every instruction set gives bitwise the same result; for tests and
    /// benchmarks.
    pub max_isa: Option<Isa>,
    /// A flag another thread may raise (Ctrl-C in Python): the run then stops within one
    /// block of 65 536 samples per replicate and returns
    /// [`WorkspaceError::Cancelled`](super::WorkspaceError::Cancelled).
    pub stop: Option<Arc<AtomicBool>>,
}

impl Default for WorkspaceOptions {
    fn default() -> Self {
        Self {
            samples: 1 << 24,
            target_rel_error: None,
            max_samples: None,
            replicates: 8,
            sampling: Sampling::Sobol,
            seed: 0,
            voxel: 0.02,
            tool: None,
            planar: None,
            extras: true,
            extras_samples: None,
            sphere_cells: 4,
            circle_bins: 36,
            dexterous_fraction: 0.5,
            keep_points: 0,
            shift_grid: true,
            quiet: false,
            batched_fk: true,
            max_isa: None,
            stop: None,
        }
    }
}
