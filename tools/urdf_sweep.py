#!/usr/bin/env python3
"""Sweep a folder of URDF files: load each in Pinocchio and in armsim, compare forward
kinematics at random states, and print a table of what each loads (development only).

Usage:
    pip install pin example-robot-data        # or: pip download example-robot-data --no-deps
    cargo build --release --no-default-features --bin armsim
    python3 tools/urdf_sweep.py DIR [--states 5] [--seed 0] [--armsim target/release/armsim]

DIR is searched recursively for *.urdf (for example-robot-data:
.../site-packages/cmeel.prefix/share/example-robot-data/robots).

For every file loaded by both, K configurations are drawn inside armsim's limits
(continuous joints in [-pi, pi], unbounded prismatic ones in [-1, 1] m); `armsim fk --json`
gives every link frame, and Pinocchio (`buildModelFromUrdf`, which ignores mimic tags) is
given the same state: mimic joints at their mimic values (from `armsim info --json`),
continuous joints as (cos, sin), floating joints (armsim: J_x, J_y, J_z, J_yaw, J_pitch,
J_roll) as position + quaternion of Rz(yaw) Ry(pitch) Rx(roll), planar joints (J_x, J_y,
J_yaw) as (x, y, cos, sin). The table gives the largest translation (m) and rotation-matrix
entry difference over all links present in both models.

Exit status: 0 when every file Pinocchio loads, armsim loads too (the one accepted refusal:
a lower limit above the upper limit) with FK equal to --tol; 1 otherwise.
"""
from __future__ import annotations

import argparse
import glob
import json
import math
import os
import subprocess
import sys

import numpy as np

try:
    import pinocchio as pin
except ImportError:  # pragma: no cover
    sys.exit("urdf_sweep.py needs Pinocchio: pip install pin")

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
ACCEPTED_REFUSAL = "is greater than upper limit"


def quiet_pin_load(path: str):
    """buildModelFromUrdf with urdfdom's console output silenced; (model, error)."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    saved = os.dup(2)
    os.dup2(devnull, 2)
    try:
        return pin.buildModelFromUrdf(path), None
    except Exception as e:  # noqa: BLE001 - any refusal is a result here
        return None, str(e).splitlines()[0]
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(devnull)


def armsim(exe: str, *args: str):
    p = subprocess.run([exe, *args], capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def sample(info: dict, rng: np.random.Generator) -> dict[str, float]:
    """A random value per armsim coordinate, inside its limits."""
    joints = {j["name"]: j for j in info["joints"]}
    q = {}
    for name in info["coordinates"]:
        j = joints[name]
        lo, hi = j["lower"], j["upper"]
        if lo is None or hi is None or not (math.isfinite(lo) and math.isfinite(hi)):
            lo, hi = (-1.0, 1.0) if j["type"] == "prismatic" else (-math.pi, math.pi)
        q[name] = float(rng.uniform(lo, hi)) if hi > lo else lo
    return q


def joint_values(info: dict, q: dict[str, float]) -> dict[str, float]:
    """Every movable armsim joint's value: coordinates, and mimic joints from their master."""
    vals = dict(q)
    for j in info["joints"]:
        m = j.get("mimic")
        if m is not None:
            vals[j["name"]] = m["multiplier"] * q[m["joint"]] + m["offset"]
    return vals


def rpy_quat_xyzw(roll: float, pitch: float, yaw: float) -> np.ndarray:
    r = pin.rpy.rpyToMatrix(roll, pitch, yaw)  # Rz(yaw) Ry(pitch) Rx(roll)
    return pin.Quaternion(r).coeffs()  # x, y, z, w


def pin_q(model, vals: dict[str, float]) -> np.ndarray:
    """Pinocchio's configuration for armsim's joint values (see the module docs)."""
    q = pin.neutral(model)
    for jid in range(1, model.njoints):
        jm, name = model.joints[jid], model.names[jid]
        kind, i = jm.shortname(), jm.idx_q
        if kind == "JointModelFreeFlyer":
            t = [vals[f"{name}_{a}"] for a in ("x", "y", "z")]
            rpy = [vals[f"{name}_{a}"] for a in ("roll", "pitch", "yaw")]
            q[i : i + 7] = np.concatenate([t, rpy_quat_xyzw(*rpy)])
        elif kind == "JointModelPlanar":
            th = vals[f"{name}_yaw"]
            q[i : i + 4] = [vals[f"{name}_x"], vals[f"{name}_y"], math.cos(th), math.sin(th)]
        elif jm.nq == 2:  # continuous: (cos, sin)
            q[i : i + 2] = [math.cos(vals[name]), math.sin(vals[name])]
        elif jm.nq == 1:
            q[i] = vals[name]
        else:
            raise ValueError(f"joint '{name}': {kind} is not mapped")
    return q


def fk_error(exe: str, path: str, model, info: dict, q: dict[str, float]):
    """Largest translation and rotation differences over the links in both models."""
    qs = ",".join(repr(q[n]) for n in info["coordinates"])
    rc, out, err = armsim(exe, "fk", path, "--json", f"--q={qs}")
    if rc != 0:
        raise RuntimeError(f"armsim fk failed: {err.strip()[:200]}")
    frames = json.loads(out)["frames"]
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin_q(model, joint_values(info, q)))
    dt = dr = 0.0
    links = {}
    for link, f in frames.items():
        if not model.existFrame(link, pin.FrameType.BODY):
            continue
        m = data.oMf[model.getFrameId(link, pin.FrameType.BODY)]
        dt = max(dt, float(np.abs(m.translation - np.array(f["translation"])).max()))
        dr = max(dr, float(np.abs(m.rotation - np.array(f["rotation"])).max()))
        links[link] = {"rotation": m.rotation.tolist(), "translation": m.translation.tolist()}
    return dt, dr, links


def sweep_file(exe: str, path: str, states: int, rng) -> dict:
    row = {"file": path}
    model, perr = quiet_pin_load(path)
    row["pin"] = "load" if model is not None else "refuse"
    row["pin_error"] = perr
    rc, out, err = armsim(exe, "info", path, "--json")
    warns = [l for l in err.splitlines() if l.startswith("warning:")]
    row["warnings"] = len(warns)
    if rc != 0:
        row["armsim"] = "refuse"
        row["armsim_error"] = err.strip().splitlines()[-1] if err.strip() else f"exit {rc}"
        return row
    row["armsim"] = "load"
    info = json.loads(out)
    row["nv"] = info["dof"]
    if model is None:
        return row
    row["pin_nv"] = model.nv
    worst = (0.0, 0.0, 0)
    row["states"] = []
    for _ in range(states):
        q = sample(info, rng)
        dt, dr, links = fk_error(exe, path, model, info, q)
        worst = (max(worst[0], dt), max(worst[1], dr), len(links))
        row["states"].append({"q": q, "links": links})
    row["fk_dt"], row["fk_dr"], row["frames"] = worst
    return row


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dir")
    ap.add_argument("--states", type=int, default=5)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--tol", type=float, default=1e-9)
    ap.add_argument("--armsim", default=os.path.join(ROOT, "target", "release", "armsim"))
    ap.add_argument(
        "--golden",
        help="also write Pinocchio's link placements at the sampled states to this JSON file "
        "(armsim coordinates by name; tests/urdf_ecosystem.rs reads it)",
    )
    a = ap.parse_args()
    exe = a.armsim
    if not os.path.exists(exe) and os.environ.get("CARGO_TARGET_DIR"):
        exe = os.path.join(os.environ["CARGO_TARGET_DIR"], "release", "armsim")
    files = sorted(glob.glob(os.path.join(a.dir, "**", "*.urdf"), recursive=True))
    rng = np.random.default_rng(a.seed)
    rows = [sweep_file(exe, f, a.states, rng) for f in files]

    print("| file | Pinocchio | armsim | warnings | nv (pin / armsim) | FK max |dt| m, |dR| | note |")
    print("|---|---|---|---|---|---|---|")
    bad = []
    for r in rows:
        name = os.path.relpath(r["file"], a.dir)
        fk = ""
        if "fk_dt" in r:
            fk = f"{r['fk_dt']:.1e}, {r['fk_dr']:.1e} ({r['frames']} links)"
        nv = f"{r.get('pin_nv', '-')} / {r.get('nv', '-')}"
        note = r.get("armsim_error") or r.get("pin_error") or ""
        if r["armsim"] == "refuse" and os.path.sep in note:
            note = note.split(": ", 1)[-1]  # drop the path, keep line: element: problem
        print(f"| {name} | {r['pin']} | {r['armsim']} | {r['warnings']} | {nv} | {fk} | {note[:160]} |")
        if r["pin"] == "load" and r["armsim"] == "refuse" and ACCEPTED_REFUSAL not in note:
            bad.append(f"{name}: armsim refuses: {note}")
        if "fk_dt" in r and max(r["fk_dt"], r["fk_dr"]) > a.tol:
            bad.append(f"{name}: FK differs by {max(r['fk_dt'], r['fk_dr']):.1e}")
    pin_ok = sum(r["pin"] == "load" for r in rows)
    both = sum(r["pin"] == "load" and r["armsim"] == "load" for r in rows)
    arm_ok = sum(r["armsim"] == "load" for r in rows)
    worst = max([max(r["fk_dt"], r["fk_dr"]) for r in rows if "fk_dt" in r] or [0.0])
    print()
    print(
        f"{len(rows)} files: Pinocchio loads {pin_ok}, armsim loads {arm_ok}, both {both}; "
        f"armsim refuses {pin_ok - both} of Pinocchio's; largest FK difference {worst:.1e} "
        f"over {a.states} random states per file"
    )
    for b in bad:
        print(f"DISAGREEMENT {b}")
    if a.golden:
        files_out = {
            os.path.relpath(r["file"], a.dir): {"states": r["states"]} for r in rows if "states" in r
        }
        out = {"generator": "tools/urdf_sweep.py", "pinocchio": pin.__version__, "files": files_out}
        with open(a.golden + ".tmp", "w") as f:
            json.dump(out, f, indent=1)
            f.write("\n")
        os.replace(a.golden + ".tmp", a.golden)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
