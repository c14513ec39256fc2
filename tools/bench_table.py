#!/usr/bin/env python3
"""Side-by-side table: armsim's criterion medians against Pinocchio's.

Usage: tools/bench_table.py PINOCCHIO_RESULTS.jsonl [CRITERION_DIR]

Reads target/criterion/<model>/<algo>/new/estimates.json (median, ns; the `*_batch`
benches per 256 states, compared per state with Pinocchio's single call) for armsim and
the JSON lines of tools/pinocchio/run.sh (best of its hdr/lib builds per model and
algorithm, URDFs from robots/ and the generated chains), and prints a Markdown table
of medians and the ratio armsim / Pinocchio.
"""
import json
import os
import sys

pin_file = sys.argv[1]
crit = sys.argv[2] if len(sys.argv) > 2 else "target/criterion"

pin = {}
for line in open(pin_file):
    r = json.loads(line)
    urdf = r["urdf"]
    if "example-robot-data" in urdf:
        continue
    name = r["model"] + ("_mimic" if r.get("mimic") else "")
    algo = "crba" if r["algo"] == "crba" else r["algo"]
    key = (name, algo)
    pin[key] = min(pin.get(key, float("inf")), r["ns_per_call"])

def ours(model, algo):
    """Median ns per call; a `*_batch` bench times 256 states, so per state."""
    p = os.path.join(crit, model, algo, "new", "estimates.json")
    if not os.path.exists(p):
        return None
    ns = json.load(open(p))["median"]["point_estimate"]
    return ns / 256 if algo.endswith("_batch") else ns

models = ["ur5", "panda", "panda_mimic", "iiwa14", "chain_50", "chain_100", "chain_200"]
algos = ["fk", "jacobians", "rnea", "rnea_batch", "crba", "aba", "aba_batch", "rnea_derivatives",
         "aba_derivatives", "minverse"]
# A batch (armsim, per state in SIMD lanes) against Pinocchio's single call on one thread.
PIN_ALGO = {"rnea_batch": "rnea", "aba_batch": "aba"}
print("| model | algo | armsim (ns) | Pinocchio 4.1 (ns) | ratio |")
print("|---|---|---:|---:|---:|")
for m in models:
    for a in algos:
        o = ours(m, a)
        p = pin.get((m, PIN_ALGO.get(a, a)))
        if o is None or p is None:
            continue
        print(f"| {m} | {a} | {o:.0f} | {p:.0f} | {o / p:.2f} |")
