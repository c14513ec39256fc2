#!/usr/bin/env bash
# Motion planning side by side: the VAMP anchor (../shared/benchmarks/motion-planning/vamp/anchor.sh)
# and `armsim plan`, run one after the other on the shown MotionBenchMaker scenes, one thread each
# (pinned to the same core when there are 2+), the same number of passes (per-problem time = median
# over the passes), and the same columns. Prints both tables and a side-by-side table with ratios.
# Its last columns compare the simplified costs on the problems both solve: where one side solves
# problems the other fails (VAMP's AORRTC leaves 16 of the Panda's bookshelf problems unsolved at
# 2000 iterations), those are the hard ones, and each side's median over its own solved set
# compares unlike with unlike.
#
#   tools/plan_vs_vamp.sh [ROBOT...] [-- PASSES]
#     ROBOT   panda and/or ur5 (default: both)
#     PASSES  identical passes per problem (default 5, as the anchor)
#
# Environment: ARMSIM (the armsim binary; default: built with `cargo build --release` into
# $CARGO_TARGET_DIR or target/), PLAN_BENCH_DIR (default ../shared/benchmarks/motion-planning),
# PLAN_SCENES (default "table_pick bookshelf_small box"), PLANNER (rrtc, default: RRT-Connect on
# both sides; aorrtc: VAMP's AORRTC and `armsim plan --planner aorrtc`, both with an iteration
# budget of PLAN_BUDGET, default 2000, VAMP's `max_iterations`).
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BENCH="$(realpath "${PLAN_BENCH_DIR:-$ROOT/../shared/benchmarks/motion-planning}")"
SCENES=(${PLAN_SCENES:-table_pick bookshelf_small box})
robots=(); passes=5
while [ $# -gt 0 ]; do
  if [ "$1" = "--" ]; then passes="${2:-5}"; break; fi
  robots+=("$1"); shift
done
[ ${#robots[@]} -gt 0 ] || robots=(panda ur5)
if [ -z "${ARMSIM:-}" ]; then
  (cd "$ROOT" && cargo build --release --quiet --bin armsim)
  ARMSIM="${CARGO_TARGET_DIR:-$ROOT/target}/release/armsim"
fi
PLANNER="${PLANNER:-rrtc}"; PLAN_BUDGET="${PLAN_BUDGET:-2000}"
vamp_env=(); armsim_planner=()
if [ "$PLANNER" = aorrtc ]; then
  vamp_env=(VAMP_PLANNER=aorrtc "VAMP_SETTINGS=max_iterations=$PLAN_BUDGET")
  armsim_planner=(--planner aorrtc --budget-iterations "$PLAN_BUDGET")
elif [ "$PLANNER" != rrtc ]; then
  echo "PLANNER: expected rrtc or aorrtc, got '$PLANNER'" >&2; exit 2
fi
pin=""; [ "$(nproc)" -ge 2 ] && command -v taskset >/dev/null && pin="taskset -c 1"
out="$(mktemp -d)"; trap 'rm -rf "$out"' EXIT
echo "# Motion planning: VAMP anchor vs armsim"
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'); host: $(uname -n), $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "armsim: $(cd "$ROOT" && git rev-parse --short HEAD 2>/dev/null || echo '?')$(cd "$ROOT" && git diff --quiet 2>/dev/null || echo ' (modified)'); passes: $passes; one thread${pin:+, $pin}; planner: $PLANNER${armsim_planner:+ (budget $PLAN_BUDGET iterations)}"
for robot in "${robots[@]}"; do
  dirs=(); for s in "${SCENES[@]}"; do dirs+=("$BENCH/$robot/$s"); done
  echo; echo "## $robot"
  echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
  echo; echo "VAMP: ${vamp_env[*]} bash $BENCH/vamp/anchor.sh $robot ${dirs[*]} -- $passes"
  env "${vamp_env[@]}" VAMP_ANCHOR_CSV="$out/vamp_$robot.csv" bash "$BENCH/vamp/anchor.sh" "$robot" "${dirs[@]}" -- "$passes" | awk '/^\| scene/{n++} /^$/{if(n)done=1} n==1&&!done' | tee "$out/vamp_$robot.md"
  # VAMP's per-robot RRT-Connect range (vamp/constants.py ROBOT_RRT_RANGES).
  case "$robot" in ur5) range=1.5 ;; *) range=1.0 ;; esac
  args=("$ARMSIM" plan "$ROOT/robots/spherized/${robot}_spherized.urdf" --srdf "$ROOT/robots/spherized/$robot.srdf" --range "$range")
  for d in "${dirs[@]}"; do args+=(--moveit-dir "$d"); done
  args+=("${armsim_planner[@]}")
  echo; echo "armsim: ${args[*]#$ROOT/} --passes $passes"
  $pin "${args[@]}" --passes "$passes" 2>/dev/null | awk '/^\| scene \| solved/{n++} /^$/{if(n)done=1} n==1&&!done' | tee "$out/armsim_$robot.md"
  # The paths once more as JSON (same seed, same path), for the problems both solve.
  $pin "${args[@]}" --json --out "$out/armsim_$robot.json" 2>/dev/null
  echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
done
echo; echo "## Side by side (armsim / VAMP)"
python3 - "$out" "${robots[@]}" <<'PY'
import sys
out, robots = sys.argv[1], sys.argv[2:]
def rows(path):
    r = {}
    for line in open(path):
        c = [x.strip() for x in line.strip().strip('|').split('|')]
        if len(c) >= 14 and c[0] not in ('scene',) and not c[0].startswith('---'):
            r[c[0]] = c
    return r
import csv, json, statistics
def both_solved_costs(robot):
    # Per scene, (armsim, VAMP) simplified costs of the problems both solved: VAMP's first
    # pass (its paths may differ between passes) against armsim's (the same every pass).
    v = {}
    for r in csv.DictReader(open(f"{out}/vamp_{robot}.csv")):
        if r["pass_"] == "0" and r["solved"] == "1":
            v[(r["scene"], int(r["index"]))] = float(r["simp_cost"])
    pairs = {}
    for r in json.load(open(f"{out}/armsim_{robot}.json"))["results"]:
        key = (r["scene"], int(r["problem"]) - 1)
        if r["status"] == "solved" and key in v:
            for s in (r["scene"], "ALL"):
                pairs.setdefault(s, []).append((r["cost"], v[key]))
    return pairs
print("| robot | scene | solved/valid armsim | VAMP | plan median µs armsim | VAMP | ratio | plan p95 µs armsim | VAMP | ratio | simplified cost median armsim | VAMP | ratio | both solved | cost median on them armsim | VAMP | ratio |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
for robot in robots:
    a, v = rows(f"{out}/armsim_{robot}.md"), rows(f"{out}/vamp_{robot}.md")
    both = both_solved_costs(robot)
    for scene in v:
        if scene not in a:
            continue
        x, y = a[scene], v[scene]
        sv = lambda c: "/".join(c[1].split("/")[:2])
        def r(i):
            try:
                return f"{float(x[i]) / float(y[i]):.2f}"
            except (ValueError, ZeroDivisionError):
                return "-"
        b = both.get(scene, [])
        ca = statistics.median(c for c, _ in b) if b else float("nan")
        cv = statistics.median(c for _, c in b) if b else float("nan")
        print(f"| {robot} | {scene} | {sv(x)} | {sv(y)} | {x[2]} | {y[2]} | {r(2)} | {x[4]} | {y[4]} | {r(4)} | {x[11]} | {y[11]} | {r(11)} | {len(b)} | {ca:.3f} | {cv:.3f} | {ca / cv:.2f} |")
PY
