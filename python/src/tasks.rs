//! Whole jobs: running a scenario file to its report, workspace sampling (the estimate
//! with its interval, and kept points), and counter-based configuration sampling whose
//! sample `i` depends only on `(seed, i)`, so shards by index range reproduce one run.

use crate::args;
use crate::batch::shaped;
use crate::convert::se3_to_4x4;
use crate::errors::{err, require_file};
use crate::interrupt;
use crate::model::PyModel;
use armsim::workspace::{sample_workspace, Sampling, WorkspaceOptions};
use armsim::{kinematics, Data};
use numpy::{PyArray1, PyArrayDyn};
use pyo3::prelude::*;
use rayon::prelude::*;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

/// Runs a scenario file; returns the report's JSON text (`armsim run --json`). Ctrl-C
/// cancels it ([`interrupt::interruptible`]): KeyboardInterrupt, no file written.
#[pyfunction]
#[pyo3(signature = (path, out_dir=None, write_files=true))]
pub fn run_scenario_json(
    py: Python<'_>,
    path: PathBuf,
    out_dir: Option<PathBuf>,
    write_files: bool,
) -> PyResult<String> {
    require_file(&path)?;
    // Ctrl-C cancels the run: KeyboardInterrupt, and no output file is written.
    let report = interrupt::interruptible(py, |stop| {
        let opts = armsim::scenarios::arm::RunOptions {
            out_dir,
            write_files,
            stop: Some(stop),
            on_stop: armsim::scenarios::OnStop::Cancel,
            ..Default::default()
        };
        armsim::scenarios::run_file_with(&path, &opts)
    })?
    .map_err(err)?;
    serde_json::to_string(&report.json).map_err(err)
}

type WorkspaceOut<'py> = (
    String,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArray1<f64>>,
);

/// Samples the reachable workspace; returns the result's JSON text and the kept points
/// `(k, 3)`, their configurations `(k, nv)` and manipulabilities `(k,)`.
#[pyfunction]
#[pyo3(signature = (model, samples=args::Int::Fits(1<<16), seed=args::Int::Fits(0), voxel=0.02, tool=None, sampling="sobol", replicates=args::Int::Fits(8), planar=None, extras=true, keep_points=args::Int::Fits(1000), target_rel_error=None), text_signature = "(model, samples=65536, seed=0, voxel=0.02, tool=None, sampling='sobol', replicates=8, planar=None, extras=True, keep_points=1000, target_rel_error=None)")]
#[allow(clippy::too_many_arguments)]
pub fn workspace_json<'py>(
    py: Python<'py>,
    model: &PyModel,
    samples: args::Int,
    seed: args::Int,
    voxel: f64,
    tool: Option<String>,
    sampling: &str,
    replicates: args::Int,
    planar: Option<bool>,
    extras: bool,
    keep_points: args::Int,
    target_rel_error: Option<f64>,
) -> PyResult<WorkspaceOut<'py>> {
    let samples = args::seed(samples, "samples")?;
    let seed = args::seed(seed, "seed")?;
    let replicates = args::size(replicates, "replicates")?;
    let keep_points = args::size(keep_points, "keep_points")?;
    if !(voxel.is_finite() && voxel > 0.0) {
        return Err(err(format!(
            "workspace: voxel {voxel} is not a positive length"
        )));
    }
    if samples == 0 || replicates < 2 {
        return Err(err(format!(
            "workspace: samples must be positive and replicates at least 2 (for the \
             standard error), got samples = {samples}, replicates = {replicates}"
        )));
    }
    let opts = WorkspaceOptions {
        samples,
        seed,
        voxel,
        tool,
        sampling: sampling.parse::<Sampling>().map_err(err)?,
        replicates,
        planar,
        extras: extras || keep_points > 0,
        keep_points,
        target_rel_error,
        quiet: true,
        ..Default::default()
    };
    let m = &*model.model;
    // Interruptible (Ctrl-C) above a few milliseconds of sampling.
    let long = interrupt::is_long(m, samples.try_into().unwrap_or(usize::MAX), 1);
    let r = interrupt::detached(py, long, |stop| {
        let opts = WorkspaceOptions {
            stop: Some(stop),
            ..opts
        };
        sample_workspace(m, &opts)
    })?
    .map_err(err)?;
    let json = serde_json::to_string(&r).map_err(err)?;
    let k = r.points.len();
    let pts: Vec<f64> = r.points.iter().flat_map(|p| p.p).collect();
    let qs: Vec<f64> = r.points.iter().flat_map(|p| p.q.iter().copied()).collect();
    let man: Vec<f64> = r.points.iter().map(|p| p.manipulability).collect();
    Ok((
        json,
        shaped(py, pts, &[k, 3])?,
        shaped(py, qs, &[k, m.nv])?,
        PyArray1::from_vec(py, man),
    ))
}

/// Two arrays (configurations and poses).
type Pair<'py> = (Bound<'py, PyArrayDyn<f64>>, Bound<'py, PyArrayDyn<f64>>);

fn splitmix(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Uniform configurations `start .. start + n` of the stream `seed` inside the sampling
/// box (joint limits; ±π for unlimited revolute joints), and the world placement of
/// `frame` (default: the tool link) at each: `(q (n, nv), poses (n, 4, 4))`.
#[pyfunction]
#[pyo3(signature = (model, n, seed=args::Int::Fits(0), frame=None, start=args::Int::Fits(0)), text_signature = "(model, n, seed=0, frame=None, start=0)")]
pub fn sample_poses<'py>(
    py: Python<'py>,
    model: &PyModel,
    n: args::Int,
    seed: args::Int,
    frame: Option<&Bound<'py, PyAny>>,
    start: args::Int,
) -> PyResult<Pair<'py>> {
    let n = args::size(n, "n")?;
    let (seed, start) = (args::seed(seed, "seed")?, args::seed(start, "start")?);
    let m = &*model.model;
    let nv = m.nv;
    let f = match frame {
        None => m.tool_link(),
        Some(f) => args::frame(m, f)?,
    };
    let mut qs = crate::batch::zeros(n, nv).map_err(|m| err(format!("sample_poses: {m}")))?;
    let mut poses = crate::batch::zeros(n, 16).map_err(|m| err(format!("sample_poses: {m}")))?;
    interrupt::detached(py, interrupt::is_long(m, n, nv + 16), |stop| {
        fill_samples(m, f, (splitmix(seed), start), &mut qs, &mut poses, &stop)
    })?
    .map_err(err)?;
    Ok((shaped(py, qs, &[n, nv])?, shaped(py, poses, &[n, 4, 4])?))
}

/// Fills `qs` (rows of `nv`) with the configurations `start ..` of the stream `key` and
/// `poses` with `frame`'s placement at each, in chunks that stop once `stop` is raised.
fn fill_samples(
    m: &armsim::Model,
    frame: usize,
    (key, start): (u64, u64),
    qs: &mut [f64],
    poses: &mut [f64],
    stop: &AtomicBool,
) -> Result<(), String> {
    const CH: usize = 256;
    let nv = m.nv;
    let bounds: Vec<(f64, f64)> = (0..nv).map(|k| m.sampling_bounds(k)).collect();
    qs.par_chunks_mut((nv * CH).max(1))
        .zip(poses.par_chunks_mut(16 * CH))
        .enumerate()
        .try_for_each(|(c, (qc, pc))| {
            if interrupt::stopped(stop) {
                return Err(interrupt::CANCELLED.to_string());
            }
            let mut d = Data::new(m);
            for (r, pose) in pc.chunks_mut(16).enumerate() {
                let i = start.wrapping_add((c * CH + r) as u64);
                let q = &mut qc[r * nv..(r + 1) * nv];
                for (k, x) in q.iter_mut().enumerate() {
                    let at = i.wrapping_mul(nv as u64).wrapping_add(k as u64);
                    let u = (splitmix(key ^ at) >> 11) as f64 * (1.0 / (1u64 << 53) as f64);
                    *x = bounds[k].0 + u * (bounds[k].1 - bounds[k].0);
                }
                kinematics::forward_kinematics(m, &mut d, q);
                se3_to_4x4(&kinematics::frame_placement(m, &d, frame), pose);
            }
            Ok(())
        })
}
