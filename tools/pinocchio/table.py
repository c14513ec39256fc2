#!/usr/bin/env python3
"""Markdown tables from bench JSON lines.

Usage: table.py [--best] results_a.jsonl [results_b.jsonl ...]

Default: one table per build variant (hdr, lib); rows = model (dof), columns =
algo; each cell lists the median ns/call of every given file, separated by
" / " (in the order the files are given).

--best: a single table whose cell is the lowest median over all variants and
files, with the variant that achieved it -- the conservative "Pinocchio
baseline to beat".
"""
import json
import sys
from collections import OrderedDict

ALGOS = ["fk", "jacobians", "rnea", "crba", "crba_upper", "aba"]


def label_of(model, urdf):
    """erd/<stem> for example-robot-data files, robots/<stem> for the repo's."""
    if "example-robot-data" in urdf:
        return "erd/" + model
    if "/robots/" in urdf:
        return "robots/" + model
    return model


def load(path):
    rows = []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line:
                rows.append(json.loads(line))
    return rows


def best(paths):
    runs = [load(p) for p in paths]
    cells, models = {}, OrderedDict()
    for rows in runs:
        for r in rows:
            key = (r["model"], r.get("urdf", ""), r.get("mimic", False))
            models.setdefault(key, r["dof"])
            c = cells.get((key, r["algo"]))
            if c is None or r["ns_per_call"] < c[0]:
                cells[(key, r["algo"])] = (r["ns_per_call"], r["variant"])
    print("| model | dof | " + " | ".join(ALGOS) + " |")
    print("|---|---:|" + "---:|" * len(ALGOS))
    for key, dof in models.items():
        model, urdf, mimic = key
        row = []
        for a in ALGOS:
            c = cells.get((key, a))
            row.append(f"{c[0]:.0f} ({c[1]})" if c else "–")
        label = label_of(model, urdf) + (" (mimic)" if mimic else "")
        print(f"| {label} | {dof} | " + " | ".join(row) + " |")


def main(paths):
    runs = [load(p) for p in paths]
    variants, models = [], OrderedDict()
    for rows in runs:
        for r in rows:
            if r["variant"] not in variants:
                variants.append(r["variant"])
            key = (r["model"], r.get("urdf", ""), r.get("mimic", False))
            models.setdefault(key, r["dof"])
    for v in variants:
        print(f"\n**variant `{v}`** — median ns per call" + (f" (runs: {' / '.join(paths)})" if len(paths) > 1 else ""))
        print()
        print("| model | dof | " + " | ".join(ALGOS) + " |")
        print("|---|---:|" + "---:|" * len(ALGOS))
        for (model, urdf, mimic), dof in models.items():
            cells = []
            for a in ALGOS:
                vals = []
                for rows in runs:
                    m = [r for r in rows if r["variant"] == v and r["model"] == model
                         and r.get("urdf", "") == urdf and r.get("mimic", False) == mimic and r["algo"] == a]
                    vals.append(f"{m[0]['ns_per_call']:.0f}" if m else "–")
                cells.append(" / ".join(vals))
            label = label_of(model, urdf) + (" (mimic)" if mimic else "")
            print(f"| {label} | {dof} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    args = sys.argv[1:]
    if args and args[0] == "--best":
        if len(args) < 2:
            sys.exit(__doc__)
        best(args[1:])
    else:
        if not args:
            sys.exit(__doc__)
        main(args)
