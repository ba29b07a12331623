#!/usr/bin/env python3
"""Where a generated solver's time goes: instructions per call and code bytes per pass.

Generates one shared case with PROXGEN, compiles its .cpp alone (g++, -std=c++17
-fno-tree-slp-vectorize -DNDEBUG and OPT, default -O3: the bench's flags at the
x86-64 baseline; valgrind cannot run AVX-512, so no -march), links it to
tests/generated/icount.cpp and runs it under callgrind with N calls and with none.
The part functions are noinline, so the self cost of each function, grouped by
its pass (the part names are <host>_<pass>_<first block>..., docs/emitter.md,
"Part functions"), minus the run without calls, over N, is that pass's share of
one call; `nm -S` gives the code bytes of the same groups.

    pass_costs.py PROXGEN CASE [--opt -O3] [--calls 200] [--models ../shared/models] [--keep DIR]

Deterministic (fixed state, fixed code). Used for docs/benchmarks.md, "Where the
time goes on the large robots".
"""
import argparse
import collections
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def group(fn):
    """The pass a generated function belongs to (host_pass_block, or a shared function's name)."""
    fn = fn.replace("(anonymous namespace)::", "").split("(")[0].split("::")[-1]
    m = re.match(r"(caba|pv)_([a-z]+)", fn)
    if m:
        return m.group(1) + "_" + m.group(2)
    for shared in ("kinematics", "eliminate_free", "accelerate_free"):
        if fn.startswith(shared):
            return shared
    if fn.startswith("constrained_aba"):
        return "caba_host"
    if fn.startswith("prox_pv"):
        return "pv_host"
    return None


def run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.exit(f"pass_costs: {' '.join(cmd)} failed:\n{r.stderr[-2000:]}")
    return r.stdout


def self_costs(exe, calls, algorithm, work):
    out = os.path.join(work, f"cg.{algorithm}.{calls}")
    run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", exe, str(calls), str(algorithm)])
    costs = collections.Counter()
    for line in run(["callgrind_annotate", "--threshold=100", out]).splitlines():
        m = re.match(r"\s*([\d,]+)\s+(?:\([^)]*\)\s+)?\?\?\?:(.*)$", line)
        if m and (g := group(m.group(2))):
            costs[g] += int(m.group(1).replace(",", ""))
        t = re.match(r"\s*([\d,]+)\s+.*PROGRAM TOTALS", line)
        if t:
            costs["(total)"] = int(t.group(1).replace(",", ""))
    return costs


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("proxgen")
    ap.add_argument("case")
    ap.add_argument("--opt", default="-O3")
    ap.add_argument("--calls", type=int, default=200)
    ap.add_argument("--models", default=os.path.join(ROOT, "..", "shared", "models"))
    ap.add_argument("--keep", help="generate and compile into this folder (default: a temporary one)")
    args = ap.parse_args()
    work = args.keep or tempfile.mkdtemp(prefix="pass_costs.")
    os.makedirs(work, exist_ok=True)
    c = args.case
    run([args.proxgen, "generate", "--cases", os.path.join(args.models, "cases.yaml"), "--case", c, "--out", work,
         "--name", c])
    obj = os.path.join(work, c + ".o")
    exe = os.path.join(work, "icount")
    run(["g++", "-std=c++17", "-fno-tree-slp-vectorize", args.opt, "-DNDEBUG", "-fno-exceptions", "-fno-rtti",
         "-I" + os.path.join(ROOT, "runtime"), "-I" + work, "-c", os.path.join(work, c + ".cpp"), "-o", obj])
    run(["g++", "-std=c++17", "-O2", "-I" + work, f'-DSOLVER_HEADER="{c}.hpp"', f"-DSOLVER={c}",
         os.path.join(ROOT, "tests", "generated", "icount.cpp"), obj, "-o", exe])
    sizes = collections.Counter()
    for line in run(["nm", "-S", "-C", obj]).splitlines():
        p = line.split()
        if len(p) >= 4 and p[2] in "tTW" and (g := group(" ".join(p[3:]))):
            sizes[g] += int(p[1], 16)
    print(f"{c}, {args.opt}, {args.calls} calls; text {sum(sizes.values())} bytes in the solver's functions")
    for algorithm, name in ((0, "constrained_aba"), (1, "prox_pv")):
        with_calls = self_costs(exe, args.calls, algorithm, work)
        without = self_costs(exe, 0, algorithm, work)
        total = (with_calls["(total)"] - without["(total)"]) / args.calls
        print(f"\n{name}: {total:.0f} instructions per call\n\n| pass | Ir per call | share | code bytes |\n|---|---|---|---|")
        rows = [(g, (with_calls[g] - without[g]) / args.calls) for g in with_calls if g != "(total)"]
        for g, ir in sorted(rows, key=lambda r: -r[1]):
            if ir >= 1:
                print(f"| {g} | {ir:.0f} | {100 * ir / total:.1f} % | {sizes.get(g, 0)} |")


if __name__ == "__main__":
    main()
