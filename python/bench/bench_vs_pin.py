"""Side-by-side timing from Python: armsim vs Pinocchio (PyPI `pin`) per call (RNEA,
forward kinematics, frame Jacobian, the RNEA and ABA derivatives, M⁻¹) and batch RNEA
throughput (armsim.rnea_batch against pin.rneaInParallel with one thread, and against a
Python loop over pin.rnea), and batch ABA (armsim.aba_batch against pin.abaInParallel). Run with RAYON_NUM_THREADS=1 to compare one thread with one. Prints a Markdown table (BENCHMARKS.md, "From Python").

    RAYON_NUM_THREADS=1 python python/bench/bench_vs_pin.py [--calls 20000] [--rounds 11] [--batch 20000]

Per-call figures: `rounds` rounds of `calls` calls, armsim and pin alternating round by round;
the median and best ns per call of each side, the median of the per-round ratios and the
ratio of the bests (Python call overhead included on both sides; the same random state
for both libraries).
"""

from __future__ import annotations

import argparse
import os
import platform
import timeit
from pathlib import Path

import numpy as np
import pinocchio as pin

import armsim as am

ROOT = Path(__file__).resolve().parents[2]
ROBOTS = [("ur5", "ur5.urdf", "tool0"), ("panda", "panda.urdf", "panda_link8"),
          ("iiwa14", "iiwa14.urdf", None)]


def paired(f_am, f_pin, calls: int, repeats: int = 11):
    """Median and best time per call of each side (ns) and the median of the per-round
    ratios: the two sides alternate round by round, so both see the same machine load."""
    t_am, t_pin = [], []
    for _ in range(repeats):
        t_am.append(timeit.timeit(f_am, number=calls) / calls * 1e9)
        t_pin.append(timeit.timeit(f_pin, number=calls) / calls * 1e9)
    ratio = float(np.median(np.array(t_am) / np.array(t_pin)))
    return (float(np.median(t_am)), min(t_am)), (float(np.median(t_pin)), min(t_pin)), ratio


def pin_q(am_model, pm, q):
    out = np.zeros(pm.nq)
    for k, name in enumerate(am_model.joint_names):
        j = pm.joints[pm.getJointId(name)]
        if j.nq == 2:
            out[j.idx_q:j.idx_q + 2] = (np.cos(q[k]), np.sin(q[k]))
        else:
            out[j.idx_q] = q[k]
    return out


def bench_robot(name, file, frame, calls, rounds, batch, rng):
    path = str(ROOT / "robots" / file)
    m = am.Model.from_file(path, ignore_mimic=True)
    pm = pin.buildModelFromUrdf(path)
    assert [pm.names[i] for i in range(1, pm.njoints)] == m.joint_names, "same joint order"
    d, pd = m.create_data(), pm.createData()
    frame = frame or m.frame_names[-1]
    fid, pf = m.frame_id(frame), pm.getFrameId(frame, pin.FrameType.BODY)
    lo = np.where(np.isfinite(m.lower_limits), m.lower_limits, -np.pi)
    hi = np.where(np.isfinite(m.upper_limits), m.upper_limits, np.pi)
    q = rng.uniform(lo, hi)
    v, a = rng.normal(size=m.nv), rng.normal(size=m.nv)
    pq = pin_q(m, pm, q)
    assert np.allclose(am.rnea(m, d, q, v, a), pin.rnea(pm, pd, pq, v, a), atol=1e-9)
    ref = pin.ReferenceFrame.LOCAL
    rows = []
    rows.append(("rnea", *paired(lambda: am.rnea(m, d, q, v, a),
                                 lambda: pin.rnea(pm, pd, pq, v, a), calls, rounds)))
    rows.append(("forward_kinematics", *paired(lambda: am.forward_kinematics(m, d, q),
                                               lambda: pin.forwardKinematics(pm, pd, pq), calls, rounds)))
    rows.append(("frame_jacobian (local)",
                 *paired(lambda: am.frame_jacobian(m, d, q, fid, "local"),
                         lambda: pin.computeFrameJacobian(pm, pd, pq, pf, ref), calls, rounds)))
    tau = rng.normal(size=m.nv)
    rows.append(("rnea_derivatives",
                 *paired(lambda: am.rnea_derivatives(m, d, q, v, a),
                         lambda: pin.computeRNEADerivatives(pm, pd, pq, v, a), calls, rounds)))
    rows.append(("aba_derivatives",
                 *paired(lambda: am.aba_derivatives(m, d, q, v, tau),
                         lambda: pin.computeABADerivatives(pm, pd, pq, v, tau), calls, rounds)))
    rows.append(("compute_minverse",
                 *paired(lambda: am.compute_minverse(m, d, q),
                         lambda: pin.computeMinverse(pm, pd, pq), calls, rounds)))
    Q = np.ascontiguousarray(rng.uniform(lo, hi, size=(batch, m.nv)))
    V, A = rng.normal(size=(batch, m.nv)), rng.normal(size=(batch, m.nv))
    PQ = np.array([pin_q(m, pm, x) for x in Q])

    def pin_loop():
        for i in range(batch):
            pin.rnea(pm, pd, PQ[i], V[i], A[i])

    # pin's batch: one state per column; tau written in place.
    pool = pin.ModelPool(pm, 1)
    PQT, VT, AT = (np.asfortranarray(x.T) for x in (PQ, V, A))
    TAU = np.asfortranarray(np.zeros((m.nv, batch)))
    pin.rneaInParallel(1, pool, PQT, VT, AT, TAU)
    assert np.allclose(am.rnea_batch(m, Q, V, A), TAU.T, rtol=1e-9, atol=1e-9)
    t_am = min(timeit.repeat(lambda: am.rnea_batch(m, Q, V, A), number=1, repeat=7))
    t_par = min(timeit.repeat(lambda: pin.rneaInParallel(1, pool, PQT, VT, AT, TAU),
                              number=1, repeat=7))
    t_pin = min(timeit.repeat(pin_loop, number=1, repeat=3))
    # Forward dynamics on the same states, the torques just computed.
    T = np.ascontiguousarray(TAU.T)
    DDQ = np.asfortranarray(np.zeros((m.nv, batch)))
    pin.abaInParallel(1, pool, PQT, VT, np.asfortranarray(T.T), DDQ)
    assert np.allclose(am.aba_batch(m, Q, V, T), DDQ.T, rtol=1e-7, atol=1e-7)
    t_am_aba = min(timeit.repeat(lambda: am.aba_batch(m, Q, V, T), number=1, repeat=7))
    TT = np.asfortranarray(T.T)
    t_par_aba = min(timeit.repeat(lambda: pin.abaInParallel(1, pool, PQT, VT, TT, DDQ),
                                  number=1, repeat=7))
    return name, m.nv, rows, (batch / t_am, batch / t_par, batch / t_pin,
                              batch / t_am_aba, batch / t_par_aba)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=20000)
    ap.add_argument("--rounds", type=int, default=11)
    ap.add_argument("--batch", type=int, default=20000)
    args = ap.parse_args()
    rng = np.random.default_rng(0)
    print(f"armsim (Python, abi3 wheel) vs pin {pin.__version__}; Python {platform.python_version()}, "
          f"{os.cpu_count()} CPUs, rayon threads = {os.environ.get('RAYON_NUM_THREADS', 'all')}; "
          f"{args.rounds} rounds of {args.calls} calls; load average {os.getloadavg()[0]:.2f} at the start\n")
    print("| robot | nv | call | armsim ns median (best) | pin ns median (best) "
          "| median of paired ratios | best / best |")
    print("|---|---|---|---|---|---|---|")
    batches = []
    for name, file, frame in ROBOTS:
        rname, nv, rows, thr = bench_robot(name, file, frame, args.calls, args.rounds, args.batch, rng)
        for call, t_am, t_pin, ratio in rows:
            print(f"| {rname} | {nv} | {call} | {t_am[0]:.0f} ({t_am[1]:.0f}) | {t_pin[0]:.0f} "
                  f"({t_pin[1]:.0f}) | {ratio:.2f}× | {t_am[1] / t_pin[1]:.2f}× |")
        batches.append((rname, nv, thr))
    print(f"\nload average {os.getloadavg()[0]:.2f} at the end\n")
    print(f"| robot | nv | am.rnea_batch (N = {args.batch}) states/s "
          "| pin.rneaInParallel(1) states/s | speed-up | Python loop over pin.rnea states/s "
          "| speed-up |")
    print("|---|---|---|---|---|---|---|")
    for rname, nv, (t_am, t_par, t_pin, _, _) in batches:
        print(f"| {rname} | {nv} | {t_am:,.0f} | {t_par:,.0f} | {t_am / t_par:.1f}× "
              f"| {t_pin:,.0f} | {t_am / t_pin:.1f}× |")
    print(f"\n| robot | nv | am.aba_batch (N = {args.batch}) states/s "
          "| pin.abaInParallel(1) states/s | speed-up |")
    print("|---|---|---|---|---|")
    for rname, nv, (_, _, _, t_am, t_par) in batches:
        print(f"| {rname} | {nv} | {t_am:,.0f} | {t_par:,.0f} | {t_am / t_par:.1f}× |")


if __name__ == "__main__":
    main()
