#!/usr/bin/env bash
# Records what path quality costs in planning time for VAMP and armsim, side by side, on
# the MotionBenchMaker `table_pick` scene of the Panda and the UR5 (all its problems; the
# trade-offs report bundles its first twelve, assets/planning/mbm/): RRT-Connect, then the
# optimising planners (VAMP's AORRTC with `max_iterations=B`, `armsim plan --planner aorrtc
# --budget-iterations B`) at each budget B. One pass each, one thread, the same core.
# Writes assets/planning/vamp_tradeoff.csv, which `armsim tradeoffs` (study 8) shows beside
# its own live figures: VAMP cannot run inside armsim.
#
#   tools/planning_tradeoff_vamp.sh [BUDGET...]     (default: 250 500 1000 2000 4000 8000)
#
# Times are planning plus final simplification (µs; VAMP: plan_ns + simp_ns; armsim:
# plan_time_us + simplify_time_us), over the solved problems; cost is the median simplified
# joint-space length. Needs ../shared/benchmarks/motion-planning/vamp/anchor.sh (builds VAMP
# offline on first use).
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BENCH="$(realpath "${PLAN_BENCH_DIR:-$ROOT/../shared/benchmarks/motion-planning}")"
budgets=("$@"); [ ${#budgets[@]} -gt 0 ] || budgets=(250 500 1000 2000 4000 8000)
(cd "$ROOT" && cargo build --release --quiet --bin armsim)
ARMSIM="${CARGO_TARGET_DIR:-$ROOT/target}/release/armsim"
pin=""; [ "$(nproc)" -ge 2 ] && command -v taskset >/dev/null && pin="taskset -c 1"
out="$(mktemp -d)"; trap 'rm -rf "$out"' EXIT
measured="$(date -u '+%Y-%m-%dT%H:%MZ') $(uname -n) load $(cut -d' ' -f1 /proc/loadavg)"
for robot in panda ur5; do
  dir="$BENCH/$robot/table_pick"
  case "$robot" in ur5) range=1.5 ;; *) range=1.0 ;; esac
  for b in 0 "${budgets[@]}"; do
    if [ "$b" = 0 ]; then venv=(); aargs=(); else
      venv=(VAMP_PLANNER=aorrtc "VAMP_SETTINGS=max_iterations=$b"); aargs=(--planner aorrtc --budget-iterations "$b"); fi
    env "${venv[@]}" VAMP_ANCHOR_CSV="$out/vamp_${robot}_$b.csv" bash "$BENCH/vamp/anchor.sh" "$robot" "$dir" -- 1 >/dev/null
    $pin "$ARMSIM" plan "$ROOT/robots/spherized/${robot}_spherized.urdf" --srdf "$ROOT/robots/spherized/$robot.srdf" \
      --range "$range" --moveit-dir "$dir" "${aargs[@]}" --json 2>/dev/null > "$out/armsim_${robot}_$b.json"
    echo "$robot budget $b done" >&2
  done
done
python3 - "$out" "$measured" "${budgets[@]}" > "$ROOT/assets/planning/vamp_tradeoff.csv" <<'PY'
import csv, json, math, sys, statistics as st
out, measured, budgets = sys.argv[1], sys.argv[2], [0] + [int(b) for b in sys.argv[3:]]
def p95(v):
    v = sorted(v); return v[max(1, math.ceil(0.95 * len(v))) - 1]
print("robot,planner,budget,valid,vamp_solved,vamp_med_us,vamp_p95_us,vamp_cost,armsim_solved,armsim_med_us,armsim_p95_us,armsim_cost,measured")
for robot in ("panda", "ur5"):
    for b in budgets:
        v = [r for r in csv.DictReader(open(f"{out}/vamp_{robot}_{b}.csv")) if r["solved"] == "1"]
        vt = [(float(r["plan_ns"]) + float(r["simp_ns"])) / 1e3 for r in v]
        vc = [float(r["simp_cost"]) for r in v]
        a = [r for r in json.load(open(f"{out}/armsim_{robot}_{b}.json"))["results"] if r["status"] == "solved"]
        at = [r["plan_time_us"] + r["simplify_time_us"] for r in a]
        ac = [r["cost"] for r in a]
        valid = sum(r["valid"] == "1" for r in csv.DictReader(open(f"{out}/vamp_{robot}_{b}.csv")))
        print(f"{robot},{'aorrtc' if b else 'rrtc'},{b},{valid},{len(v)},{st.median(vt):.1f},{p95(vt):.1f},{st.median(vc):.4f},"
              f"{len(a)},{st.median(at):.1f},{p95(at):.1f},{st.median(ac):.4f},{measured}")
PY
cat "$ROOT/assets/planning/vamp_tradeoff.csv"
