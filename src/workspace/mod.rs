//! Reachable-workspace sampling with intervals that cover the truth.
//!
//! [`sample_workspace`] draws joint configurations uniformly inside the sampling box
//! ([`Model::sampling_bounds`]), runs forward kinematics of the tool origin eight
//! configurations at a time (`f64` SIMD lanes, [`crate::kinematics::fk_lanes`]), and measures
//! the set of tool points on a grid of cubic voxels (edge [`WorkspaceOptions::voxel`]) —
//! or, when the cloud is planar, of square pixels in its plane, reporting an area.
//!
//! The budget is reached by doublings: `R` independent replicates (independent random
//! streams, or independently Owen-scrambled Sobol' sequences) advance together, and after
//! every doubling the pooled occupancy of all samples gives the bias-corrected measure,
//! the replicates' own grids its noise, and the doubling series the under-sampling still
//! to come ([`estimate`]). The result is a headline measure with a 95 % interval, or,
//! when the samples are too few, a lower bound and the samples needed. In adaptive mode
//! ([`WorkspaceOptions::target_rel_error`]) the doublings go on until the interval is
//! narrow enough. See `docs/workspace.md` for the derivations and the calibration.
//!
//! Parts: [`sobol`] (sequence and scrambling), `sampler` (joint-space streams), `plane`
//! (planarity of the cloud), `grid` (dense occupancy bitsets and their scans), `counts`
//! (two-bit hit counters), `volume` (the replicated volume pass), `kernel` (its hot loop,
//! per instruction set), `estimate` (the estimator and its interval), `result`
//! (what is returned), `extras` (the Jacobian pass: manipulability, condition number,
//! dexterity), `output` (CSV), `progress` (the progress bar).

mod counts;
pub mod estimate;
mod grid;
mod jacobian_pass;
mod output;
pub mod picture_geometry;
mod plane;
mod progress;
mod result;
mod sample_stream;
pub mod sobol;
mod volume;
mod volume_context;
mod volume_kernel;
mod workspace_options;

pub use crate::kinematics::fk_lanes::Isa;
pub use estimate::{Estimate, IntervalKind};
pub use output::summary_lines;
pub use result::{
    ConvergencePoint, ExtrasSummary, PlaneInfo, SamplePoint, VoxelBias, VoxelStats, WorkspaceResult,
};
pub use workspace_options::{Sampling, UnknownSampling, WorkspaceOptions};

use crate::core::spatial::Vec3;
use crate::model::{Model, WORLD};
use crate::workspace::jacobian_pass::{jacobian_pass, JacobianPass};
use crate::workspace::sample_stream::{JointBox, QStream, RandomStream};
use grid::Grid;
use std::time::Instant;
use volume_context::Ctx;
use volume_kernel::Replicate;

/// Why a run could not start.
#[derive(Debug, thiserror::Error)]
pub enum WorkspaceError {
    /// An option or the model does not allow the run.
    #[error("workspace: {0}")]
    Invalid(String),
    /// The caller raised [`WorkspaceOptions::stop`].
    #[error("workspace: cancelled")]
    Cancelled,
}

fn invalid<T>(msg: impl Into<String>) -> Result<T, WorkspaceError> {
    Err(WorkspaceError::Invalid(msg.into()))
}

/// The deepest link (most movable ancestors), the last in tree order among ties.
fn default_tool(model: &Model) -> usize {
    let depth = |link: usize| model.support(model.links[link].body).count();
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
    let chain: Vec<usize> = model.support(link.body).collect();
    let root = *chain.last().expect("the tool moves");
    let mut radius = link.offset.trans.norm();
    for &b in &chain {
        if b != root {
            radius += model.placement[b].trans.norm();
        }
        let k = model.q_index[b];
        radius += model.stroke(b, jb.lo[k], jb.lo[k] + jb.span[k]);
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

/// Checks the options against the model; returns the tool link.
fn validate(model: &Model, opts: &WorkspaceOptions) -> Result<usize, WorkspaceError> {
    if model.nv == 0 {
        return invalid("the model has no coordinates");
    }
    if !(opts.voxel.is_finite() && opts.voxel > 0.0) {
        return invalid(format!("voxel must be positive, got {}", opts.voxel));
    }
    if opts.replicates < 2 {
        return invalid("at least 2 replicates are needed for a standard error");
    }
    if let Some(t) = opts.target_rel_error {
        if !(t.is_finite() && t > 0.0) {
            return invalid(format!("target_rel_error must be positive, got {t}"));
        }
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
    Ok(tool)
}

/// Per-replicate counts of the doublings: from `2^min(6, k)` up to the budget (fixed
/// mode) or up to what `max_samples` allows (adaptive mode; the loop stops earlier once
/// the target is met).
fn stage_plan(opts: &WorkspaceOptions) -> Vec<u64> {
    let r = opts.replicates;
    let n = per_replicate(opts.samples, r);
    let last = match opts.target_rel_error {
        None => n,
        Some(_) => {
            let max = opts.max_samples.unwrap_or(1 << 30).max(r as u64);
            let k = 63 - (max / r as u64).leading_zeros();
            (1u64 << k).max(n.min(1 << k))
        }
    };
    let k_last = last.trailing_zeros();
    (k_last.min(6)..=k_last).map(|k| 1u64 << k).collect()
}

/// Samples the reachable workspace of `model`'s tool link and measures it (see the
/// module docs and `docs/workspace.md`). Runs on the current rayon pool.
pub fn sample_workspace(
    model: &Model,
    opts: &WorkspaceOptions,
) -> Result<WorkspaceResult, WorkspaceError> {
    let t0 = Instant::now();
    let tool = validate(model, opts)?;
    let plan = stage_plan(opts);
    let n_max = *plan.last().expect("one stage");
    if opts.sampling == Sampling::Sobol && n_max > 1 << 32 {
        return invalid("Sobol': at most 2^32 samples per replicate");
    }
    let jb = JointBox::new(model);
    let (center, radius) = reach_bound(model, tool, &jb);
    let chain = crate::kinematics::fk_lanes::ToolChain::new(model, tool).expect("the tool moves");
    let mut warnings = Vec::new();
    let (shape, rots, tol) = pilot(model, opts, &jb, tool, radius);
    let mut planar = match opts.planar {
        None => shape.off_plane <= tol,
        Some(p) => p,
    };
    warnings.extend(shape_warnings(&shape, planar, tol));
    loop {
        let plane_frame = planar.then_some(shape.plane);
        let ctx = make_ctx(
            model,
            opts,
            tool,
            &jb,
            &chain,
            (center, radius),
            plane_frame,
        )?;
        let passes = doublings(&ctx, opts, &plan, planar);
        if ctx.stopped() {
            return Err(WorkspaceError::Cancelled);
        }
        let max_off = passes
            .reps
            .iter()
            .map(|r| r.marks.max_off_plane)
            .fold(0.0, f64::max);
        if planar && opts.planar.is_none() && max_off > 100.0 * tol {
            warnings.push(format!(
                "the pilot cloud looked planar but a sample lies {max_off:.3e} m off the plane: measured in 3-D"
            ));
            planar = false;
            continue;
        }
        let m = measure(&ctx, opts, planar, (&shape, &rots), passes, &mut warnings);
        return Ok(assemble(ctx, opts, planar, &shape, m, warnings, t0));
    }
}

/// The warnings about the pilot cloud's shape: a forced plane that is not flat, a cloud
/// of fewer than two dimensions.
fn shape_warnings(shape: &plane::Shape, planar: bool, tol: f64) -> Vec<String> {
    let mut out = Vec::new();
    if planar && shape.off_plane > tol {
        out.push(format!(
            "the tool points are not planar (up to {:.3e} m off the best-fit plane): the area is that of their projection",
            shape.off_plane
        ));
    }
    if shape.dimension < 2 {
        out.push(format!(
            "the tool points span {} dimension(s): the measure is pure discretisation",
            shape.dimension
        ));
    }
    out
}

/// What the volume and Jacobian passes measured, before it is laid out as the result.
struct Measured {
    e: Estimate,
    samples: u64,
    per_replicate: u64,
    reached: Option<bool>,
    convergence: Vec<ConvergencePoint>,
    pooled_scan: grid::Scan,
    bbox: (Vec3, Vec3),
    outside: u64,
    bias: VoxelBias,
    jac: JacobianPass,
    dex_measure: f64,
    union: Vec<u64>,
    boundary_bits: Vec<u64>,
}

/// The estimate, the pooled occupancy and its boundary, the extent of the samples, the
/// voxel-bias block and the Jacobian pass, from the doublings; pushes their warnings.
fn measure(
    ctx: &Ctx,
    opts: &WorkspaceOptions,
    planar: bool,
    (shape, rots): (&plane::Shape, &[crate::core::spatial::Mat3]),
    passes: Doublings,
    warnings: &mut Vec<String>,
) -> Measured {
    let (cm, dims) = (ctx.est.cell_measure(), ctx.est.dims());
    let e = estimate::estimate(&passes.stages, cm, dims);
    let last = passes.stages.last().expect("one stage");
    let n = last.samples / opts.replicates as u64;
    warnings.extend(coverage_warnings(&e, opts, planar, passes.reached));
    let union = volume::common_union(ctx, &passes.reps);
    let pooled_scan = ctx.grid.scan(&union);
    let boundary_bits = ctx.grid.boundary_bits(&union);
    let mut lo = Vec3::repeat(f64::INFINITY);
    let mut hi = Vec3::repeat(f64::NEG_INFINITY);
    for rep in &passes.reps {
        let (a, b) = rep.marks.bounds();
        lo = lo.inf(&a);
        hi = hi.sup(&b);
    }
    let outside: u64 = passes.reps.iter().map(|r| r.marks.outside).sum();
    if outside > 0 {
        warnings.push(format!("{outside} samples fell outside the grid"));
    }
    drop(passes.reps);
    let bias = voxel_bias(&e, last, cm, dims, opts.voxel, planar);
    let samples = last.samples;
    let jac = jacobian_pass(
        ctx,
        opts,
        planar,
        shape,
        rots,
        n,
        samples,
        &union,
        &boundary_bits,
    );
    if let Some(w) = &jac.warning {
        warnings.push(w.clone());
    }
    let dex_measure = jac
        .summary
        .as_ref()
        .map_or(0.0, |s| s.dexterous_voxels as f64 * ctx.grid.cell_measure());
    Measured {
        e,
        samples,
        per_replicate: n,
        reached: passes.reached,
        convergence: passes.convergence,
        pooled_scan,
        bbox: (lo, hi),
        outside,
        bias,
        jac,
        dex_measure,
        union,
        boundary_bits,
    }
}

/// Lays out the result (volume or area fields by `planar`).
fn assemble(
    ctx: Ctx,
    opts: &WorkspaceOptions,
    planar: bool,
    shape: &plane::Shape,
    m: Measured,
    warnings: Vec<String>,
    t0: Instant,
) -> WorkspaceResult {
    let model = ctx.model;
    let e = m.e;
    let interval = Some(e.interval);
    let pl = &shape.plane;
    let dex = m.dex_measure;
    WorkspaceResult {
        robot: model.name.clone(),
        tool: model.links[ctx.tool].name.clone(),
        joint_names: model.dof_names(),
        sampling: opts.sampling,
        seed: opts.seed,
        replicates: opts.replicates,
        samples: m.samples,
        samples_per_replicate: m.per_replicate,
        voxel: opts.voxel,
        planar,
        cloud_dimension: shape.dimension,
        plane: planar.then(|| PlaneInfo {
            normal: pl.n.into(),
            offset: pl.o.dot(&pl.n),
            u: pl.u.into(),
            v: pl.v.into(),
        }),
        volume_m3: if planar { 0.0 } else { e.measure },
        volume_stderr: if planar { 0.0 } else { e.stderr },
        volume_interval_m3: if planar { None } else { interval },
        area_m2: planar.then_some(e.measure),
        area_stderr: planar.then_some(e.stderr),
        area_interval_m2: if planar { interval } else { None },
        interval_kind: e.kind,
        samples_needed: e.samples_needed,
        samples_per_voxel: e.samples_per_cell,
        target_rel_error: opts.target_rel_error,
        target_reached: m.reached,
        pooled: e.raw,
        bias: m.bias,
        convergence: m.convergence,
        occupied_voxels: m.pooled_scan.occupied,
        boundary_voxels: m.pooled_scan.boundary,
        bbox: [m.bbox.0.into(), m.bbox.1.into()],
        dexterous_volume_m3: if planar { 0.0 } else { dex },
        dexterous_area_m2: planar.then_some(dex),
        dexterous_interval: m.jac.summary.as_ref().map(|_| [Some(dex), e.interval[1]]),
        extras: m.jac.summary,
        outside_grid: m.outside,
        warnings,
        threads: rayon::current_num_threads(),
        time_s: t0.elapsed().as_secs_f64(),
        voxels: m.jac.voxels,
        points: m.jac.points,
        grid: ctx.grid,
        union: m.union,
        boundary_bits: m.boundary_bits,
        estimate: e,
    }
}

/// The grids and shared state of the passes: the common grid, the pooled estimation
/// grid (shifted by an offset drawn from the seed), the batched FK chain.
fn make_ctx<'a>(
    model: &'a Model,
    opts: &'a WorkspaceOptions,
    tool: usize,
    jb: &JointBox,
    chain: &crate::kinematics::fk_lanes::ToolChain,
    (center, radius): (Vec3, f64),
    plane_frame: Option<grid::PlaneFrame>,
) -> Result<Ctx<'a>, WorkspaceError> {
    let grid = Grid::new(opts.voxel, &center, radius, plane_frame, [0.0; 3]).map_err(|cells| {
        WorkspaceError::Invalid(format!(
            "a dense grid of {cells} cells of {} m around a reach of {radius:.3} m is too large (max {}): use a larger voxel",
            opts.voxel,
            grid::MAX_CELLS
        ))
    })?;
    let est = volume_context::shifted_grid(
        &grid,
        &center,
        radius,
        opts.seed,
        u64::MAX - 1,
        opts.shift_grid,
    );
    Ok(Ctx {
        model,
        tool,
        jb: jb.clone(),
        grid,
        est,
        sampling: opts.sampling,
        seed: opts.seed,
        shift: opts.shift_grid,
        center,
        radius,
        chain: chain.clone(),
        batched: opts.batched_fk,
        isa: Isa::at_most(opts.max_isa),
        stop: opts.stop.as_deref(),
    })
}

/// The warnings about coverage and the adaptive target.
fn coverage_warnings(
    e: &Estimate,
    opts: &WorkspaceOptions,
    planar: bool,
    reached: Option<bool>,
) -> Vec<String> {
    let unit = if planar { "m²" } else { "m³" };
    let mut out = Vec::new();
    if e.kind == IntervalKind::LowerBound {
        out.push(format!(
            "coverage has not converged ({:.1} % of the closed voxels unhit): the {} is only bounded below, by {:.4} {unit}; about {} samples (or a larger voxel) would give an interval",
            100.0 * e.unhit_fraction,
            if planar { "area" } else { "volume" },
            e.interval[0].unwrap_or(0.0),
            e.samples_needed.unwrap_or(0)
        ));
    }
    if reached == Some(false) {
        out.push(format!(
            "the target relative error {} was not reached within {} samples",
            opts.target_rel_error.unwrap_or(0.0),
            e.samples
        ));
    }
    out
}

/// The pilot cloud (4096 random samples through the scalar FK): its shape (planarity,
/// dimension), the tool rotations (for the in-plane tool axis), and the flatness
/// tolerance (1 nm per metre of reach).
fn pilot(
    model: &Model,
    opts: &WorkspaceOptions,
    jb: &JointBox,
    tool: usize,
    radius: f64,
) -> (plane::Shape, Vec<crate::core::spatial::Mat3>, f64) {
    let mut pilot = Vec::with_capacity(4096);
    let mut rots = Vec::with_capacity(4096);
    let mut data = crate::model::data::Data::new(model);
    let mut q = vec![0.0; model.nv];
    let mut s = RandomStream::new(opts.seed, u64::MAX, model.nv, 0);
    for _ in 0..4096 {
        s.next_q(jb, &mut q);
        crate::kinematics::forward_kinematics(model, &mut data, &q);
        let m = crate::kinematics::frame_placement(model, &data, tool);
        pilot.push(m.trans);
        rots.push(m.rot);
    }
    // Flat within 1 nm per metre of reach; a direction counts for the dimension beyond
    // 1 µm per metre.
    let tol = 1e-9 * (1.0 + radius);
    (plane::analyse(&pilot, 1e3 * tol), rots, tol)
}

/// What the doublings of the volume pass leave.
struct Doublings {
    stages: Vec<estimate::Stage>,
    convergence: Vec<ConvergencePoint>,
    /// Adaptive mode: whether the target was reached.
    reached: Option<bool>,
    reps: Vec<Replicate>,
}

/// Runs the volume pass doubling by doubling (`plan`: samples per replicate), with the
/// progress bar showing the estimate after each; in adaptive mode stops once the
/// target is met.
fn doublings(ctx: &Ctx, opts: &WorkspaceOptions, plan: &[u64], planar: bool) -> Doublings {
    let r = opts.replicates;
    let n_max = *plan.last().expect("one stage");
    let pb = progress::bar(n_max * r as u64, opts.quiet, "workspace");
    let mut reps: Vec<Replicate> = (0..r).map(|i| Replicate::new(ctx, i)).collect();
    let cm = ctx.est.cell_measure();
    let dims = ctx.est.dims();
    let unit = if planar { "m²" } else { "m³" };
    let mut stages = Vec::new();
    let mut convergence = Vec::new();
    let mut reached = None;
    for &n in plan {
        stages.push(volume::run_stage(ctx, &mut reps, n, &pb));
        if ctx.stopped() {
            break;
        }
        let e = estimate::estimate(&stages, cm, dims);
        convergence.push(convergence_point(&e, n));
        pb.set_message(match e.interval {
            [Some(lo), Some(hi)] => format!("{:.4} {unit} in [{lo:.4}, {hi:.4}]", e.measure),
            [lo, _] => format!("≥ {:.4} {unit} (lower bound)", lo.unwrap_or(0.0)),
        });
        if let Some(t) = opts.target_rel_error {
            let ok = e.kind == IntervalKind::Interval && e.rel_half_width() <= t;
            reached = Some(ok);
            if ok && n >= per_replicate(opts.samples, r).min(n_max) {
                break;
            }
        }
    }
    pb.finish_and_clear();
    Doublings {
        stages,
        convergence,
        reached,
        reps,
    }
}

/// One point of the convergence series: the estimate after `n` samples per replicate.
fn convergence_point(e: &Estimate, n: u64) -> ConvergencePoint {
    ConvergencePoint {
        samples: e.samples,
        samples_per_replicate: n,
        measure: e.measure,
        stderr: e.stderr,
        corrected: e.corrected,
        corrected_stderr: e.stderr,
        richardson: e.richardson,
        richardson_stderr: e.stderr,
        raw: e.raw,
        interval: e.interval,
    }
}

/// The voxel-bias block of the result.
fn voxel_bias(
    e: &Estimate,
    last: &estimate::Stage,
    cm: f64,
    dims: i32,
    h: f64,
    planar: bool,
) -> VoxelBias {
    let exposed = last.closed.exposed as f64;
    let second_order = (e.corrected - e.richardson).abs();
    VoxelBias {
        unit: if planar { "m2" } else { "m3" },
        exposed_faces: exposed,
        staircase_surface: exposed * h.powi(dims - 1),
        bias: e.voxel_bias,
        corrected: e.corrected,
        corrected_stderr: e.stderr,
        coarse: last.closed_coarse as f64 * cm * 2f64.powi(dims),
        richardson: e.richardson,
        richardson_stderr: e.stderr,
        undersampling: e.remaining,
        corrected_undersampling: e.remaining,
        second_order,
        uncertainty: second_order
            + e.remaining_bounds
                .map_or(f64::INFINITY, |[a, b]| 0.5 * (b - a)),
        interval: [
            e.interval[0].unwrap_or(0.0),
            e.interval[1].unwrap_or(f64::INFINITY),
        ],
        isolated_holes: last.closed.holes as f64,
    }
}
