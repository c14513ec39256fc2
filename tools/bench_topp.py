#!/usr/bin/env python3
"""TOPP of the main job's planned pieces: armsim against toppra 0.6 (PyPI), side by side.

    python3 tools/bench_topp.py [--reps 21] [--no-build]

1. builds armsim (release) unless --no-build, and runs the main job
   (`armsim run scenarios/ur5_pick_and_place.toml`) with the hidden hook
   ARMSIM_TOPP_DUMP=target/topp_pieces.json: every planned piece is re-timed REPS times
   by armsim's `topp` (TOPP-RA, the dense check and repairs included; with and without the
   torque limits) and 3 times by the conic solver, and written out with its grid `s_i`,
   the path `q, q', q''` at the grid points and the limits;
2. creates target/benchvenv with toppra 0.6 from PyPI (once);
3. times toppra on exactly the same grid points, path samples and velocity/acceleration
   limits (toppra's "interpolation" discretisation, the same both-ends-of-interval form
   as armsim; one `compute_parameterization(0, 0)` per repetition, no dense check), and
   prints the CPU times (the thread's CPU time, mean over the repetitions: the CPU clocks
   of some VMs tick in 4 ms steps), the wall medians, the ratio and the durations.

toppra gets no torque constraint (torque does not bind on this motion; armsim's column
"no torque" is the like-for-like figure, "full" what the main job runs).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
VENV = os.path.join(ROOT, "target", "benchvenv")
DUMP = os.path.join(ROOT, "target", "topp_pieces.json")


def ensure_venv():
    py = os.path.join(VENV, "bin", "python")
    if not os.path.exists(py):
        subprocess.check_call([sys.executable, "-m", "venv", VENV])
    try:
        subprocess.check_call([py, "-c", "import toppra"], stderr=subprocess.DEVNULL)
    except subprocess.CalledProcessError:
        subprocess.check_call([py, "-m", "pip", "install", "-q", "toppra==0.6.*"])
    return py


def run_armsim(reps, build):
    if build:
        subprocess.check_call(["cargo", "build", "--release", "-q"], cwd=ROOT)
    env = dict(os.environ, ARMSIM_TOPP_DUMP=DUMP, ARMSIM_TOPP_REPS=str(reps))
    subprocess.check_call(
        [os.path.join(ROOT, "target", "release", "armsim"), "run",
         "scenarios/ur5_pick_and_place.toml", "--out", os.path.join(ROOT, "target", "bench_topp_out")],
        cwd=ROOT, env=env, stdout=subprocess.DEVNULL)
    with open(DUMP) as f:
        return json.load(f)["pieces"]


TOPPRA_CODE = r'''
import json, sys, time, statistics
import numpy as np
import toppra as ta
import toppra.constraint as constraint
import toppra.algorithm as algo
ta.setup_logging("WARNING")

class Sampled(ta.interpolator.AbstractGeometricPath):
    """The path known at the grid points only (q, q', q'' from armsim)."""
    def __init__(self, s, q, dq, ddq):
        self.s, self.d = np.asarray(s), [np.asarray(q), np.asarray(dq), np.asarray(ddq)]
    def __call__(self, ss, order=0):
        ss = np.atleast_1d(ss)
        idx = np.searchsorted(self.s, ss)
        idx = np.clip(idx, 0, len(self.s) - 1)
        if not np.allclose(self.s[idx], ss, rtol=0, atol=1e-12):
            raise ValueError("evaluated off the grid")
        return self.d[order][idx]
    @property
    def dof(self):
        return self.d[0].shape[1]
    @property
    def path_interval(self):
        return np.array([self.s[0], self.s[-1]])
    @property
    def waypoints(self):
        return self.s, self.d[0]

pieces, reps = json.load(open(sys.argv[1]))["pieces"], int(sys.argv[2])
out = []
for p in pieces:
    path = Sampled(p["s"], p["q"], p["dq"], p["ddq"])
    v, a = np.array(p["velocity"]), np.array(p["acceleration"])
    scheme = constraint.DiscretizationType.Interpolation
    cons = [constraint.JointVelocityConstraint(np.stack([-v, v], axis=1)),
            constraint.JointAccelerationConstraint(np.stack([-a, a], axis=1),
                                                   discretization_scheme=scheme)]
    times, cpu, dur = [], [], None
    for _ in range(reps):
        t0, c0 = time.perf_counter(), time.thread_time()
        inst = algo.TOPPRA(cons, path, gridpoints=np.asarray(p["s"]),
                           parametrizer="ParametrizeConstAccel")
        sdd, sd, _, _ = inst.compute_parameterization(0, 0, return_data=True)
        cpu.append(time.thread_time() - c0)
        times.append(time.perf_counter() - t0)
    ss = np.asarray(p["s"])
    sd = np.asarray(sd)
    dur = float(np.sum(2 * np.diff(ss) / (sd[:-1] + sd[1:])))
    out.append({"times": times, "cpu": cpu, "duration": dur})
print(json.dumps(out))
'''


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--reps", type=int, default=21)
    ap.add_argument("--no-build", action="store_true")
    args = ap.parse_args()
    py = ensure_venv()
    pieces = run_armsim(args.reps, not args.no_build)
    res = json.loads(subprocess.check_output([py, "-c", TOPPRA_CODE, DUMP, str(args.reps)]))
    med = statistics.median

    def mean(x):  # CPU clocks tick in ms steps on some VMs: the mean over the repetitions
        return sum(x) / len(x)
    print(f"TOPP of the main job's {len(pieces)} planned pieces ({pieces[0]['segments']} intervals), "
          f"{args.reps} runs each (conic: 3): mean thread CPU ms (median wall ms in brackets)")
    print("| piece | armsim (TOPP-RA + dense check) | armsim, no torque limits | armsim conic | "
          "toppra 0.6, one solve | armsim / toppra | duration armsim s | duration toppra s |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    cols = [("armsim_cpu_s", "armsim_s"), ("armsim_no_torque_cpu_s", "armsim_no_torque_s"),
            ("conic_cpu_s", "conic_s")]
    tot_c, tot_w, dur = [0.0] * 4, [0.0] * 4, [0.0, 0.0]
    for k, (p, r) in enumerate(zip(pieces, res)):
        c = [mean(p[a]) for a, _ in cols] + [mean(r["cpu"])]
        w = [med(p[b]) for _, b in cols] + [med(r["times"])]
        tot_c = [x + y for x, y in zip(tot_c, c)]
        tot_w = [x + y for x, y in zip(tot_w, w)]
        dur[0] += p["armsim_duration"]
        dur[1] += r["duration"]
        cells = " | ".join(f"{x * 1e3:.2f} ({y * 1e3:.2f})" for x, y in zip(c, w))
        print(f"| {k + 1} | {cells} | {c[0] / c[3]:.2f} | {p['armsim_duration']:.4f} | {r['duration']:.4f} |")
    cells = " | ".join(f"{x * 1e3:.2f} ({y * 1e3:.2f})" for x, y in zip(tot_c, tot_w))
    print(f"| all | {cells} | {tot_c[0] / tot_c[3]:.2f} | {dur[0]:.4f} | {dur[1]:.4f} |")

if __name__ == "__main__":
    main()
