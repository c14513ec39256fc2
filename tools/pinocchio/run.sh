#!/usr/bin/env bash
# Build (if needed) and run the Pinocchio timing harness.
#
#   tools/pinocchio/run.sh [--standard] [URDF ...]
#
#   --standard   also bench the standard set: example-robot-data ur5_robot.urdf
#                and panda.urdf, every robots/*.urdf of the repo, and the
#                generated chain_50 / chain_100 / chain_200 (gen_chain.py).
#                Standard URDFs with <mimic> tags are run twice: Pinocchio's
#                default parse (mimic joint = independent DOF) and with --mimic.
#
# Env: OUT (default tools/pinocchio/results.jsonl, overwritten),
#      VARIANTS (default "hdr lib"), BENCH_ARGS (extra args for bench, e.g.
#      "--reps 21 --rep-ms 20"), PYTHON (default python3),
#      NICE (default empty; e.g. NICE=-20 runs the bench under `nice -n -20`
#      when allowed -- measured to make no reliable difference on this VM).
# Each JSON line gets a "run" field (UTC start time of this run.sh call).
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
REPO="$(cd "$HERE/../.." && pwd)"
PYTHON="${PYTHON:-python3}"
OUT="${OUT:-$HERE/results.jsonl}"
VARIANTS="${VARIANTS:-hdr lib}"
RUN_ID="$(date -u +%Y-%m-%dT%H:%M:%SZ)"

std=()
urdfs=()   # entries: "<flags>|<path>"
for a in "$@"; do
  if [[ "$a" == "--standard" ]]; then
    ERD="$("$PYTHON" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')/cmeel.prefix/share/example-robot-data/robots"
    for f in "$ERD/ur_description/urdf/ur5_robot.urdf" "$ERD/panda_description/urdf/panda.urdf"; do
      if [[ -f "$f" ]]; then std+=("$f"); else echo "warning: $f not found (pip install example-robot-data)" >&2; fi
    done
    for f in "$REPO"/robots/*.urdf; do [[ -f "$f" ]] && std+=("$f"); done
    for f in "${std[@]}"; do
      urdfs+=("|$f")
      if grep -q "<mimic" "$f"; then urdfs+=("--mimic|$f"); fi
    done
    mkdir -p "$HERE/build"
    for n in 50 100 200; do
      "$PYTHON" "$HERE/gen_chain.py" "$n" > "$HERE/build/chain_$n.urdf"
      urdfs+=("|$HERE/build/chain_$n.urdf")
    done
  else
    urdfs+=("|$a")
  fi
done
[[ ${#urdfs[@]} -gt 0 ]] || { sed -n 2,15p "$0" >&2; exit 2; }

# Rebuild when a binary is missing or older than bench.cpp / build.sh.
need_build=0
for v in $VARIANTS; do
  b="$HERE/build/bench_$v"
  if [[ ! -x "$b" || "$HERE/bench.cpp" -nt "$b" || "$HERE/build.sh" -nt "$b" ]]; then need_build=1; fi
done
if [[ $need_build == 1 ]]; then "$HERE/build.sh"; fi

NICE="${NICE:-}"
nice_cmd=()
if [[ -n "$NICE" ]] && [[ -z "$(nice -n "$NICE" true 2>&1)" ]]; then nice_cmd=(nice -n "$NICE"); fi

tmp="$(mktemp)"
trap 'rm -f "$tmp"' EXIT
status=0
for entry in "${urdfs[@]}"; do
  flags="${entry%%|*}"
  u="${entry#*|}"
  for v in $VARIANTS; do
    # shellcheck disable=SC2086
    "${nice_cmd[@]}" "$HERE/build/bench_$v" ${BENCH_ARGS:-} $flags "$u" \
      | sed "s/}\$/, \"run\": \"$RUN_ID\"}/" | tee -a "$tmp" || status=1
  done
done
mv "$tmp" "$OUT"
trap - EXIT
echo "wrote $OUT" >&2
exit $status
