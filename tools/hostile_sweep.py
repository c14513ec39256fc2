#!/usr/bin/env python3
"""One-value mutations of every bundled scenario, run through `armsim run`: each numeric
literal in turn is replaced by a hostile value (nan, ±inf, ±1e308, 1e-300, 0, -1), and the
run is judged under a time limit and a memory cap.

Verdicts (issue 28's rule: no panic, no signal, no hang, no runaway memory, no exit 0 on
an input that must be refused, and a message naming the file):
  ok        refused with a message naming the file, or accepted (a finite value)
  PANIC     "panicked" in stderr
  SIGNAL    killed by a signal (abort, out of memory under the cap)
  HANG      over the time limit
  ACCEPTED  exit 0 with a non-finite value written into the file
  NONFINITE exit 0 with NaN or inf in the printed report
  UNNAMED   refused without naming the file

Usage: python3 tools/hostile_sweep.py [--bin target/release/armsim] [--jobs 2]
       [--timeout 30] [--values nan,inf,...] [--only SUBSTRING] [--sample N] [--seed S]
       [--replay PREVIOUS.jsonl]
Writes one JSON line per run to --out (default /tmp/hostile_sweep.jsonl) and prints the
counts and every non-ok case.
"""
import argparse, concurrent.futures as cf, json, os, random, re, resource, shutil
import subprocess, sys, tempfile, time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
NUM = re.compile(r"(?<![\w.\"'-])-?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.\"'])")
STR = re.compile(r"\"(?:[^\"\\]|\\.)*\"|'[^']*'")
NONFINITE = {"nan", "inf", "-inf", "+inf"}


def numeric_spans(text):
    """(start, end) of every numeric literal outside strings and comments."""
    spans, pos = [], 0
    for line in text.splitlines(keepends=True):
        code = line.split("#", 1)[0] if "#" in line and not STR.search(line) else line
        masked = STR.sub(lambda m: " " * len(m.group()), code)
        if "#" in masked:
            masked = masked[: masked.index("#")]
        # skip table headers and the left-hand side of assignments
        eq = masked.find("=")
        if masked.lstrip().startswith("["):
            if eq < 0:
                pos += len(line)
                continue
        for m in NUM.finditer(masked):
            if eq >= 0 and m.start() < eq:
                continue
            spans.append((pos + m.start(), pos + m.end()))
        pos += len(line)
    return spans


def limit_memory(cap):
    def f():
        resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
    return f


def run_one(args, scenario, start, end, value, work):
    text = scenario.read_text()
    mutated = text[:start] + value + text[end:]
    line = text.count("\n", 0, start) + 1
    d = Path(tempfile.mkdtemp(dir=work))
    (d / "scenarios").mkdir()
    for sub in ("robots", "meshes"):
        if (ROOT / sub).exists():
            os.symlink(ROOT / sub, d / sub)
    # sibling files a scenario may name (gear trains, tables)
    for other in scenario.parent.iterdir():
        if other != scenario:
            os.symlink(other, d / "scenarios" / other.name)
    f = d / "scenarios" / scenario.name
    assert not f.exists(), f"{f} must be a fresh file, not a link to the original"
    f.write_text(mutated)
    t0 = time.time()
    try:
        p = subprocess.run([args.bin, "run", str(f)], cwd=d / "scenarios", capture_output=True,
                           timeout=args.timeout, preexec_fn=limit_memory(args.memory))
        rc, out, err = p.returncode, p.stdout.decode(errors="replace"), p.stderr.decode(errors="replace")
    except subprocess.TimeoutExpired:
        rc, out, err = None, "", ""
    dt = time.time() - t0
    shutil.rmtree(d, ignore_errors=True)
    if rc is None:
        verdict = "HANG"
    elif "panicked" in err:
        verdict = "PANIC"
    elif rc < 0:
        verdict = "SIGNAL"
    elif rc == 0 and value.lower() in NONFINITE:
        verdict = "ACCEPTED"
    elif rc == 0 and re.search(r"(?<![\w])(NaN|-?inf)(?![\w])", out):
        verdict = "NONFINITE"
    elif rc != 0 and scenario.name not in err:
        verdict = "UNNAMED"
    else:
        verdict = "ok"
    first = (err.strip().splitlines() or [""])[0][:300]
    return dict(file=scenario.name, line=line, was=text[start:end], value=value, rc=rc,
                seconds=round(dt, 2), verdict=verdict, stderr=first)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default=str(ROOT / "target/release/armsim"))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=30)
    ap.add_argument("--memory", type=int, default=4 << 30)
    ap.add_argument("--values", default="nan,inf,-inf,1e308,-1e308,1e-300,0,-1")
    ap.add_argument("--only", default="")
    ap.add_argument("--sample", type=int, default=0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", default="/tmp/hostile_sweep.jsonl")
    ap.add_argument("--replay", default="", help="re-run the cases of a previous --out "
                    "that were not ok (same file, line, old and new value)")
    args = ap.parse_args()
    values = args.values.split(",")
    cases = []
    for s in sorted((ROOT / "scenarios").glob("*.toml")):
        if args.only and args.only not in s.name:
            continue
        for a, b in numeric_spans(s.read_text()):
            for v in values:
                cases.append((s, a, b, v))
    if args.replay:
        want = {(r["file"], r["line"], r["was"], r["value"])
                for r in map(json.loads, open(args.replay)) if r["verdict"] != "ok"}
        cases = [c for c in cases
                 if (c[0].name, c[0].read_text().count("\n", 0, c[1]) + 1,
                     c[0].read_text()[c[1]:c[2]], c[3]) in want]
    elif args.sample and args.sample < len(cases):
        random.Random(args.seed).shuffle(cases)
        cases = cases[: args.sample]
    work = tempfile.mkdtemp(prefix="hostile_sweep_")
    bad, counts = [], {}
    with open(args.out, "w") as out, cf.ThreadPoolExecutor(args.jobs) as pool:
        futs = [pool.submit(run_one, args, *c, work) for c in cases]
        for fu in cf.as_completed(futs):
            r = fu.result()
            out.write(json.dumps(r) + "\n")
            counts[r["verdict"]] = counts.get(r["verdict"], 0) + 1
            if r["verdict"] != "ok":
                bad.append(r)
    shutil.rmtree(work, ignore_errors=True)
    print(f"{len(cases)} runs: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    for r in sorted(bad, key=lambda r: (r["verdict"], r["file"], r["line"])):
        print(f"{r['verdict']:9} {r['file']}:{r['line']} {r['was']} -> {r['value']} "
              f"({r['seconds']} s, rc {r['rc']}): {r['stderr']}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
