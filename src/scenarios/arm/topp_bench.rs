//! Hidden benchmark hook of the TOPP stage (`tools/bench_topp.py`). With the environment
//! variable `ARMSIM_TOPP_DUMP=FILE.json`, every planned piece timed by TOPP is also
//!
//! - re-timed `ARMSIM_TOPP_REPS` times (default 21) with the options it was timed with
//!   (reachability), with the torque limits left out, and 3 times with the conic solver
//!   (wall time and the thread's CPU time of each call);
//! - written to `FILE.json` with the grid `s_i`, the path `q, q', q''` at the grid points,
//!   the limits, the durations and the wall times of each repetition,
//!
//! so that another TOPP implementation (toppra) can be timed on exactly the same pieces,
//! grid and limits. Without the variable nothing happens.

use crate::dynamics::Effects;
use crate::model::Model;
use crate::motion::topp;
use crate::motion::{JointLimits, Path, ToppMethod, ToppOptions, ToppTrajectory, Trajectory};
use serde_json::{json, Value};
use std::sync::Mutex;
use std::time::Instant;

/// Pieces recorded so far in this process.
static PIECES: Mutex<Vec<Value>> = Mutex::new(Vec::new());

/// CPU time of the calling thread (s), from `/proc/thread-self/schedstat` (Linux; `NaN`
/// elsewhere).
fn thread_cpu_s() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|t| t.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(f64::NAN, |ns| ns * 1e-9)
}

/// Times of `reps` calls of [`topp`] (wall and thread CPU, s) and the duration of the last.
struct Timed {
    wall: Vec<f64>,
    cpu: Vec<f64>,
    duration: f64,
}

fn time_it<P: Path + Clone>(
    model: &Model,
    path: &P,
    limits: &JointLimits,
    effects: &Effects,
    opts: &ToppOptions,
    reps: usize,
) -> Timed {
    let mut out = Timed {
        wall: Vec::with_capacity(reps),
        cpu: Vec::with_capacity(reps),
        duration: f64::NAN,
    };
    for _ in 0..reps {
        let (start, cpu) = (Instant::now(), thread_cpu_s());
        let r = topp(model, path.clone(), limits, effects, opts);
        out.cpu.push(thread_cpu_s() - cpu);
        out.wall.push(start.elapsed().as_secs_f64());
        out.duration = r.map_or(f64::NAN, |t| t.duration());
    }
    out
}

/// Records a planned piece (see the module docs) when `ARMSIM_TOPP_DUMP` is set.
pub(super) fn record<P: Path + Clone>(
    model: &Model,
    path: &P,
    limits: &JointLimits,
    effects: &Effects,
    opts: &ToppOptions,
    timed: &ToppTrajectory<P>,
) {
    let Ok(file) = std::env::var("ARMSIM_TOPP_DUMP") else {
        return;
    };
    let reps = std::env::var("ARMSIM_TOPP_REPS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(21usize)
        .max(1);
    let n = model.nv;
    let (s, _, _) = timed.profile();
    let (mut q, mut dq, mut ddq) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut rows = [Vec::new(), Vec::new(), Vec::new()];
    for &si in &s {
        path.eval(si, &mut q, &mut dq, &mut ddq);
        rows[0].push(q.clone());
        rows[1].push(dq.clone());
        rows[2].push(ddq.clone());
    }
    let full = time_it(model, path, limits, effects, opts, reps);
    let kin_limits = JointLimits {
        effort: vec![f64::INFINITY; n],
        ..limits.clone()
    };
    let kin = time_it(model, path, &kin_limits, effects, opts, reps);
    let conic_opts = ToppOptions {
        method: ToppMethod::Conic,
        ..opts.clone()
    };
    let conic = time_it(model, path, limits, effects, &conic_opts, 3);
    let effort: Vec<Value> = limits
        .effort
        .iter()
        .map(|e| if e.is_finite() { json!(e) } else { Value::Null })
        .collect();
    let piece = json!({
        "s": s,
        "q": rows[0],
        "dq": rows[1],
        "ddq": rows[2],
        "velocity": limits.velocity,
        "acceleration": limits.acceleration,
        "effort": effort,
        "segments": opts.segments,
        "duration": timed.duration(),
        "stats": timed.stats(),
        "armsim_s": full.wall,
        "armsim_cpu_s": full.cpu,
        "armsim_duration": full.duration,
        "armsim_no_torque_s": kin.wall,
        "armsim_no_torque_cpu_s": kin.cpu,
        "armsim_no_torque_duration": kin.duration,
        "conic_s": conic.wall,
        "conic_cpu_s": conic.cpu,
        "conic_duration": conic.duration,
    });
    let mut all = PIECES.lock().unwrap_or_else(|e| e.into_inner());
    all.push(piece);
    let text = serde_json::to_string(&json!({ "pieces": *all })).unwrap_or_default();
    if let Err(e) = std::fs::write(&file, text) {
        eprintln!("ARMSIM_TOPP_DUMP: cannot write {file}: {e}");
    }
}
