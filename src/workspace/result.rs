//! What [`crate::workspace::sample_workspace`] returns: the result, its voxel-bias block, the
//! convergence series, the Jacobian-pass summary, and the queries on the pooled
//! occupancy (which voxel is occupied, boundary, its statistics).

use crate::core::spatial::Vec3;
use crate::workspace::estimate::{Estimate, IntervalKind};
use crate::workspace::grid::Grid;
use crate::workspace::workspace_options::Sampling;
use serde::Serialize;

/// The plane of a planar workspace.
#[derive(Clone, Debug, Serialize)]
pub struct PlaneInfo {
    /// Unit normal.
    pub normal: [f64; 3],
    /// Signed distance of the plane from the world origin along the normal (m).
    pub offset: f64,
    /// First in-plane axis (pixel columns).
    pub u: [f64; 3],
    /// Second in-plane axis (pixel rows).
    pub v: [f64; 3],
}

/// One point of the convergence series.
#[derive(Clone, Debug, Serialize)]
pub struct ConvergencePoint {
    /// Total samples (`R ×` per replicate).
    pub samples: u64,
    /// Samples per replicate.
    pub samples_per_replicate: u64,
    /// The headline measure after these samples (m³, or m² when planar).
    pub measure: f64,
    /// Its noise scale (standard deviation of the replicates' corrected measures).
    pub stderr: f64,
    /// Pooled bias-corrected measure (see [`VoxelBias::corrected`]).
    pub corrected: f64,
    /// Its noise scale.
    pub corrected_stderr: f64,
    /// Pooled Richardson measure (see [`VoxelBias::richardson`]).
    pub richardson: f64,
    /// Its noise scale.
    pub richardson_stderr: f64,
    /// Pooled raw occupancy (occupied cells × cell measure).
    pub raw: f64,
    /// The 95 % interval after these samples; the upper end is null while only a lower
    /// bound can be given.
    pub interval: [Option<f64>; 2],
}

/// The discretisation bias and the corrected estimates on the pooled estimation grid (all
/// samples; units of the measure: m³, or m² when planar). See `docs/workspace.md`.
#[derive(Clone, Debug, Serialize)]
pub struct VoxelBias {
    /// `"m3"` or `"m2"`.
    pub unit: &'static str,
    /// Exposed faces (edges when planar) of the pooled occupied cells.
    pub exposed_faces: f64,
    /// The staircase surface (m², or perimeter in m) `exposed × h^(D−1)`: an estimate of
    /// `∮ ‖n‖₁ dS`, between the true surface and √3 (√2) times it.
    pub staircase_surface: f64,
    /// First-order overestimate at full coverage, `exposed × h^D / 2`.
    pub bias: f64,
    /// Pooled raw occupancy minus `bias`, isolated holes counted as filled.
    pub corrected: f64,
    /// Its noise scale: the standard deviation of the replicates' own corrected
    /// measures (each on its own shifted grid).
    pub corrected_stderr: f64,
    /// The pooled samples on cells of `2h`.
    pub coarse: f64,
    /// Richardson extrapolation `2 M(h) − M(2h)` of the pooled occupancy.
    pub richardson: f64,
    /// Its noise scale (as `corrected_stderr`).
    pub richardson_stderr: f64,
    /// Growth of `corrected` still expected from more samples: the unseen boundary
    /// cells estimated from the cells hit once and twice (see [`Estimate::remaining`]);
    /// `None` while coverage has not converged.
    pub undersampling: Option<f64>,
    /// The same (kept for the JSON contract).
    pub corrected_undersampling: Option<f64>,
    /// `|corrected − richardson|`: the two first-order-unbiased estimates differ by
    /// their second-order terms (and noise), a scale for what the first-order correction
    /// leaves.
    pub second_order: f64,
    /// Systematic uncertainty of the headline: `second_order` plus half the range of the
    /// unseen cells' measure
    /// (∞, serialized as null, while coverage has not converged).
    pub uncertainty: f64,
    /// The 95 % interval of the headline (the same as `volume_interval_m3` or
    /// `area_interval_m2`; the upper end ∞, serialized as null, for a lower bound).
    pub interval: [f64; 2],
    /// Empty cells of the pooled occupancy with every face neighbour occupied (holes left
    /// by under-sampling, counted as filled by `corrected`).
    pub isolated_holes: f64,
}

/// Summary of the Jacobian pass.
#[derive(Clone, Debug, Serialize)]
pub struct ExtrasSummary {
    /// Samples of the pass.
    pub samples: u64,
    /// Voxels with at least one of them.
    pub voxels: u64,
    /// Mean samples per such voxel.
    pub samples_per_voxel: f64,
    /// Mean translational manipulability over the samples.
    pub manipulability_mean: f64,
    /// Largest.
    pub manipulability_max: f64,
    /// Smallest translational condition number.
    pub condition_min: f64,
    /// What is binned: `"tool z axis (cube map)"` or `"in-plane tool axis angle"`.
    pub orientation: &'static str,
    /// Number of orientation bins.
    pub orientation_bins: usize,
    /// Distinct bins that make a voxel dexterous.
    pub dexterous_min_bins: usize,
    /// Dexterous voxels (pixels).
    pub dexterous_voxels: u64,
}

/// Result of [`sample_workspace`].
#[derive(Clone, Debug, Serialize)]
pub struct WorkspaceResult {
    /// Robot name.
    pub robot: String,
    /// Tool link.
    pub tool: String,
    /// Coordinate names, in order.
    pub joint_names: Vec<String>,
    /// Sampling scheme.
    pub sampling: Sampling,
    /// Seed.
    pub seed: u64,
    /// Replicates `R`.
    pub replicates: usize,
    /// Samples of the volume pass (`R × samples_per_replicate`).
    pub samples: u64,
    /// Samples per replicate (a power of two).
    pub samples_per_replicate: u64,
    /// Voxel (pixel) edge, m.
    pub voxel: f64,
    /// Whether the workspace was measured as an area in a plane.
    pub planar: bool,
    /// Number of principal directions in which the pilot cloud has extent (0 to 3).
    pub cloud_dimension: usize,
    /// The plane, when planar.
    pub plane: Option<PlaneInfo>,
    /// The volume: bias-corrected pooled occupancy plus the estimated unseen boundary
    /// cells (0 when planar: see `area_m2`). See `docs/workspace.md`.
    pub volume_m3: f64,
    /// Its noise scale (standard deviation of the replicates' corrected volumes; the
    /// interval also holds the systematic terms).
    pub volume_stderr: f64,
    /// 95 % interval of the volume `[lo, hi]`; `hi` is null when the samples only
    /// allow a lower bound (then see `samples_needed`). Null when planar.
    pub volume_interval_m3: Option<[Option<f64>; 2]>,
    /// The area in the plane, as `volume_m3` (planar only).
    pub area_m2: Option<f64>,
    /// Its noise scale.
    pub area_stderr: Option<f64>,
    /// 95 % interval of the area (planar only), as `volume_interval_m3`.
    pub area_interval_m2: Option<[Option<f64>; 2]>,
    /// `"interval"` (95 %, two-sided) or `"lower_bound"` (too few samples: only a
    /// lower bound).
    pub interval_kind: IntervalKind,
    /// When only a lower bound is given: about how many samples a two-sided interval
    /// needs.
    pub samples_needed: Option<u64>,
    /// Samples per occupied voxel of the pooled estimation grid.
    pub samples_per_voxel: f64,
    /// The adaptive mode's target (relative half-width of the interval), if any.
    pub target_rel_error: Option<f64>,
    /// Whether the target was reached (adaptive mode).
    pub target_reached: Option<bool>,
    /// The full estimate after the last doubling.
    pub estimate: Estimate,
    /// Raw occupied measure of all samples pooled on the pooled estimation grid (m³ or
    /// m²).
    pub pooled: f64,
    /// Discretisation bias and corrected estimates.
    pub bias: VoxelBias,
    /// Mean measure against samples per replicate (doublings).
    pub convergence: Vec<ConvergencePoint>,
    /// Occupied voxels of the pooled occupancy.
    pub occupied_voxels: u64,
    /// Pooled voxels with at least one empty face neighbour.
    pub boundary_voxels: u64,
    /// Bounding box of every tool point, `[[min x, y, z], [max x, y, z]]` (m).
    pub bbox: [[f64; 3]; 2],
    /// Dexterous volume (0 when planar): the voxels whose Jacobian-pass samples reach
    /// enough orientation bins — a lower bound, it only grows with samples.
    pub dexterous_volume_m3: f64,
    /// Dexterous area (planar only).
    pub dexterous_area_m2: Option<f64>,
    /// Where the dexterous measure lies: `[counted, upper end of the workspace's
    /// interval]` (null upper end for a lower bound); null without the Jacobian pass.
    pub dexterous_interval: Option<[Option<f64>; 2]>,
    /// The Jacobian pass, when run.
    pub extras: Option<ExtrasSummary>,
    /// Samples that fell outside the grid (always 0 unless the reach bound is wrong).
    pub outside_grid: u64,
    /// Things the caller should know.
    pub warnings: Vec<String>,
    /// Rayon threads used.
    pub threads: usize,
    /// Wall time, s.
    pub time_s: f64,
    /// Per-voxel statistics of the Jacobian pass, voxels in grid order.
    #[serde(skip)]
    pub voxels: Vec<VoxelStats>,
    /// Kept sample points.
    #[serde(skip)]
    pub points: Vec<SamplePoint>,
    #[serde(skip)]
    pub(crate) grid: Grid,
    #[serde(skip)]
    pub(crate) union: Vec<u64>,
    #[serde(skip)]
    pub(crate) boundary_bits: Vec<u64>,
}

impl WorkspaceResult {
    /// The main estimate: the area when planar, the volume otherwise.
    pub fn measure(&self) -> f64 {
        self.area_m2.unwrap_or(self.volume_m3)
    }

    /// Noise scale of [`Self::measure`].
    pub fn measure_stderr(&self) -> f64 {
        self.area_stderr.unwrap_or(self.volume_stderr)
    }

    /// The 95 % interval of [`Self::measure`]; the upper end is `None` for a lower bound.
    pub fn measure_interval(&self) -> [Option<f64>; 2] {
        self.estimate.interval
    }

    /// Whether `value` lies in [`Self::measure_interval`] (above the lower bound when
    /// there is no upper end).
    pub fn interval_covers(&self, value: f64) -> bool {
        let [lo, hi] = self.estimate.interval;
        lo.is_none_or(|lo| lo <= value) && hi.is_none_or(|hi| value <= hi)
    }

    /// Whether the voxel containing world point `p` is occupied (pooled samples). For a
    /// planar workspace `p` is projected onto the plane.
    pub fn is_occupied(&self, p: &Vec3) -> bool {
        let (c, _) = self.grid.coords(p);
        self.grid
            .locate(&c)
            .is_some_and(|i| Grid::test(&self.union, i))
    }

    /// Whether that voxel is a boundary voxel.
    pub fn is_boundary(&self, p: &Vec3) -> bool {
        let (c, _) = self.grid.coords(p);
        self.grid
            .locate(&c)
            .is_some_and(|i| Grid::test(&self.boundary_bits, i))
    }

    /// Jacobian-pass statistics of the voxel containing `p`, if any sample fell in it.
    pub fn voxel_at(&self, p: &Vec3) -> Option<&VoxelStats> {
        let (c, _) = self.grid.coords(p);
        let g = self.grid.global(self.grid.locate(&c)?);
        let key = |v: &[i64; 3]| (v[2], v[1], v[0]);
        self.voxels
            .binary_search_by(|v| key(&v.index).cmp(&key(&g)))
            .ok()
            .map(|i| &self.voxels[i])
    }

    /// Corners `[min, max]` (world, m) of the voxel with global index `index`; for a
    /// planar workspace, the in-plane coordinates `[(u, v) min, (u, v) max]` and 0.
    pub fn voxel_bounds(&self, index: [i64; 3]) -> [[f64; 3]; 2] {
        let h = self.voxel;
        let lo = index.map(|i| i as f64 * h);
        let mut hi = index.map(|i| (i + 1) as f64 * h);
        if self.planar {
            hi[2] = 0.0;
        }
        [lo, hi]
    }
}

/// A kept sample (for the points CSV).
#[derive(Clone, Debug, serde::Serialize)]
pub struct SamplePoint {
    /// Joint coordinates.
    pub q: Vec<f64>,
    /// Tool point in the world (m).
    pub p: [f64; 3],
    /// Translational manipulability.
    pub manipulability: f64,
    /// Translational condition number.
    pub condition: f64,
}

/// Per-voxel statistics of the Jacobian pass.
#[derive(Clone, Debug, serde::Serialize)]
pub struct VoxelStats {
    /// Global cell index `(i, j, k)` (planar: in-plane `(i, j)` and 0).
    pub index: [i64; 3],
    /// World position of the cell centre.
    pub center: [f64; 3],
    /// Whether the cell has an empty face neighbour in the pooled occupancy.
    pub boundary: bool,
    /// Jacobian-pass samples in the cell.
    pub samples: u32,
    /// Mean translational manipulability.
    pub manipulability_mean: f64,
    /// Smallest.
    pub manipulability_min: f64,
    /// Largest.
    pub manipulability_max: f64,
    /// Mean translational condition number (∞ if a sample was exactly singular).
    pub condition_mean: f64,
    /// Smallest.
    pub condition_min: f64,
    /// Largest.
    pub condition_max: f64,
    /// Distinct orientation bins reached.
    pub orientations: u32,
    /// Whether `orientations` reaches the dexterity threshold.
    pub dexterous: bool,
}
