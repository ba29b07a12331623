#!/usr/bin/env python3
"""Instructions per call of each (case, algorithm) under callgrind.

Runs `proxgen_bench_calls CASE ALGORITHM N` under `valgrind --tool=callgrind`
twice, with N calls and with none, and reports (Ir(N) - Ir(0)) / N: loading the
model, drawing the states and building the work space cost the same in both
runs, so only the calls remain. Deterministic (same states, same code).

    count_calls.py BUILD_DIR OUT.json [--calls N] [--cases a,b] [--algorithms x,y]
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile

ALGORITHMS = ["aba", "caba", "pv", "ltl", "ltls", "gen_caba", "gen_pv"]
NOT_BUILT = 3  # proxgen_bench_calls' exit code for an algorithm this build lacks


def case_names(cases_yaml):
    """The `- name:` entries of cases.yaml, in order (the file's own simple shape)."""
    with open(cases_yaml) as f:
        return re.findall(r"^\s*-\s*name:\s*(\S+)\s*$", f.read(), re.M)


def instructions(driver, case, algorithm, calls, workdir):
    """Total Ir of one run, or None when the algorithm is not built."""
    out = os.path.join(workdir, f"callgrind.{case}.{algorithm}.{calls}")
    cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", driver, case, algorithm, str(calls)]
    run = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if run.returncode == NOT_BUILT:
        return None
    if run.returncode != 0:
        sys.exit(f"count_calls: {' '.join(cmd)} failed:\n{run.stderr[-2000:]}")
    with open(out) as f:
        for line in f:
            if line.startswith("summary:") or line.startswith("totals:"):
                return int(line.split()[1])
    sys.exit(f"count_calls: no totals in {out}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("build_dir")
    ap.add_argument("out")
    ap.add_argument("--calls", type=int, default=1000)
    ap.add_argument("--cases", help="comma-separated (default: every case of cases.yaml)")
    ap.add_argument("--algorithms", default=",".join(ALGORITHMS))
    args = ap.parse_args()

    with open(os.path.join(args.build_dir, "CMakeCache.txt")) as f:
        models = re.search(r"^PROXGEN_MODELS_DIR:PATH=(.*)$", f.read(), re.M).group(1)
    cases = args.cases.split(",") if args.cases else case_names(os.path.join(models, "cases.yaml"))
    driver = os.path.join(args.build_dir, "bench", "proxgen_bench_calls")

    results = []
    with tempfile.TemporaryDirectory(prefix="proxgen-callgrind-") as work:
        for case in cases:
            for algorithm in args.algorithms.split(","):
                full = instructions(driver, case, algorithm, args.calls, work)
                if full is None:
                    print(f"{case:26s} {algorithm:9s} not built", flush=True)
                    continue
                base = instructions(driver, case, algorithm, 0, work)
                per_call = (full - base) / args.calls
                results.append({"case": case, "algorithm": algorithm, "ir_per_call": per_call,
                                "ir_total": full, "ir_baseline": base, "calls": args.calls})
                print(f"{case:26s} {algorithm:9s} {per_call:12,.0f} Ir/call", flush=True)
    with open(args.out, "w") as f:
        json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
