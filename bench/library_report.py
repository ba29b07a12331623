#!/usr/bin/env python3
"""Writes the dynamics library's section of bench/RESULTS.md (docs/benchmarks.md, "The dynamics library").

    library_report.py --build BUILD_DIR --timings library.json [--calls library-calls.json]
                      [--scaling delassus-scaling.json] --results bench/RESULTS.md --command "..."

Inputs: the Google Benchmark JSON of proxgen_bench_joint_space (with repetitions and
aggregates), the instruction counts of `count_calls.py --library`, and the JSON of
delassus_scaling.py. The section, from its heading to the end of the file or to the next
heading of the same level, is replaced if RESULTS.md has it, appended otherwise; the rest of
the file (bench/report.py's) is left as it is. Standard library only.
"""
import argparse
import datetime
import json
import os
import platform
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from report import cpu_description, fmt_ir, fmt_ratio, fmt_us, medians  # noqa: E402

HEADING = "## The dynamics library: generated functions against their generic twins"

FUNCTIONS = ["inverse_dynamics", "nonlinear_effects", "mass_matrix", "mass_matrix_inverse", "constraint_placements",
             "constraint_jacobian", "constraint_drift", "delassus", "delassus_inverse"]
GENERIC = {"inverse_dynamics": "inverseDynamics (RNEA + J^T lambda)", "nonlinear_effects": "nonLinearEffects",
           "mass_matrix": "crba", "mass_matrix_inverse": "massMatrixInverse",
           "constraint_placements": "constraintPlacements", "constraint_jacobian": "constraintJacobianRows",
           "constraint_drift": "constraintDrift", "delassus": "delassus", "delassus_inverse": "delassusInverse"}

# Pinocchio 3.7 on this machine kind (AMD EPYC, 2 vCPUs), 2026-12-01, g++ -O3: median µs per
# call over 200 random states x 30 repetitions. rnea, crba (WORLD), computeMinverse and
# computeDampedDelassusMatrixInverse at mu = 1e4 (Pinocchio's 1e-4). Not measured in this run.
PINOCCHIO = {
    # case: (rnea, crba, Minv, damped Delassus inverse)
    "iiwa_h3": (0.70, 0.55, 1.04, 1.25),
    "iiwa_h6": (0.70, 0.55, 1.02, 1.48),
    "solo_f3x2": (1.35, 1.15, 2.60, 2.98),
    "solo_f3x4": (1.33, 1.15, 2.59, 3.82),
    "talos_f6x2": (4.65, 3.87, 10.2, 7.85),
    "talos_f6x2_h6x2": (4.60, 3.85, 10.3, 9.53),
    "atlas_shadow_f6x2": (8.34, 7.18, 23.0, 12.7),
    "atlas_shadow_f6x2_t3x5": (8.32, 7.22, 23.1, 17.2),
    "atlas_shadow_f6x2_t3x10": (8.55, 7.36, 23.6, 21.5),
}
CASE_ORDER = list(PINOCCHIO)
TARGET = 1.0 / 3.0  # issue 14: generated inverse_dynamics and mass_matrix at most a third of rnea and crba


def compiler(build_dir):
    cfg = os.path.join(build_dir, "bench", "bench_config.json")
    with open(cfg) as f:
        config = json.load(f)
    try:
        version = subprocess.run([config["cxx"], "--version"], stdout=subprocess.PIPE, text=True).stdout.splitlines()[0]
    except (OSError, IndexError):
        version = config["cxx"]
    return version, config


def timing_tables(t, calls, cases):
    out = []
    for fn in FUNCTIONS:
        out.append(f"### `{fn}` (generic twin: `{GENERIC[fn]}`)\n")
        out.append("| case | nv | m | generated µs | generic µs | gen / generic time | generated Ir | generic Ir | "
                   "gen / generic Ir |")
        out.append("|---|---|---|---|---|---|---|---|---|")
        for c in cases:
            g, r = t.get(f"{c}/{fn}/generated"), t.get(f"{c}/{fn}/generic")
            gi, ri = calls.get((c, f"{fn}/generated")), calls.get((c, f"{fn}/generic"))
            nv, m = SIZES.get(c, ("?", "?"))
            out.append(f"| {c} | {nv} | {m} | {fmt_us(g)} | {fmt_us(r)} | {fmt_ratio(g, r)} | {fmt_ir(gi)} | "
                       f"{fmt_ir(ri)} | {fmt_ratio(gi, ri)} |")
        out.append("")
    return out


def target_table(t, cases):
    out = ["| case | inverse_dynamics µs | Pinocchio rnea µs | ratio | ≤ 1/3? | mass_matrix µs | Pinocchio crba µs | "
           "ratio | ≤ 1/3? | mass_matrix_inverse µs | Pinocchio Minv µs | ratio | delassus_inverse µs | "
           "Pinocchio damped Delassus inverse µs | ratio |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for c in cases:
        if c not in PINOCCHIO:
            continue
        rnea, crba, minv, dinv = PINOCCHIO[c]
        idt, mmt = t.get(f"{c}/inverse_dynamics/generated"), t.get(f"{c}/mass_matrix/generated")
        mit, dit = t.get(f"{c}/mass_matrix_inverse/generated"), t.get(f"{c}/delassus_inverse/generated")
        met = lambda x, p: "—" if x is None else ("yes" if x / p <= TARGET else "no")
        out.append(f"| {c} | {fmt_us(idt)} | {rnea} | {fmt_ratio(idt, rnea)} | {met(idt, rnea)} | {fmt_us(mmt)} | "
                   f"{crba} | {fmt_ratio(mmt, crba)} | {met(mmt, crba)} | {fmt_us(mit)} | {minv} | "
                   f"{fmt_ratio(mit, minv)} | {fmt_us(dit)} | {dinv} | {fmt_ratio(dit, dinv)} |")
    return out


def route_table(t, calls, cases):
    out = ["| case | nv | m | delassus_inverse µs | route through mass_matrix µs | generated / route time | "
           "delassus_inverse Ir | route Ir | generated / route Ir |",
           "|---|---|---|---|---|---|---|---|---|"]
    for c in cases:
        g, r = t.get(f"{c}/delassus_inverse/generated"), t.get(f"{c}/delassus_inverse/route_mass_matrix")
        gi, ri = calls.get((c, "delassus_inverse/generated")), calls.get((c, "delassus_inverse/route_mass_matrix"))
        nv, m = SIZES.get(c, ("?", "?"))
        out.append(f"| {c} | {nv} | {m} | {fmt_us(g)} | {fmt_us(r)} | {fmt_ratio(g, r)} | {fmt_ir(gi)} | {fmt_ir(ri)} | "
                   f"{fmt_ratio(gi, ri)} |")
    return out


def scaling_tables(s):
    out = []
    fits = s["fits"]
    out.append("| shape | cost | sweep | range | slope (all) | slope (three largest) |")
    out.append("|---|---|---|---|---|---|")
    for f in fits:
        if "sweep" not in f:
            continue
        what = "n at m = 6" if f["sweep"] == "n" else f"m at n = {f['sweep'].split('@')[1]}"
        cost = "time" if f["cost"] == "median_us" else "Ir"
        out.append(f"| {f['shape']} | {cost} | {what} | {f['range'][0]}–{f['range'][1]} | {f['slope_all']:.2f} | "
                   f"{f['slope_upper']:.2f} |")
    out.append("")
    out.append("Least squares over every (n, m) of a shape, weighted by 1/cost (relative residuals); "
               "coefficients in the cost's unit:")
    out.append("")
    out.append("| shape | cost | model | coefficients | largest relative residual | rms relative residual |")
    out.append("|---|---|---|---|---|---|")
    for f in fits:
        if "model" not in f:
            continue
        cost = "time (µs)" if f["cost"] == "median_us" else "Ir"
        coef = ", ".join(f"{name}: {c:.4g}" for name, c in f["coefficients"].items())
        out.append(f"| {f['shape']} | {cost} | {f['model']} | {coef} | {100 * f['max_rel_residual']:.1f} % | "
                   f"{100 * f['rms_rel_residual']:.1f} % |")
    out.append("")
    out.append("Points (CPU µs per call, median; Ir per call):")
    out.append("")
    out.append("| shape | n | m | median µs | min µs | Ir/call |")
    out.append("|---|---|---|---|---|---|")
    seen = set()
    for p in sorted(s["points"], key=lambda p: (p["shape"], p["n"], p["m"])):
        if (p["shape"], p["n"], p["m"]) in seen:
            continue
        seen.add((p["shape"], p["n"], p["m"]))
        out.append(f"| {p['shape']} | {p['n']} | {p['m']} | {fmt_us(p['median_us'])} | {fmt_us(p['min_us'])} | "
                   f"{fmt_ir(p.get('ir_per_call'))} |")
    return out


SIZES = {}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", required=True)
    ap.add_argument("--timings", required=True)
    ap.add_argument("--calls")
    ap.add_argument("--scaling")
    ap.add_argument("--results", required=True)
    ap.add_argument("--command", required=True, help="the commands that produced the inputs, for the text")
    ap.add_argument("--load", default="", help="load average at the start of the timed run")
    args = ap.parse_args()

    t_all, context = medians(args.timings)
    t = {k: v[0] for k, v in t_all.items()}
    calls = {}
    if args.calls:
        with open(args.calls) as f:
            calls = {(r["case"], r["algorithm"]): r["ir_per_call"] for r in json.load(f)}
    cases = [c for c in CASE_ORDER if any(k.startswith(c + "/") for k in t)]
    for name, (_, _, counters) in t_all.items():
        if "nv" in counters:
            SIZES[name.split("/")[0]] = (int(counters["nv"]), int(counters["nc"]))
    version, config = compiler(args.build)
    flags = " ".join(["-O3 -DNDEBUG"] + ([f"-march={config['march']}"] if config["march"] else []))
    date = context.get("date", datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"))

    s = [HEADING, ""]
    s.append(f"Written by `bench/library_report.py` from one run ({date}, host {platform.node() or '?'}, "
             f"{context.get('num_cpus', '?')} CPUs at {context.get('mhz_per_cpu', '?')} MHz"
             f"{', load average ' + args.load + ' at the start' if args.load else ''}; the machine is shared with "
             f"other work, so the times are medians of repetitions and the ratios, taken in the same run, are "
             f"what to read). Processor: {cpu_description()}. Compiler: {version}. Everything, generic and "
             f"generated, compiled with `{flags}` (the generated sources also with proxgen_add_solver's "
             f"`{' '.join(config['solver_options'])}`); the x86-64 baseline, so callgrind can run it "
             f"(this valgrind does not decode AVX-512). mu = 1e4. Method: docs/benchmarks.md, \"The dynamics "
             f"library\".")
    s.append("")
    s.append("Commands:")
    s.append("")
    s.append("```sh")
    s.extend(args.command.split(" ;; "))
    s.append("```")
    s.append("")
    s.append("Time: median over the repetitions of the mean CPU time per call, 1000 random states cycled (the "
             "same states for both sides). Ir: instructions per call under callgrind, "
             "(run with N calls - run with none) / N, deterministic.")
    s.append("")
    s.append("### Against Pinocchio 3.7 (issue 14's target)")
    s.append("")
    s.append("Pinocchio 3.7, measured on this machine on 2026-12-01 at -O3, not in this run (median µs per call, "
             "200 random states x 30 repetitions; `rnea`, `crba`, `computeMinverse`, "
             "`computeDampedDelassusMatrixInverse` at mu = 1e4). The target: generated `inverse_dynamics` and "
             "`mass_matrix` at most a third of `rnea` and `crba`. Ratio = generated / Pinocchio.")
    s.append("")
    s.extend(target_table(t, cases))
    s.append("")
    s.append("### `delassus_inverse` against the route through `mass_matrix`")
    s.append("")
    s.append("The route: the generated `mass_matrix` and `constraint_jacobian`, Eigen's fixed-size LLT of M, "
             "`J M^-1 J^T + I/mu`, its LLT and the inverse (bench_joint_space.cpp, `Route`), on the same states "
             "in the same run. Below 1: the generated recursion is faster.")
    s.append("")
    s.extend(route_table(t, calls, cases))
    s.append("")
    if args.scaling:
        with open(args.scaling) as f:
            scaling = json.load(f)
        s.append("### `delassus_inverse` against n and m (synthetic robots)")
        s.append("")
        s.append("The scaling study's serial chains and binary trees of n revolute joints on a fixed base with m/3 "
                 "point contacts (bench/synthetic.cpp); each generated with `--functions delassus_inverse` and "
                 "compiled alone with the flags above (bench/delassus_scaling.py). Time: CPU time, median of the "
                 "repetitions of ~20 ms batches over 64 random configurations; Ir: callgrind, as above. "
                 "O(n + m^2) predicts a slope of 1 against n at fixed m, and against m at fixed n a slope that "
                 "rises towards 2 as the m^2 part overtakes the n part. The times share the machine with other "
                 "work and move by tens of percent from point to point: fit the instruction counts.")
        s.append("")
        s.extend(scaling_tables(scaling))
        s.append("")
    s.append("### Every function against its generic twin")
    s.append("")
    s.extend(timing_tables(t, calls, cases))

    section = "\n".join(s).rstrip() + "\n"
    text = open(args.results).read() if os.path.exists(args.results) else "# Benchmark results\n"
    start = text.find(HEADING)
    if start >= 0:
        nxt = re.search(r"^## ", text[start + len(HEADING):], re.M)
        end = start + len(HEADING) + nxt.start() if nxt else len(text)
        text = text[:start] + section + ("\n" + text[end:] if nxt else "")
    else:
        text = text.rstrip() + "\n\n" + section
    with open(args.results, "w") as f:
        f.write(text)
    print(f"library_report: wrote the section into {args.results}")


if __name__ == "__main__":
    main()
