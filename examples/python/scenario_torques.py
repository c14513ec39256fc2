# %% [markdown]
# # armsim from Python: a scenario, its torques, a Rerun recording
#
# Runs `scenarios/planar_2r.toml` (the textbook 2R arm: swing up, a straight tip line,
# time-optimal), reads the report, recomputes the joint torques along the planned
# waypoints with `armsim.rnea_batch`, plots them with matplotlib (PNG) and logs them,
# with the tool path, to a Rerun `.rrd` file (open it with `rerun out.rrd`).
#
# Run: `python examples/python/scenario_torques.py [OUT_DIR]` (default `out/python_example`).

# %%
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import rerun as rr  # noqa: E402

import armsim as am  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
out = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "out" / "python_example"
out.mkdir(parents=True, exist_ok=True)

# %% The scenario: its report as a dict
report = am.run_scenario(ROOT / "scenarios" / "planar_2r.toml", out_dir=out / "run")
joints = report["model"]["joints"]
print(f"{report['scenario']}: ok={report['ok']}, duration {report['plan']['duration_s']:.3f} s")
for t in report["torque_check"]:
    print(f"  {t['joint']}: peak {t['peak_torque']:.2f} N·m of {t['limit']} (rms {t['rms_torque']:.2f})")

# %% A smooth joint path through the plan's waypoints (quintic rest-to-rest per piece)
model = am.Model.from_file(ROOT / "robots" / "planar_2r.toml")
pieces = report["plan"]["pieces"]
waypoints = [np.array([p["end_q"][j] for j in joints]) for p in pieces]
t_all, q_all, v_all, a_all = [], [], [], []
t0 = pieces[1]["start_s"]
for p, q_from, q_to in zip(pieces[1:], waypoints[:-1], waypoints[1:]):
    T = p["duration_s"]
    s = np.linspace(0.0, 1.0, 200)[:, None]
    shape = 10 * s**3 - 15 * s**4 + 6 * s**5
    dshape = (30 * s**2 - 60 * s**3 + 30 * s**4) / T
    ddshape = (60 * s - 180 * s**2 + 120 * s**3) / T**2
    dq = q_to - q_from
    t_all.append(p["start_s"] + s[:, 0] * T)
    q_all.append(q_from + shape * dq)
    v_all.append(dshape * dq)
    a_all.append(ddshape * dq)
t = np.concatenate(t_all)
Q, V, A = (np.ascontiguousarray(np.concatenate(x)) for x in (q_all, v_all, a_all))

# %% Torques (gravity from the model) and the tool path, in one batched call each
tau = am.rnea_batch(model, Q, V, A)
tool = am.fk_batch(model, Q, "tool")[:, :3, 3]

# %% Plot
fig, ax = plt.subplots(figsize=(8, 4))
for k, name in enumerate(joints):
    ax.plot(t, tau[:, k], label=name)
ax.set_xlabel("time (s)")
ax.set_ylabel("torque (N·m)")
ax.set_title(f"{report['scenario']}: joint torques along the planned waypoints")
ax.legend()
ax.grid(True, alpha=0.3)
png = out / "torques.png"
fig.savefig(png, dpi=100)
print(f"wrote {png}")

# %% Rerun: scalars over time and the tool path, saved to a file (no viewer)
rrd = out / "torques.rrd"
rr.init("armsim_python_example")
rr.save(str(rrd))
rr.log("tool_path", rr.LineStrips3D([tool]), static=True)
for i in range(0, len(t), 4):
    rr.set_time("time", duration=float(t[i]))
    for k, name in enumerate(joints):
        rr.log(f"torque/{name}", rr.Scalars(float(tau[i, k])))
    rr.log("tool", rr.Points3D([tool[i]], radii=0.02))
rr.disconnect()
print(f"wrote {rrd}")
