//! Batches on `(N, nq)` arrays: RNEA, ABA, CRBA, gravity, FK, Jacobians and IK. Inputs are
//! checked under the GIL, then the rows run on rayon with the GIL released, one
//! workspace per chunk of rows (nothing allocated per row except IK's answers). RNEA,
//! ABA, CRBA and FK run eight rows at a time in SIMD lanes (`dynamics::rnea_lanes`,
//! `aba_lanes`, `crba_lanes`, `kinematics::pose_lanes`).

use crate::args::{self, rows};
use crate::convert::se3_from_4x4;
use crate::dyn_calls;
use crate::errors::err;
use crate::ik::{self, IkResult};
use crate::interrupt;
use crate::model::PyModel;
use armsim::{dynamics, kinematics, Data, FrameId, Model, Robot};
use numpy::{PyArray1, PyArrayDyn, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;

/// `n × width` zeros, or an error saying how much memory that is when it cannot be had
/// (a huge batch must raise in Python, not abort the interpreter).
pub(crate) fn zeros(n: usize, width: usize) -> Result<Vec<f64>, String> {
    let too_much = |len: f64| {
        format!(
            "a result of {n} rows × {width} values ({:.1} GiB) cannot be allocated",
            len * 8.0 / (1u64 << 30) as f64
        )
    };
    let len = n
        .checked_mul(width)
        .ok_or_else(|| too_much(n as f64 * width as f64))?;
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|_| too_much(len as f64))?;
    v.resize(len, 0.0);
    Ok(v)
}

pub(crate) fn shaped<'py>(
    py: Python<'py>,
    v: Vec<f64>,
    dims: &[usize],
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    PyArray1::from_vec(py, v).reshape(dims)
}

fn same_rows(what: &[(&str, usize)]) -> PyResult<usize> {
    let n = what[0].1;
    for (name, m) in &what[1..] {
        if *m != n {
            return Err(err(format!(
                "{name} has {m} rows but {} has {n}",
                what[0].0
            )));
        }
    }
    Ok(n)
}

/// Rows per rayon task of the lane batches (a multiple of the eight SIMD lanes; one
/// lane workspace per task).
const LANE_CHUNK: usize = 256;

/// A scalar dynamics call of `dyn_calls` (its error names the quantity and the joint).
type ScalarCall =
    for<'d> fn(&Model, &'d mut Data, &[f64], &[f64], &[f64]) -> Result<&'d [f64], String>;

/// Runs `rows(workspace, x, y, z, out)` (a lane driver: `dynamics::rnea_rows`,
/// `aba_rows`) over the `(n, nv)` inputs in chunks of [`LANE_CHUNK`] rows on rayon, one
/// workspace per task, Ctrl-C honoured between chunks; a row whose result is not finite
/// is redone by `scalar`, whose error names the row and the joint.
fn lane_batch<W>(
    py: Python<'_>,
    m: &Model,
    n: usize,
    (xs, ys, zs): (&[f64], &[f64], &[f64]),
    init: impl Fn() -> W + Sync + Send,
    rows: impl Fn(&mut W, &[f64], &[f64], &[f64], &mut [f64]) + Sync + Send,
    scalar: ScalarCall,
) -> PyResult<Vec<f64>> {
    let nv = m.nv;
    // Eight rows in lanes cost about one scalar row.
    let long = interrupt::is_long(m, n / 8, nv);
    interrupt::detached(py, long, |stop| {
        let mut out = zeros(n, nv)?;
        if nv == 0 {
            return Ok(out);
        }
        out.par_chunks_mut(nv * LANE_CHUNK)
            .enumerate()
            .try_for_each_init(&init, |w, (c, chunk)| {
                if interrupt::stopped(&stop) {
                    return Err(interrupt::CANCELLED.to_string());
                }
                let s = c * LANE_CHUNK * nv..c * LANE_CHUNK * nv + chunk.len();
                let ins = (&xs[s.clone()], &ys[s.clone()], &zs[s]);
                rows(w, ins.0, ins.1, ins.2, chunk);
                redo_non_finite(m, c * LANE_CHUNK, ins, chunk, scalar)
            })?;
        Ok::<_, String>(out)
    })?
    .map_err(err)
}

/// `τ` for every row of `(Q, V, A)`: an `(N, nv)` array. Eight rows at a time in SIMD
/// lanes (`dynamics::rnea_rows`; equal to `rnea` row by row to rounding).
#[pyfunction]
pub fn rnea_batch<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    a: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let m = &*model.model;
    let nv = m.nv;
    let (q, v, a) = (rows(q, "Q", nv)?, rows(v, "V", nv)?, rows(a, "A", nv)?);
    let n = same_rows(&[("Q", q.rows), ("V", v.rows), ("A", a.rows)])?;
    let out = lane_batch(
        py,
        m,
        n,
        (q.slice(), v.slice(), a.slice()),
        || dynamics::RneaLanes::new(m),
        |w, q, v, a, out| dynamics::rnea_rows(m, w, q, v, a, out),
        dyn_calls::rnea,
    )?;
    shaped(py, out, &[n, nv])
}

/// The rows of `out` (the first is row `r0` of the batch) holding a non-finite value,
/// redone by the scalar call: its error names the row and the joint.
fn redo_non_finite(
    m: &Model,
    r0: usize,
    (x, y, z): (&[f64], &[f64], &[f64]),
    out: &mut [f64],
    scalar: ScalarCall,
) -> Result<(), String> {
    let nv = m.nv;
    let Some(k) = out.iter().position(|v| !v.is_finite()) else {
        return Ok(());
    };
    let mut d = Data::new(m);
    for r in k / nv..out.len() / nv {
        let s = r * nv..(r + 1) * nv;
        if out[s.clone()].iter().all(|v| v.is_finite()) {
            continue;
        }
        let res = scalar(m, &mut d, &x[s.clone()], &y[s.clone()], &z[s.clone()])
            .map_err(|e| format!("row {}: {e}", r0 + r))?;
        out[s].copy_from_slice(res);
    }
    Ok(())
}

/// `q̈` for every row of `(Q, V, TAU)`: an `(N, nv)` array. Eight rows at a time in
/// SIMD lanes (`dynamics::aba_rows`); with mimic joints row by row through the projected
/// mass matrix, as `aba`.
#[pyfunction]
pub fn aba_batch<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    tau: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let m = &*model.model;
    let nv = m.nv;
    let (q, v, t) = (rows(q, "Q", nv)?, rows(v, "V", nv)?, rows(tau, "TAU", nv)?);
    let n = same_rows(&[("Q", q.rows), ("V", v.rows), ("TAU", t.rows)])?;
    let (qs, vs, ts) = (q.slice(), v.slice(), t.slice());
    let out = if m.has_mimic {
        interrupt::batch_rows(py, m, n, nv, |d, i, row| {
            let s = i * nv..(i + 1) * nv;
            let ddq = dyn_calls::aba(m, d, &qs[s.clone()], &vs[s.clone()], &ts[s])
                .map_err(|e| format!("row {i}: {e}"))?;
            row.copy_from_slice(ddq);
            Ok(())
        })?
    } else {
        lane_batch(
            py,
            m,
            n,
            (qs, vs, ts),
            || dynamics::AbaLanes::new(m),
            |w, q, v, t, out| dynamics::aba_rows(m, w, q, v, t, out),
            dyn_calls::aba,
        )?
    };
    shaped(py, out, &[n, nv])
}

/// `M(q)` for every row of `Q`: an `(N, nv, nv)` array (each matrix symmetric, the
/// model's armature on the diagonal, as `crba`). Eight rows at a time in SIMD lanes
/// (`dynamics::crba_rows`; equal to `crba` row by row to rounding), in chunks of
/// [`LANE_CHUNK`] rows on rayon, Ctrl-C honoured between chunks.
#[pyfunction]
pub fn crba_batch<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let m = &*model.model;
    let (nv, nn) = (m.nv, m.nv * m.nv);
    let q = rows(q, "Q", nv)?;
    let (n, qs) = (q.rows, q.slice());
    // Eight rows in lanes cost about one scalar row.
    let long = interrupt::is_long(m, n / 8, nn);
    let out = interrupt::detached(py, long, |stop| {
        let mut out = zeros(n, nn)?;
        if nn == 0 {
            return Ok(out);
        }
        out.par_chunks_mut(nn * LANE_CHUNK)
            .enumerate()
            .try_for_each_init(
                || dynamics::CrbaLanes::new(m),
                |w, (c, chunk)| {
                    if interrupt::stopped(&stop) {
                        return Err(interrupt::CANCELLED.to_string());
                    }
                    let r0 = c * LANE_CHUNK;
                    dynamics::crba_rows(m, w, &qs[r0 * nv..r0 * nv + chunk.len() / nn * nv], chunk);
                    Ok(())
                },
            )?;
        Ok::<_, String>(out)
    })?
    .map_err(err)?;
    shaped(py, out, &[n, nv, nv])
}

/// `g(q)` for every row of `Q`: an `(N, nv)` array.
#[pyfunction]
pub fn gravity_batch<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let m = &*model.model;
    let nv = m.nv;
    let q = rows(q, "Q", nv)?;
    let (n, qs) = (q.rows, q.slice());
    let out = interrupt::batch_rows(py, m, n, nv, |d, i, row| {
        let g = dyn_calls::gravity(m, d, &qs[i * nv..(i + 1) * nv])
            .map_err(|e| format!("row {i}: {e}"))?;
        row.copy_from_slice(g);
        Ok(())
    })?;
    shaped(py, out, &[n, nv])
}

/// The world placement of `frame` for every row of `Q`: an `(N, 4, 4)` array. Eight rows at
/// a time in SIMD lanes over the frame's support chain (`kinematics::pose_lanes`; equal to
/// `forward_kinematics` + the frame placement row by row to rounding).
#[pyfunction]
pub fn fk_batch<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: &Bound<'py, PyAny>,
    frame: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    use kinematics::pose_lanes::{PoseLanes, POSE_VALUES};
    let m = &*model.model;
    let nv = m.nv;
    let f = args::frame(m, frame)?;
    let q = rows(q, "Q", nv)?;
    let (n, qs) = (q.rows, q.slice());
    // Eight rows in lanes cost about one scalar row.
    let long = interrupt::is_long(m, n / 8, POSE_VALUES);
    let out = interrupt::detached(py, long, |stop| {
        let mut out = zeros(n, POSE_VALUES)?;
        out.par_chunks_mut(POSE_VALUES * LANE_CHUNK)
            .enumerate()
            .try_for_each_init(
                || PoseLanes::new(m, f),
                |w, (c, chunk)| {
                    if interrupt::stopped(&stop) {
                        return Err(interrupt::CANCELLED.to_string());
                    }
                    let r0 = c * LANE_CHUNK;
                    let rows = chunk.len() / POSE_VALUES;
                    w.frame_poses(m, &qs[r0 * nv..(r0 + rows) * nv], chunk);
                    Ok(())
                },
            )?;
        Ok::<_, String>(out)
    })?
    .map_err(err)?;
    shaped(py, out, &[n, 4, 4])
}

/// The Jacobian of `frame` for every row of `Q`: an `(N, 6, nv)` array.
#[pyfunction]
#[pyo3(signature = (model, q, frame, reference="world_aligned"))]
pub fn jacobian_batch<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: &Bound<'py, PyAny>,
    frame: &Bound<'py, PyAny>,
    reference: &str,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let m = &*model.model;
    let nv = m.nv;
    let f = args::frame(m, frame)?;
    let e = args::expressed(reference)?;
    let q = rows(q, "Q", nv)?;
    let (n, qs) = (q.rows, q.slice());
    let out = interrupt::batch_rows(py, m, n, 6 * nv, |d, i, row| {
        kinematics::compute_frame_jacobian(m, d, &qs[i * nv..(i + 1) * nv], f, e, row);
        Ok(())
    })?;
    shaped(py, out, &[n, 6, nv])
}

/// IK for every target `(N, 4, 4)`; target `i` uses seed `seed + start + i`, so any
/// split of the targets into shards (`start` = the shard's first index) gives the same
/// answers. Returns a dict of arrays: `q (N, nv)`, `status`, `position_error`,
/// `rotation_error`, `iterations`, `reason`.
#[pyfunction]
#[pyo3(signature = (model, frame, targets, q0=None, start=args::Int::Fits(0), **kwargs), text_signature = "(model, frame, targets, q0=None, start=0, **kwargs)")]
pub fn ik_batch<'py>(
    py: Python<'py>,
    model: &PyModel,
    frame: &Bound<'py, PyAny>,
    targets: &Bound<'py, PyAny>,
    q0: Option<&Bound<'py, PyAny>>,
    start: args::Int,
    kwargs: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let start = args::seed(start, "start")?;
    let m = &*model.model;
    let f = args::frame(m, frame)?;
    let opts = ik::options(kwargs)?;
    let targets = args::poses(targets, "targets")?;
    let q0 = q0.map(|q| rows(q, "q0", m.nv)).transpose()?;
    if let Some(q0) = &q0 {
        same_rows(&[("targets", targets.len()), ("q0", q0.rows)])?;
    }
    let q0s = q0.as_ref().map(|r| r.slice());
    let sols = interrupt::interruptible(py, |stop| {
        targets
            .par_chunks(4)
            .enumerate()
            .flat_map_iter(|(c, chunk)| {
                let mut robot = Robot::from_model(m.clone());
                let mut o = opts.clone();
                let out: Vec<_> = chunk
                    .iter()
                    .enumerate()
                    .map(|(k, t)| {
                        if interrupt::stopped(&stop) {
                            return Err(interrupt::CANCELLED.to_string());
                        }
                        let i = c * 4 + k;
                        o.seed = opts.seed.wrapping_add(start).wrapping_add(i as u64);
                        let seed = q0s.map(|s| &s[i * m.nv..(i + 1) * m.nv]);
                        robot
                            .ik_from(FrameId(f), &se3_from_4x4(t), seed, &o)
                            .map_err(|e| e.to_string())
                    })
                    .collect();
                out
            })
            .collect::<Result<Vec<_>, _>>()
    })?;
    let sols = sols.map_err(err)?;
    let n = sols.len();
    let mut q = Vec::with_capacity(n * m.nv);
    let d = PyDict::new(py);
    let res: Vec<IkResult> = sols
        .into_iter()
        .map(|s| {
            q.extend_from_slice(&s.q);
            IkResult::new(py, s)
        })
        .collect();
    d.set_item("q", shaped(py, q, &[n, m.nv])?)?;
    d.set_item("status", PyList::new(py, res.iter().map(|r| r.status))?)?;
    let col = |g: fn(&IkResult) -> f64| PyArray1::from_vec(py, res.iter().map(g).collect());
    d.set_item("position_error", col(|r| r.position_error))?;
    d.set_item("rotation_error", col(|r| r.rotation_error))?;
    d.set_item(
        "iterations",
        PyArray1::from_vec(py, res.iter().map(|r| r.iterations as u64).collect()),
    )?;
    d.set_item(
        "reason",
        PyList::new(py, res.iter().map(|r| r.reason.clone()))?,
    )?;
    Ok(d)
}
