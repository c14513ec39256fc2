//! The Jacobian pass: for each of its samples, the world-aligned Jacobian of the tool
//! frame, the translational manipulability and condition number, and the bin of the tool
//! orientation; per voxel the mean/min/max of both measures and the set of distinct
//! orientation bins, which defines the dexterous sub-workspace.
//!
//! Measures use the translational rows `J_v` (3 × nv) of the world-aligned Jacobian (the
//! velocity of the tool point in world axes), whose units are consistent:
//! `σ₁ ≥ σ₂ ≥ …` its singular values (from the eigenvalues of `J_v J_vᵀ`, no allocation),
//! `m = min(3, nv)` — or, for a planar workspace, those of the in-plane rows
//! `[uᵀ; vᵀ] J_v` with `m = min(2, nv)`; manipulability `w = σ₁ ⋯ σ_m` (Yoshikawa's
//! `√det(J Jᵀ)` for `nv ≥ m`), condition number `κ = σ₁ / σ_m` (∞ at a singularity).
//!
//! Orientation bins: in 3-D the tool z axis on an equal-angle cube map (`6 k²` cells of
//! roughly equal solid angle); in a plane the angle of the tool axis that lies in the
//! plane, in equal arcs. A voxel is *dexterous* when its samples reach at least
//! `⌈fraction × bins⌉` distinct bins.
//!
//! The samples are the first ones of replicates 0, 1, … of the volume pass, in order, so
//! every one lands in an occupied voxel. Work is cut into fixed chunks computed in
//! parallel and merged in chunk order: the result does not depend on the thread count.

use crate::core::spatial::{Mat3, Vec3};
use crate::kinematics::{compute_joint_jacobians, frame_jacobian, frame_placement, Expressed};
use crate::model::data::Data;
use crate::workspace::grid::{Grid, PlaneFrame};
use crate::workspace::result::{ExtrasSummary, SamplePoint, VoxelStats};
use crate::workspace::sample_stream::{QStream, RandomStream, SobolStream};
use crate::workspace::volume_context::Ctx;
use crate::workspace::workspace_options::{Sampling, WorkspaceOptions};
use indicatif::ProgressBar;
use nalgebra::DMatrix;
use rayon::prelude::*;
use std::collections::HashMap;

/// Samples per chunk.
const CHUNK: u64 = 1 << 13;

/// How tool orientations are binned.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Bins {
    /// Tool z axis, `k × k` cells per cube face.
    Sphere { k: usize },
    /// Angle of tool axis `axis` in the plane, `bins` arcs.
    Circle {
        bins: usize,
        axis: usize,
        plane: PlaneFrame,
    },
}

impl Bins {
    /// Number of bins.
    pub fn count(&self) -> usize {
        match self {
            Bins::Sphere { k } => 6 * k * k,
            Bins::Circle { bins, .. } => *bins,
        }
    }

    /// Bin of tool rotation `rot`.
    #[inline]
    pub fn bin(&self, rot: &Mat3) -> usize {
        match *self {
            Bins::Sphere { k } => {
                let d = rot.column(2);
                let (ax, ay, az) = (d.x.abs(), d.y.abs(), d.z.abs());
                let (face, a, b, m) = if ax >= ay && ax >= az {
                    (usize::from(d.x < 0.0), d.y, d.z, ax)
                } else if ay >= az {
                    (2 + usize::from(d.y < 0.0), d.z, d.x, ay)
                } else {
                    (4 + usize::from(d.z < 0.0), d.x, d.y, az)
                };
                let cell = |t: f64| {
                    let s = (t / m).atan() / std::f64::consts::FRAC_PI_2 + 0.5;
                    ((s * k as f64) as usize).min(k - 1)
                };
                face * k * k + cell(a) * k + cell(b)
            }
            Bins::Circle { bins, axis, plane } => {
                let a = rot.column(axis);
                let t = a.dot(&plane.v).atan2(a.dot(&plane.u));
                let s = t / std::f64::consts::TAU + 0.5;
                ((s * bins as f64) as usize).min(bins - 1)
            }
        }
    }
}

/// Translational manipulability and condition number from the top three rows of a
/// 6 × nv Jacobian (see the module docs).
pub(crate) fn measures(jac: &DMatrix<f64>, plane: Option<&PlaneFrame>) -> (f64, f64) {
    let nv = jac.ncols();
    let sigma = |lam: &[f64]| -> (f64, f64) {
        let mut w = 1.0;
        for &l in lam {
            w *= l.max(0.0).sqrt();
        }
        let (max, min) = (lam[0].max(0.0).sqrt(), lam[lam.len() - 1].max(0.0).sqrt());
        let k = if min <= max * f64::EPSILON {
            f64::INFINITY
        } else {
            max / min
        };
        (w, k)
    };
    match plane {
        Some(pl) => {
            let (mut a, mut b, mut d) = (0.0, 0.0, 0.0);
            for c in 0..nv {
                let col = Vec3::new(jac[(0, c)], jac[(1, c)], jac[(2, c)]);
                let (x, y) = (col.dot(&pl.u), col.dot(&pl.v));
                a += x * x;
                b += x * y;
                d += y * y;
            }
            let half_t = 0.5 * (a + d);
            let disc = (0.25 * (a - d) * (a - d) + b * b).sqrt();
            let l1 = half_t + disc;
            // The small eigenvalue from the determinant: no cancellation.
            let l2 = if l1 > 0.0 { (a * d - b * b) / l1 } else { 0.0 };
            let lam = [l1, l2];
            sigma(&lam[..nv.clamp(1, 2)])
        }
        None => {
            let mut m = Mat3::zeros();
            for c in 0..nv {
                let col = Vec3::new(jac[(0, c)], jac[(1, c)], jac[(2, c)]);
                m += col * col.transpose();
            }
            let e = m.symmetric_eigenvalues();
            let mut lam = [e[0], e[1], e[2]];
            lam.sort_by(|x, y| y.total_cmp(x));
            sigma(&lam[..nv.clamp(1, 3)])
        }
    }
}

/// One sample's record.
#[derive(Clone, Copy, Debug)]
struct Record {
    cell: usize,
    bin: u8,
    w: f64,
    k: f64,
}

#[derive(Clone, Copy, Debug)]
struct Acc {
    n: u32,
    w_sum: f64,
    w_min: f64,
    w_max: f64,
    k_sum: f64,
    k_min: f64,
    k_max: f64,
    bins: u128,
}

impl Acc {
    fn new() -> Self {
        Acc {
            n: 0,
            w_sum: 0.0,
            w_min: f64::INFINITY,
            w_max: 0.0,
            k_sum: 0.0,
            k_min: f64::INFINITY,
            k_max: 0.0,
            bins: 0,
        }
    }
}

/// Output of the Jacobian pass.
pub(crate) struct Extras {
    pub voxels: Vec<VoxelStats>,
    pub points: Vec<SamplePoint>,
    pub samples: u64,
    /// Samples that fell outside the pooled occupancy (should be 0).
    pub strays: u64,
    pub w_mean: f64,
    pub w_max: f64,
    pub k_min: f64,
}

/// One chunk: `len` samples of replicate `r` from sample `start`; the first `keep` are
/// also returned as points.
fn chunk<S: QStream>(
    ctx: &Ctx,
    bins: &Bins,
    mut stream: S,
    len: u64,
    keep: u64,
) -> (Vec<Record>, Vec<SamplePoint>) {
    let model = ctx.model;
    let plane = ctx.grid.plane.as_ref();
    let mut data = Data::new(model);
    let mut jac = DMatrix::zeros(6, model.nv);
    let mut q = vec![0.0; model.nv];
    let mut out = Vec::with_capacity(len as usize);
    let mut kept = Vec::with_capacity(keep as usize);
    for i in 0..len {
        stream.next_q(&ctx.jb, &mut q);
        compute_joint_jacobians(model, &mut data, &q);
        frame_jacobian(model, &data, ctx.tool, Expressed::WorldAligned, &mut jac);
        let pose = frame_placement(model, &data, ctx.tool);
        let (c, _) = ctx.grid.coords(&pose.trans);
        let (w, k) = measures(&jac, plane);
        if i < keep {
            kept.push(SamplePoint {
                q: q.clone(),
                p: [pose.trans.x, pose.trans.y, pose.trans.z],
                manipulability: w,
                condition: k,
            });
        }
        out.push(Record {
            cell: ctx.grid.locate(&c).unwrap_or(usize::MAX),
            bin: bins.bin(&pose.rot) as u8,
            w,
            k,
        });
    }
    (out, kept)
}

/// The pass's fixed chunks, never across a replicate: `(replicate, start, length, points
/// to keep)` covering the first `total` samples of replicates 0, 1, … (`per_rep` each),
/// the first `keep` kept as points.
fn chunks(total: u64, per_rep: u64, keep: u64) -> Vec<(u64, u64, u64, u64)> {
    let mut jobs = Vec::new();
    let mut g = 0u64;
    'outer: for r in 0.. {
        let mut s = 0;
        while s < per_rep {
            if g >= total {
                break 'outer;
            }
            let len = CHUNK.min(per_rep - s).min(total - g);
            jobs.push((r as u64, s, len, keep.saturating_sub(g).min(len)));
            s += len;
            g += len;
        }
    }
    jobs
}

/// Runs the pass over `total` samples (`per_rep` per replicate), keeping the first
/// `keep` as points; `union` and `boundary` are the pooled occupancy and its boundary
/// cells; `threshold` distinct bins make a voxel dexterous.
#[allow(clippy::too_many_arguments)]
pub(crate) fn run(
    ctx: &Ctx,
    bins: &Bins,
    total: u64,
    per_rep: u64,
    keep: u64,
    union: &[u64],
    boundary: &[u64],
    threshold: usize,
    pb: &ProgressBar,
) -> Extras {
    let jobs = chunks(total, per_rep, keep);
    let g: u64 = jobs.iter().map(|j| j.2).sum();
    let d = ctx.model.nv;
    let mut acc: HashMap<usize, Acc> = HashMap::new();
    let mut points = Vec::new();
    let mut strays = 0u64;
    let (mut w_sum, mut w_max, mut k_min) = (0.0, 0.0f64, f64::INFINITY);
    let wave = 4 * rayon::current_num_threads().max(1);
    for batch in jobs.chunks(wave) {
        let results: Vec<(Vec<Record>, Vec<SamplePoint>)> = batch
            .par_iter()
            .map(|&(r, s, len, kp)| {
                let out = match ctx.sampling {
                    Sampling::Random => {
                        chunk(ctx, bins, RandomStream::new(ctx.seed, r, d, s), len, kp)
                    }
                    Sampling::Sobol => {
                        chunk(ctx, bins, SobolStream::new(ctx.seed, r, d, s), len, kp)
                    }
                };
                pb.inc(len);
                out
            })
            .collect();
        for (recs, kept) in results {
            points.extend(kept);
            for rec in recs {
                if rec.cell == usize::MAX || !Grid::test(union, rec.cell) {
                    strays += 1;
                    continue;
                }
                w_sum += rec.w;
                w_max = w_max.max(rec.w);
                k_min = k_min.min(rec.k);
                let a = acc.entry(rec.cell).or_insert_with(Acc::new);
                a.n += 1;
                a.w_sum += rec.w;
                a.w_min = a.w_min.min(rec.w);
                a.w_max = a.w_max.max(rec.w);
                a.k_sum += rec.k;
                a.k_min = a.k_min.min(rec.k);
                a.k_max = a.k_max.max(rec.k);
                a.bins |= 1u128 << rec.bin;
            }
        }
    }
    let mut cells: Vec<usize> = acc.keys().copied().collect();
    cells.sort_unstable();
    let voxels = cells
        .into_iter()
        .map(|cell| {
            let a = &acc[&cell];
            let n = a.n as f64;
            let c = ctx.grid.center(cell);
            let orientations = a.bins.count_ones();
            VoxelStats {
                index: ctx.grid.global(cell),
                center: [c.x, c.y, c.z],
                boundary: Grid::test(boundary, cell),
                samples: a.n,
                manipulability_mean: a.w_sum / n,
                manipulability_min: a.w_min,
                manipulability_max: a.w_max,
                condition_mean: a.k_sum / n,
                condition_min: a.k_min,
                condition_max: a.k_max,
                orientations,
                dexterous: orientations as usize >= threshold,
            }
        })
        .collect();
    let counted = g - strays;
    Extras {
        voxels,
        points,
        samples: g,
        strays,
        w_mean: if counted > 0 {
            w_sum / counted as f64
        } else {
            0.0
        },
        w_max,
        k_min,
    }
}

/// What the Jacobian pass adds to the result.
pub(super) struct JacobianPass {
    pub voxels: Vec<VoxelStats>,
    pub points: Vec<SamplePoint>,
    pub summary: Option<ExtrasSummary>,
    pub warning: Option<String>,
}

/// The Jacobian pass (manipulability, condition, dexterity, kept points), when asked for.
#[allow(clippy::too_many_arguments)]
pub(super) fn jacobian_pass(
    ctx: &Ctx,
    opts: &WorkspaceOptions,
    planar: bool,
    shape: &crate::workspace::plane::Shape,
    rots: &[Mat3],
    per_rep: u64,
    total: u64,
    union: &[u64],
    boundary_bits: &[u64],
) -> JacobianPass {
    let m_extras = if opts.extras {
        opts.extras_samples.unwrap_or(1 << 20).min(total)
    } else {
        0
    };
    let keep = (opts.keep_points as u64).min(total);
    let mut out = JacobianPass {
        voxels: Vec::new(),
        points: Vec::new(),
        summary: None,
        warning: None,
    };
    if m_extras.max(keep) == 0 {
        return out;
    }
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
        Bins::Circle {
            bins: opts.circle_bins,
            axis,
            plane: shape.plane,
        }
    } else {
        Bins::Sphere {
            k: opts.sphere_cells,
        }
    };
    let threshold = ((opts.dexterous_fraction * bins.count() as f64).ceil() as usize).max(1);
    let pb = crate::workspace::progress::bar(m_extras.max(keep), opts.quiet, "jacobians");
    let ex = run(
        ctx,
        &bins,
        m_extras.max(keep),
        per_rep,
        keep,
        union,
        boundary_bits,
        threshold,
        &pb,
    );
    pb.finish_and_clear();
    if ex.strays > 0 {
        out.warning = Some(format!(
            "{} Jacobian-pass samples fell outside the occupied voxels",
            ex.strays
        ));
    }
    out.points = ex.points;
    if opts.extras {
        let dex = ex.voxels.iter().filter(|v| v.dexterous).count() as u64;
        out.summary = Some(ExtrasSummary {
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
        });
        out.voxels = ex.voxels;
    }
    out
}
