"""Batched forward kinematics from Python: ``armsim.fk_batch`` (eight rows at a time in
SIMD lanes over the frame's support chain) against what a Pinocchio user has in Python, a
loop of ``pin.framesForwardKinematics`` reading ``data.oMf[frame]`` (pin 4.1 has no batched
FK in Python). Checks the poses agree to 1e-12 first. Run with RAYON_NUM_THREADS=1 to
compare one thread with one (BENCHMARKS.md, "Linearised steps, CRBA and FK in lanes").

    RAYON_NUM_THREADS=1 python python/bench/bench_fk_batch.py [--batch 20000]
"""

from __future__ import annotations

import argparse
import timeit
from pathlib import Path

import numpy as np
import pinocchio as pin

import armsim as am

ROOT = Path(__file__).resolve().parents[2]
ROBOTS = [("ur5.urdf", "tool0"), ("panda.urdf", "panda_link8"), ("iiwa14.urdf", None)]


def bench(file, frame, n, rng):
    path = str(ROOT / "robots" / file)
    m = am.Model.from_file(path, ignore_mimic=True)
    pm = pin.buildModelFromUrdf(path)
    pd = pm.createData()
    frame = frame or m.frame_names[-1]
    fid, pf = m.frame_id(frame), pm.getFrameId(frame, pin.FrameType.BODY)
    lo = np.where(np.isfinite(m.lower_limits), m.lower_limits, -np.pi)
    hi = np.where(np.isfinite(m.upper_limits), m.upper_limits, np.pi)
    q = np.ascontiguousarray(rng.uniform(lo, hi, size=(n, m.nv)))

    def pin_loop():
        out = np.empty((n, 4, 4))
        for i in range(n):
            pin.framesForwardKinematics(pm, pd, q[i])
            out[i] = pd.oMf[pf].homogeneous
        return out

    worst = float(np.abs(am.fk_batch(m, q, fid) - pin_loop()).max())
    assert worst < 1e-12, f"{file}: poses differ by {worst:.2e}"
    t_am = min(timeit.repeat(lambda: am.fk_batch(m, q, fid), number=1, repeat=7))
    t_pin = min(timeit.repeat(pin_loop, number=1, repeat=3))
    return n / t_am, n / t_pin


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--batch", type=int, default=20000)
    args = ap.parse_args()
    rng = np.random.default_rng(0)
    print("| robot | am.fk_batch states/s | Python loop over pin.framesForwardKinematics states/s | ratio |")
    print("|---|---|---|---|")
    for file, frame in ROBOTS:
        a, p = bench(file, frame, args.batch, rng)
        print(f"| {file} | {a:.3g} | {p:.3g} | {a / p:.0f}× |")


if __name__ == "__main__":
    main()
