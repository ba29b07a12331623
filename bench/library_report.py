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

# Pinocchio's damped Delassus inverse (computeDampedDelassusMatrixInverse at mu = 1e4, Pinocchio's
# 1e-4), measured on this machine kind on 2026-12-01 at -O3 (median µs per call over 200 random states
# x 30 repetitions), NOT in the run: bench_joint_space.cpp does not time it. rnea, nonLinearEffects,
# crba and computeMinverse are timed in the run itself (<case>/<function>/pinocchio).
PINOCCHIO_DELASSUS_INVERSE = {
    "iiwa_h3": 1.25, "iiwa_h6": 1.48, "solo_f3x2": 2.98, "solo_f3x4": 3.82, "talos_f6x2": 7.85,
    "talos_f6x2_h6x2": 9.53, "atlas_shadow_f6x2": 12.7, "atlas_shadow_f6x2_t3x5": 17.2,
    "atlas_shadow_f6x2_t3x10": 21.5,
}
CASE_ORDER = list(PINOCCHIO_DELASSUS_INVERSE)
# (generated function, Pinocchio variant, Pinocchio's name) of the same-run table.
PINOCCHIO_PAIRS = [
    ("inverse_dynamics", "pinocchio", "rnea"),
    ("nonlinear_effects", "pinocchio", "nonLinearEffects"),
    ("mass_matrix", "pinocchio", "crba + lower copy"),
    ("mass_matrix", "pinocchio_upper", "crba alone"),
    ("mass_matrix", "pinocchio_world", "crba WORLD + lower copy"),
    ("mass_matrix_inverse", "pinocchio", "computeMinverse + lower copy"),
    ("mass_matrix_inverse", "pinocchio_upper", "computeMinverse alone"),
]
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


def target_table(t, calls, cases):
    """Generated against Pinocchio, same run: one row per (case, function, Pinocchio variant)."""
    out = ["| case | generated function | Pinocchio | generated µs | Pinocchio µs | time ratio | ≤ 1/3? | "
           "generated Ir | Pinocchio Ir | Ir ratio |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    for c in cases:
        for fn, variant, pin_name in PINOCCHIO_PAIRS:
            g, p = t.get(f"{c}/{fn}/generated"), t.get(f"{c}/{fn}/{variant}")
            if p is None:
                continue
            gi, pi = calls.get((c, f"{fn}/generated")), calls.get((c, f"{fn}/{variant}"))
            met = "—" if g is None else ("yes" if g / p <= TARGET else "no")
            out.append(f"| {c} | `{fn}` | `{pin_name}` | {fmt_us(g)} | {fmt_us(p)} | {fmt_ratio(g, p)} | {met} | "
                       f"{fmt_ir(gi)} | {fmt_ir(pi)} | {fmt_ratio(gi, pi)} |")
    return out


def delassus_anchor_table(t, cases):
    if not any(t.get(f"{c}/delassus_inverse/generated") is not None for c in cases):
        return []  # a run without delassus_inverse (--benchmark_filter): nothing to set beside the figures
    out = ["| case | delassus_inverse µs (this run) | Pinocchio damped Delassus inverse µs (2026-12-01, not this run) | "
           "ratio |", "|---|---|---|---|"]
    for c in cases:
        d, p = t.get(f"{c}/delassus_inverse/generated"), PINOCCHIO_DELASSUS_INVERSE.get(c)
        if p is not None:
            out.append(f"| {c} | {fmt_us(d)} | {p} | {fmt_ratio(d, p)} |")
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


def pinocchio_subsection(t, calls, cases, run=None):
    """The same-run comparison with Pinocchio; `run`: lines saying which run, when it is not the section's."""
    s = []
    s.append("### Against Pinocchio 3.7 in the same run (issue 14's target)")
    s.append("")
    s.append("Pinocchio 3.7 (an install outside the repository, found by CMake: bench/pinocchio.cmake) in the same "
             "process on the same states and qdd (bench_pinocchio.cpp, `pinocchioJointSpace`, interleaved with the "
             "generated functions by the random interleaving), each checked against the generic twin before any "
             "timing. `rnea` has no constraint forces; the generated `inverse_dynamics` adds `J^T lambda` for the "
             "case's constraints (more work, not less). `crba` and `computeMinverse` fill the upper triangle only: "
             "\"+ lower copy\" copies it to the lower one (the full matrix, what the generated functions return: "
             "the fair comparison), \"alone\" is Pinocchio's call by itself. `crba` runs in Pinocchio 3.7's default "
             "LOCAL convention, and in its WORLD convention (the anchor figures of 2026-12-01 used WORLD) with the "
             "copy: the targets are held against the faster of the two. The target: generated "
             "`inverse_dynamics` and `mass_matrix` at most a third of `rnea` and `crba`. Ratio = generated / "
             "Pinocchio; Ir from callgrind on the same build.")
    s.append("")
    s.extend(run or [])
    s.extend(target_table(t, calls, cases))
    s.append("")
    anchor = delassus_anchor_table(t, cases)
    if anchor:
        s.append("`delassus_inverse` against Pinocchio's damped Delassus inverse, which this run does not time (the "
                 "figures measured on 2026-12-01 on this machine kind):")
        s.append("")
        s.extend(anchor)
        s.append("")
    return s


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
    ap.add_argument("--pinocchio-only", action="store_true",
                    help="replace only the subsection against Pinocchio (from its heading to the next ###) in the "
                         "existing section, with this run's context and commands")
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

    if args.pinocchio_only:
        run = [f"From its own run ({date}, host {platform.node() or '?'}, {context.get('num_cpus', '?')} CPUs"
               f"{', load average ' + args.load + ' at the start' if args.load else ''}; the machine shared with "
               f"other work), compiled with `{flags}` (the generated sources also with "
               f"`{' '.join(config['solver_options'])}`), {version}, the x86-64 baseline. Commands:", "", "```sh",
               *args.command.split(" ;; "), "```", "",
               "Ir: a \"—\" where the case was not counted. `mass_matrix` and `mass_matrix_inverse` are the same "
               "code for every layout of a robot (they do not read the constraints), so one case per robot gives "
               "their instructions. The time ratio at the target is the one of this run's load; the Ir ratio is "
               "deterministic. Below, mass_matrix_inverse's \"<= 1/3?\" is only for reading: the issue sets no "
               "target for it. Where the generated `mass_matrix` zeroes `M` in one fill before its pass (Talos, "
               "the Atlas: pass_mass_matrix.cpp, `fillFirst`), glibc's `memset` does it with `rep stosb`, which "
               "callgrind counts once per byte (`8 nv^2`: 20,000 on Talos, 56,448 on the Atlas): its Ir is "
               "that much above the instructions the processor decodes, so read its time.", ""]
        sub = "\n".join(pinocchio_subsection(t, calls, cases, run)).rstrip() + "\n\n"
        text = open(args.results).read()
        start = text.find("### Against Pinocchio 3.7")
        if start < 0 or text.find(HEADING) < 0:
            sys.exit(f"library_report: no subsection against Pinocchio in {args.results} to replace")
        nxt = re.search(r"^##+ ", text[start + 4:], re.M)
        end = start + 4 + nxt.start() if nxt else len(text)
        with open(args.results, "w") as f:
            f.write(text[:start] + sub + text[end:])
        print(f"library_report: replaced the subsection against Pinocchio in {args.results}")
        return

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
    s.extend(pinocchio_subsection(t, calls, cases))
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
