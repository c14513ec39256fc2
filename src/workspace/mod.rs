//! Reachable-workspace sampling with honest error bars.
//!
//! [`sample_workspace`] draws joint configurations uniformly inside the sampling box
//! ([`Model::sampling_bounds`]), runs forward kinematics of the tool link, and measures
//! the set of tool points on a grid of cubic voxels (edge [`WorkspaceOptions::voxel`]) —
//! or, when the cloud is planar, of square pixels in its plane, reporting an area.
//!
//! Error bars come from `R` independent replicates (independent random streams, or
//! independently Owen-scrambled Sobol' sequences): every estimate is the mean over
//! replicates, its standard error `sd / √R`. The discretisation bias is estimated
//! separately (first order: half the staircase surface times a voxel; and a Richardson
//! extrapolation from `h` and `2h`), as is the under-sampling left at the last doubling.
//! See `docs/workspace.md` for the derivations and measured figures.
//!
//! Parts: [`sobol`] (sequence and scrambling), `sampler` (joint-space streams), `plane`
//! (planarity of the cloud), `grid` (dense occupancy bitsets), `volume` (the replicated
//! volume pass and its statistics), `extras` (the Jacobian pass: manipulability,
//! condition number, dexterity), `output` (CSV), `progress` (the progress bar).

mod extras;
mod grid;
mod output;
mod plane;
mod progress;
mod sampler;
pub mod sobol;
mod volume;

pub use extras::{SamplePoint, VoxelStats};

use crate::model::{Model, WORLD};
use crate::spatial::Vec3;
use grid::Grid;
use sampler::{JointBox, QStream, RandomStream};
use serde::Serialize;
use std::time::Instant;
use volume::{mean_stderr, remaining_growth, Ctx};

/// How joint space is sampled.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Sampling {
    /// Independent uniform samples (counter-mode SplitMix64).
    Random,
    /// Owen-scrambled Sobol' (randomised quasi-Monte Carlo), at most 31 coordinates.
    Sobol,
}

impl std::str::FromStr for Sampling {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "random" => Ok(Sampling::Random),
            "sobol" => Ok(Sampling::Sobol),
            _ => Err(format!("unknown sampling '{s}': expected random or sobol")),
        }
    }
}

/// Options of [`sample_workspace`].
#[derive(Clone, Debug)]
pub struct WorkspaceOptions {
    /// Total samples of the volume pass, split into `replicates` streams of a power of two
    /// each (the count per replicate is rounded to the nearest power of two).
    pub samples: u64,
    /// Independent replicates `R` (≥ 2); the standard errors are `sd / √R`.
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
}

impl Default for WorkspaceOptions {
    fn default() -> Self {
        Self {
            samples: 1 << 24,
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
        }
    }
}

/// Why a run could not start.
#[derive(Debug, thiserror::Error)]
pub enum WorkspaceError {
    /// An option or the model does not allow the run.
    #[error("workspace: {0}")]
    Invalid(String),
}

fn invalid<T>(msg: impl Into<String>) -> Result<T, WorkspaceError> {
    Err(WorkspaceError::Invalid(msg.into()))
}

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
    /// Mean occupied measure over replicates (m³, or m² when planar).
    pub measure: f64,
    /// Its standard error.
    pub stderr: f64,
    /// Mean bias-corrected measure (see [`VoxelBias::corrected`]).
    pub corrected: f64,
    /// Its standard error.
    pub corrected_stderr: f64,
    /// Mean Richardson measure (see [`VoxelBias::richardson`]).
    pub richardson: f64,
    /// Its standard error.
    pub richardson_stderr: f64,
}

/// The discretisation bias and the corrected estimates (units of the measure: m³, or m²
/// when planar). See `docs/workspace.md`.
#[derive(Clone, Debug, Serialize)]
pub struct VoxelBias {
    /// `"m3"` or `"m2"`.
    pub unit: &'static str,
    /// Exposed faces (edges when planar) of the occupied cells, mean over replicates.
    pub exposed_faces: f64,
    /// The staircase surface (m², or perimeter in m) `exposed × h^(D−1)`: an estimate of
    /// `∮ ‖n‖₁ dS`, between the true surface and √3 (√2) times it.
    pub staircase_surface: f64,
    /// First-order overestimate at full coverage, `exposed × h^D / 2`.
    pub bias: f64,
    /// Raw estimate minus `bias`, mean over replicates.
    pub corrected: f64,
    /// Its standard error.
    pub corrected_stderr: f64,
    /// The same samples on cells of `2h`, mean over replicates.
    pub coarse: f64,
    /// Richardson extrapolation `2 M(h) − M(2h)`, mean over replicates.
    pub richardson: f64,
    /// Its standard error.
    pub richardson_stderr: f64,
    /// Growth of the raw measure still expected from more samples per replicate
    /// (geometric extrapolation of the last two doublings, the ratio floored at the
    /// corner-sliver law `2^(−1/D)`); `None` when the increments are not yet shrinking
    /// (and the last one is above the standard error).
    pub undersampling: Option<f64>,
    /// The same for `corrected` (holes left by under-sampling also add exposed faces,
    /// so it converges more slowly).
    pub corrected_undersampling: Option<f64>,
    /// `|corrected − richardson|`: the two first-order-unbiased estimates differ by
    /// their second-order terms (and noise), a scale for what the first-order correction
    /// leaves.
    pub second_order: f64,
    /// Systematic uncertainty of `corrected`: `second_order + corrected_undersampling`
    /// (∞, serialized as null, when that is `None`).
    pub uncertainty: f64,
    /// Where the true measure should lie: `[corrected − 3 stderr − second_order,
    /// corrected + 3 stderr + second_order + corrected_undersampling]` (more samples only
    /// add cells, so the under-sampling widens the upper side only).
    pub interval: [f64; 2],
    /// Empty cells with every face neighbour occupied, mean over replicates (holes left
    /// by under-sampling, or true cavities).
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
    /// Occupied volume, mean over replicates (0 when planar: see `area_m2`).
    pub volume_m3: f64,
    /// Its standard error.
    pub volume_stderr: f64,
    /// Occupied area in the plane, mean over replicates (planar only).
    pub area_m2: Option<f64>,
    /// Its standard error.
    pub area_stderr: Option<f64>,
    /// Occupied measure of all samples pooled (m³ or m²): more coverage than one
    /// replicate; `pooled − mean` shows what `R` times more samples still add.
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
    /// Dexterous volume (0 when planar).
    pub dexterous_volume_m3: f64,
    /// Dexterous area (planar only).
    pub dexterous_area_m2: Option<f64>,
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
    grid: Grid,
    #[serde(skip)]
    union: Vec<u64>,
    #[serde(skip)]
    boundary_bits: Vec<u64>,
}

impl WorkspaceResult {
    /// The main estimate: the area when planar, the volume otherwise.
    pub fn measure(&self) -> f64 {
        self.area_m2.unwrap_or(self.volume_m3)
    }

    /// Standard error of [`Self::measure`].
    pub fn measure_stderr(&self) -> f64 {
        self.area_stderr.unwrap_or(self.volume_stderr)
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

/// The deepest link (most movable ancestors), the last in tree order among ties.
fn default_tool(model: &Model) -> usize {
    let depth = |link: usize| {
        let mut b = model.links[link].body;
        let mut d = 0;
        while b != WORLD {
            d += 1;
            b = model.parent[b];
        }
        d
    };
    let mut best = (0, 0);
    for l in 0..model.links.len() {
        let d = depth(l);
        if d >= best.1 {
            best = (l, d);
        }
    }
    best.0
}

/// A ball that contains every tool point for configurations in the box: centred on the
/// first joint's origin (which that joint does not move), with radius the sum, along the
/// tool's chain, of the placement offsets, the largest prismatic strokes and the tool
/// offset.
fn reach_bound(model: &Model, tool: usize, jb: &JointBox) -> (Vec3, f64) {
    let link = &model.links[tool];
    let mut chain = Vec::new();
    let mut b = link.body;
    while b != WORLD {
        chain.push(b);
        b = model.parent[b];
    }
    let root = *chain.last().expect("the tool moves");
    let mut radius = link.offset.trans.norm();
    for &b in &chain {
        if b != root {
            radius += model.placement[b].trans.norm();
        }
        if !model.kind[b].is_revolute() {
            let k = model.q_index[b];
            let (lo, hi) = (jb.lo[k], jb.lo[k] + jb.span[k]);
            let s = |q: f64| (model.q_mult[b] * q + model.q_offset[b]).abs();
            radius += s(lo).max(s(hi));
        }
    }
    (model.placement[root].trans, radius)
}

/// Per-replicate sample count: `samples / R` rounded to the nearest power of two.
fn per_replicate(samples: u64, replicates: usize) -> u64 {
    let target = (samples / replicates as u64).max(1);
    let k = 63 - target.leading_zeros();
    let lo = 1u64 << k;
    if k < 63 && target - lo > (lo << 1) - target {
        lo << 1
    } else {
        lo
    }
}

/// Samples the reachable workspace of `model`'s tool link and measures it (see the
/// module docs and `docs/workspace.md`). Runs on the current rayon pool.
pub fn sample_workspace(
    model: &Model,
    opts: &WorkspaceOptions,
) -> Result<WorkspaceResult, WorkspaceError> {
    let t0 = Instant::now();
    if model.nv == 0 {
        return invalid("the model has no coordinates");
    }
    if !(opts.voxel.is_finite() && opts.voxel > 0.0) {
        return invalid(format!("voxel must be positive, got {}", opts.voxel));
    }
    if opts.replicates < 2 {
        return invalid("at least 2 replicates are needed for a standard error");
    }
    if opts.sampling == Sampling::Sobol && model.nv > sobol::MAX_DIMS {
        return invalid(format!(
            "Sobol' sampling has direction numbers for {} coordinates, the model has {}: use random sampling",
            sobol::MAX_DIMS,
            model.nv
        ));
    }
    if !(1..=4).contains(&opts.sphere_cells) || !(1..=128).contains(&opts.circle_bins) {
        return invalid("sphere_cells must be 1 to 4 and circle_bins 1 to 128");
    }
    if !(opts.dexterous_fraction > 0.0 && opts.dexterous_fraction <= 1.0) {
        return invalid("dexterous_fraction must be in (0, 1]");
    }
    let tool = match &opts.tool {
        Some(name) => model
            .link_id(name)
            .ok_or_else(|| WorkspaceError::Invalid(format!("link '{name}' does not exist")))?,
        None => default_tool(model),
    };
    if model.links[tool].body == WORLD {
        return invalid(format!(
            "link '{}' is fixed to the world: it has no workspace",
            model.links[tool].name
        ));
    }
    let n = per_replicate(opts.samples, opts.replicates);
    if opts.sampling == Sampling::Sobol && n > 1 << 32 {
        return invalid("Sobol': at most 2^32 samples per replicate");
    }
    let jb = JointBox::new(model);
    let (center, radius) = reach_bound(model, tool, &jb);
    let mut warnings = Vec::new();

    // Pilot cloud: planarity and the in-plane tool axis.
    let mut pilot = Vec::with_capacity(4096);
    let mut rots = Vec::with_capacity(4096);
    {
        let mut data = crate::data::Data::new(model);
        let mut q = vec![0.0; model.nv];
        let mut s = RandomStream::new(opts.seed, u64::MAX, model.nv, 0);
        for _ in 0..4096 {
            s.next_q(&jb, &mut q);
            crate::kinematics::forward_kinematics(model, &mut data, &q);
            let m = crate::kinematics::frame_placement(model, &data, tool);
            pilot.push(m.trans);
            rots.push(m.rot);
        }
    }
    // Flat within 1 nm per metre of reach; a direction counts for the dimension beyond
    // 1 µm per metre.
    let tol = 1e-9 * (1.0 + radius);
    let shape = plane::analyse(&pilot, 1e3 * tol);
    let mut planar = match opts.planar {
        None => shape.off_plane <= tol,
        Some(p) => p,
    };
    if planar && shape.off_plane > tol {
        warnings.push(format!(
            "the tool points are not planar (up to {:.3e} m off the best-fit plane): the area is that of their projection",
            shape.off_plane
        ));
    }
    if shape.dimension < 2 {
        warnings.push(format!(
            "the tool points span {} dimension(s): the measure is pure discretisation",
            shape.dimension
        ));
    }

    let k_max = n.trailing_zeros();
    let checkpoints: Vec<u64> = (k_max.min(10)..=k_max).map(|k| 1u64 << k).collect();
    let threads = rayon::current_num_threads();

    loop {
        let plane_frame = planar.then_some(shape.plane);
        let grid = Grid::new(opts.voxel, &center, radius, plane_frame, [0.0; 3]).map_err(|cells| {
            WorkspaceError::Invalid(format!(
                "a dense grid of {cells} cells of {} m around a reach of {radius:.3} m is too large (max {}): use a larger voxel",
                opts.voxel,
                grid::MAX_CELLS
            ))
        })?;
        let ctx = Ctx {
            model,
            tool,
            jb: jb.clone(),
            grid,
            sampling: opts.sampling,
            seed: opts.seed,
            shift: opts.shift_grid,
            center,
            radius,
        };
        let r = opts.replicates;
        let pb = progress::bar(n * r as u64, opts.quiet, "workspace");
        let (reps, union) = volume::run(&ctx, r, &checkpoints, &pb);
        pb.finish_and_clear();
        let max_off = reps.iter().map(|r| r.max_off_plane).fold(0.0, f64::max);
        if planar && opts.planar.is_none() && max_off > 100.0 * tol {
            warnings.push(format!(
                "the pilot cloud looked planar but a sample lies {max_off:.3e} m off the plane: measured in 3-D"
            ));
            planar = false;
            continue;
        }

        // Statistics over replicates.
        let g = &ctx.grid;
        let cm = g.cell_measure();
        let dims = g.dims();
        let col = |f: &dyn Fn(&volume::Replicate) -> f64| -> (f64, f64) {
            mean_stderr(&reps.iter().map(f).collect::<Vec<_>>())
        };
        let at = |j: usize| {
            let raw = col(&|r| r.checks[j].scan.occupied as f64 * cm);
            let corr = col(&|r| {
                let s = &r.checks[j].scan;
                (s.occupied as f64 - 0.5 * s.exposed as f64) * cm
            });
            let coarse_cm = cm * 2f64.powi(dims);
            let rich = col(&|r| {
                let c = &r.checks[j];
                2.0 * c.scan.occupied as f64 * cm - c.coarse as f64 * coarse_cm
            });
            let coarse = col(&|r| r.checks[j].coarse as f64 * coarse_cm);
            (raw, corr, rich, coarse)
        };
        let convergence: Vec<ConvergencePoint> = checkpoints
            .iter()
            .enumerate()
            .map(|(j, &cp)| {
                let (raw, corr, rich, _) = at(j);
                ConvergencePoint {
                    samples: cp * r as u64,
                    samples_per_replicate: cp,
                    measure: raw.0,
                    stderr: raw.1,
                    corrected: corr.0,
                    corrected_stderr: corr.1,
                    richardson: rich.0,
                    richardson_stderr: rich.1,
                }
            })
            .collect();
        let last = checkpoints.len() - 1;
        let ((raw, raw_se), (corrected, corrected_se), (rich, rich_se), (coarse, _)) = at(last);
        let (exposed, _) = col(&|r| r.last().scan.exposed as f64);
        let (holes, _) = col(&|r| r.last().scan.holes as f64);
        let series =
            |f: fn(&ConvergencePoint) -> f64| -> Vec<f64> { convergence.iter().map(f).collect() };
        let undersampling = remaining_growth(&series(|c| c.measure), dims, raw_se);
        let corrected_undersampling =
            remaining_growth(&series(|c| c.corrected), dims, corrected_se);
        if corrected_undersampling.is_none() {
            warnings.push(
                "coverage has not converged (the estimates still grow as fast with more samples): use more samples or a larger voxel"
                    .into(),
            );
        }
        let bias = VoxelBias {
            unit: if planar { "m2" } else { "m3" },
            exposed_faces: exposed,
            staircase_surface: exposed * opts.voxel.powi(dims - 1),
            bias: 0.5 * exposed * cm,
            corrected,
            corrected_stderr: corrected_se,
            coarse,
            richardson: rich,
            richardson_stderr: rich_se,
            undersampling,
            corrected_undersampling,
            second_order: (corrected - rich).abs(),
            uncertainty: (corrected - rich).abs()
                + corrected_undersampling.unwrap_or(f64::INFINITY),
            interval: [
                corrected - 3.0 * corrected_se - (corrected - rich).abs(),
                corrected
                    + 3.0 * corrected_se
                    + (corrected - rich).abs()
                    + corrected_undersampling.unwrap_or(f64::INFINITY),
            ],
            isolated_holes: holes,
        };
        let pooled_scan = g.scan(&union);
        let boundary_bits = g.boundary_bits(&union);
        let mut lo = Vec3::repeat(f64::INFINITY);
        let mut hi = Vec3::repeat(f64::NEG_INFINITY);
        for rep in &reps {
            lo = lo.inf(&rep.lo);
            hi = hi.sup(&rep.hi);
        }
        let outside: u64 = reps.iter().map(|r| r.outside).sum();
        if outside > 0 {
            warnings.push(format!("{outside} samples fell outside the grid"));
        }

        // Jacobian pass.
        let total = n * r as u64;
        let m_extras = if opts.extras {
            opts.extras_samples.unwrap_or(1 << 20).min(total)
        } else {
            0
        };
        let keep = (opts.keep_points as u64).min(total);
        let bins = if planar {
            // The tool axis that stays closest to the plane.
            let axis = (0..3)
                .min_by(|&a, &b| {
                    let s = |k: usize| -> f64 {
                        rots.iter()
                            .map(|r| r.column(k).dot(&shape.plane.n).abs())
                            .sum()
                    };
                    s(a).total_cmp(&s(b))
                })
                .unwrap_or(0);
            extras::Bins::Circle {
                bins: opts.circle_bins,
                axis,
                plane: shape.plane,
            }
        } else {
            extras::Bins::Sphere {
                k: opts.sphere_cells,
            }
        };
        let threshold = ((opts.dexterous_fraction * bins.count() as f64).ceil() as usize).max(1);
        let (voxels, points, extras) = if m_extras.max(keep) > 0 {
            let pb = progress::bar(m_extras.max(keep), opts.quiet, "jacobians");
            let ex = extras::run(
                &ctx,
                &bins,
                m_extras.max(keep),
                n,
                keep,
                &union,
                &boundary_bits,
                threshold,
                &pb,
            );
            pb.finish_and_clear();
            if ex.strays > 0 {
                warnings.push(format!(
                    "{} Jacobian-pass samples fell outside the occupied voxels",
                    ex.strays
                ));
            }
            if opts.extras {
                let dex = ex.voxels.iter().filter(|v| v.dexterous).count() as u64;
                let summary = ExtrasSummary {
                    samples: ex.samples,
                    voxels: ex.voxels.len() as u64,
                    samples_per_voxel: ex.samples as f64 / ex.voxels.len().max(1) as f64,
                    manipulability_mean: ex.w_mean,
                    manipulability_max: ex.w_max,
                    condition_min: ex.k_min,
                    orientation: if planar {
                        "in-plane tool axis angle"
                    } else {
                        "tool z axis (cube map)"
                    },
                    orientation_bins: bins.count(),
                    dexterous_min_bins: threshold,
                    dexterous_voxels: dex,
                };
                (ex.voxels, ex.points, Some(summary))
            } else {
                (Vec::new(), ex.points, None)
            }
        } else {
            (Vec::new(), Vec::new(), None)
        };
        let dex_measure = extras
            .as_ref()
            .map_or(0.0, |e| e.dexterous_voxels as f64 * cm);

        let pl = &shape.plane;
        return Ok(WorkspaceResult {
            robot: model.name.clone(),
            tool: model.links[tool].name.clone(),
            joint_names: model.dof_names(),
            sampling: opts.sampling,
            seed: opts.seed,
            replicates: r,
            samples: total,
            samples_per_replicate: n,
            voxel: opts.voxel,
            planar,
            cloud_dimension: shape.dimension,
            plane: planar.then(|| PlaneInfo {
                normal: pl.n.into(),
                offset: pl.o.dot(&pl.n),
                u: pl.u.into(),
                v: pl.v.into(),
            }),
            volume_m3: if planar { 0.0 } else { raw },
            volume_stderr: if planar { 0.0 } else { raw_se },
            area_m2: planar.then_some(raw),
            area_stderr: planar.then_some(raw_se),
            pooled: pooled_scan.occupied as f64 * cm,
            bias,
            convergence,
            occupied_voxels: pooled_scan.occupied,
            boundary_voxels: pooled_scan.boundary,
            bbox: [lo.into(), hi.into()],
            dexterous_volume_m3: if planar { 0.0 } else { dex_measure },
            dexterous_area_m2: planar.then_some(dex_measure),
            extras,
            outside_grid: outside,
            warnings,
            threads,
            time_s: t0.elapsed().as_secs_f64(),
            voxels,
            points,
            grid: ctx.grid,
            union,
            boundary_bits,
        });
    }
}
