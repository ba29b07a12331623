#!/usr/bin/env python3
"""Writes bench/RESULTS.md and its plots from one run of bench/run.sh.

    report.py --build BUILD_DIR --suite suite.json --calls calls.json
              --scaling scaling.json --python python.json --out-dir bench/ [--no-compile]
    report.py --build BUILD_DIR --python python.json --section python   # that section alone, on stdout
    report.py --build BUILD_DIR --suite suite.json --section peers [--out-dir bench/]   # the peers, and the plot

Inputs: the Google Benchmark JSON of proxgen_bench and proxgen_bench_scaling
(run with repetitions and aggregates), the instruction counts of count_calls.py,
the JSON of python_overhead.py, and BUILD_DIR/bench/bench_config.json (compiler,
-march and generated sources, for the compile time and object size of each
generated solver). Standard library only; plots through gnuplot.
"""
import argparse
import json
import math
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time

# Pinocchio 3.7 timings measured by the project's steering team on an AVX-512 EPYC
# (KVM guest, 2 vCPUs), K = 3, mu = 1e4 (its mu = 1e-4), median of 60 repetitions;
# Ir = callgrind instructions per call. The same figures, with how they were taken:
# docs/benchmarks.md, "Anchor figures".
ANCHOR = {
    # case: (nv, rows, aba us, cABA us, PV us, proxLTL us, aba Ir, cABA Ir, PV Ir)
    "iiwa_h3": (7, 3, 1.43, 1.89, 1.77, 2.04, 17163, 23942, 25060),
    "iiwa_h6": (7, 6, 1.42, 1.93, 2.31, 2.60, 17163, 24661, 32524),
    "solo_f3x2": (18, 6, 3.10, 3.54, 3.75, 4.46, 38347, 46436, 50678),
    "solo_f3x4": (18, 12, 3.12, 4.16, 4.93, 6.00, 38347, 54513, 68253),
    "talos_f6x2": (50, 12, 10.31, 10.27, 11.48, 14.51, 120892, 130907, 154158),
    "talos_f6x2_h6x2": (50, 24, 10.11, 11.66, 15.20, 21.06, 120892, 148425, 217970),
    "atlas_shadow_f6x2": (84, 12, 18.38, 17.11, 18.20, 26.94, 210850, 216168, 239096),
    "atlas_shadow_f6x2_t3x5": (84, 27, 18.08, 20.07, 24.74, 41.34, 210850, 251572, 355675),
    "atlas_shadow_f6x2_t3x10": (84, 42, 18.47, 23.09, 34.51, 58.38, 210850, 284707, 533331),
}
# Which Pinocchio column each of our algorithms is compared with (time index, Ir index).
ANCHOR_COLUMN = {"aba": (2, 6), "caba": (3, 7), "pv": (4, 8), "ltl": (5, None),
                 "gen_caba": (3, 7), "gen_pv": (4, 8)}
ALGORITHMS = ["aba", "caba", "pv", "ltl", "ltls", "gen_caba", "gen_pv", "mujoco", "pin_caba", "pin_pv"]
LABEL = {"aba": "ABA", "caba": "cABA", "pv": "proxPV", "ltl": "proxLTL", "ltls": "proxLTLs",
         "gen_caba": "generated cABA", "gen_pv": "generated proxPV",
         "mujoco": "MuJoCo mj_forward", "pin_caba": "Pinocchio constrainedABA", "pin_pv": "Pinocchio pv"}
# Peers timed in the same run when the build found them (bench/mujoco.cmake, bench/pinocchio.cmake).
PEERS = ["mujoco", "pin_caba", "pin_pv"]
TARGET = 1.0 / 3.0  # the project's target: generated solvers at most a third of Pinocchio's figures


# ---------------------------------------------------------------- inputs
def medians(path, aggregate="median"):
    """{run_name: (median cpu time us, median real time us, counters)} from Google Benchmark JSON
    (another aggregate, such as the suite's "min", with `aggregate`)."""
    with open(path) as f:
        data = json.load(f)
    scale = {"ns": 1e-3, "us": 1.0, "ms": 1e3, "s": 1e6}
    out = {}
    for b in data["benchmarks"]:
        # Aggregates: keep the one asked for; a run without repetitions has single iterations.
        if b.get("run_type") == "aggregate" and b.get("aggregate_name") != aggregate:
            continue
        if b.get("run_type") != "aggregate" and aggregate != "median":
            continue
        k = scale[b["time_unit"]]
        counters = {c: b[c] for c in b if c in ("nv", "nc", "n", "m") or c.startswith(("mj_", "pin_"))}
        out[b["run_name"]] = (b["cpu_time"] * k, b["real_time"] * k, counters)
    return out, data.get("context", {})


def load_calls(path):
    if not path or not os.path.exists(path):
        return {}
    with open(path) as f:
        return {(r["case"], r["algorithm"]): r["ir_per_call"] for r in json.load(f)}


# ---------------------------------------------------------------- formatting
def fmt_us(x):
    return "—" if x is None else (f"{x:.3g}" if x < 10 else f"{x:.1f}")


def fmt_ir(x):
    return "—" if x is None else f"{x:,.0f}"


def fmt_ratio(a, b):
    return "—" if a is None or b is None else f"{a / b:.2f}"


# ---------------------------------------------------------------- compile time, object size
def compile_generated(build_dir):
    """[(case, cpu seconds, wall seconds, text, data, bss)] of each generated .cpp compiled alone at -O2
    (with the build's -march, if any, and proxgen_add_solver's options, both from bench_config.json)."""
    cfg_path = os.path.join(build_dir, "bench", "bench_config.json")
    if not os.path.exists(cfg_path):
        return []
    with open(cfg_path) as f:
        cfg = json.load(f)
    rows = []
    with tempfile.TemporaryDirectory(prefix="proxgen-compile-") as tmp:
        for g in cfg["generated"]:
            src = g["source"]
            obj = os.path.join(tmp, g["case"] + ".o")
            march = [f"-march={cfg['march']}"] if cfg.get("march") else []
            cmd = [cfg["cxx"], "-std=c++17", "-O2", *march, *cfg.get("solver_options", []), "-I", os.path.dirname(src),
                   "-I", cfg["runtime_include"],
                   "-c", src, "-o", obj]
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            start = time.perf_counter()
            subprocess.run(cmd, check=True)
            wall = time.perf_counter() - start
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
            size = subprocess.run(["size", obj], check=True, stdout=subprocess.PIPE, text=True).stdout
            text, data, bss = (int(x) for x in size.splitlines()[1].split()[:3])
            rows.append((g["case"], cpu, wall, text, data, bss))
    return rows


# ---------------------------------------------------------------- scaling fits
def loglog_slope(points):
    """Least-squares slope of log t against log x."""
    xs = [math.log(x) for x, _ in points]
    ys = [math.log(t) for _, t in points]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx > 0 else float("nan")


def scaling_series(scaling):
    """{(shape, alg): {(n, m): time}} from names <shape>/n:<n>/m:<m>/<alg>."""
    series = {}
    for name, (cpu, _, _) in scaling.items():
        shape, n, m, alg = name.split("/")
        series.setdefault((shape, alg), {})[(int(n[2:]), int(m[2:]))] = cpu
    return series


def sweep(points, fixed, axis):
    """Points of a series along n (axis 0, m == fixed) or along m (axis 1, n == fixed), sorted."""
    other = 1 - axis
    return sorted((key[axis], t) for key, t in points.items() if key[other] == fixed)


# ---------------------------------------------------------------- plots
def gnuplot(script):
    if not shutil.which("gnuplot"):
        print("report: gnuplot not found, no plots", file=sys.stderr)
        return False
    subprocess.run(["gnuplot"], input=script, text=True, check=True)
    return True


# How each series is drawn in the DoF plot: (gnuplot point type, colour). Filled
# markers are proxgen's generated solvers, open ones its generic solvers, the rest peers.
DOF_STYLE = {"gen_caba": (7, "#1f77b4"), "gen_pv": (5, "#2ca02c"), "caba": (6, "#1f77b4"), "pv": (4, "#2ca02c"),
             "aba": (12, "#7f7f7f"), "mujoco": (9, "#d62728"), "pin_caba": (11, "#ff7f0e"), "pin_pv": (13, "#9467bd")}


def dof_positions(suite, cases):
    """{case: x} for the DoF plot: cases of equal nv spread a few percent apart around
    their nv, in order of constraint rows, so that no two share a column."""
    groups = {}
    for c in cases:
        counters = next((suite[f"{c}/{a}"][2] for a in ALGORITHMS if f"{c}/{a}" in suite), {})
        groups.setdefault(counters.get("nv", 0), []).append((counters.get("nc", 0), c))
    x = {}
    for nv, members in groups.items():
        members.sort()
        for j, (_, c) in enumerate(members):
            x[c] = nv * 1.14 ** (j - (len(members) - 1) / 2)
    return x, groups


def plot_dof(suite, cases, out_png, tmp, subtitle=""):
    x, groups = dof_positions(suite, cases)
    lines = []
    for alg in DOF_STYLE:
        pts = [(x[c], suite[f"{c}/{alg}"][0]) for c in cases if f"{c}/{alg}" in suite]
        if not pts:
            continue
        path = os.path.join(tmp, f"dof_{alg}.dat")
        with open(path, "w") as f:
            f.writelines(f"{px} {t}\n" for px, t in sorted(pts))
        pt, colour = DOF_STYLE[alg]
        title = ("proxgen generic " if alg in ("aba", "caba", "pv") else "proxgen " if alg in ("gen_caba", "gen_pv") else "") + LABEL[alg]
        lines.append(f"'{path}' using 1:2 with points pt {pt} ps 1.6 lc rgb '{colour}' title '{title}'")
    # Each case's constraint rows under its column.
    labels = "".join(f"set label 'm={suite_rows(suite, c)}' at {x[c]}, graph {0.03 + 0.04 * (k % 2)} center font ',9'\n"
                     for k, c in enumerate(sorted(cases, key=lambda c: x[c])))
    xtics = ", ".join(f"'{nv:.0f}' {nv}" for nv in sorted(groups))
    return gnuplot(f"""set terminal pngcairo size 1150,700
set output '{out_png}'
set termoption noenhanced
set title "Time per call against DoF: one marker per shared case and solver (K = 3, mu = 1e4; median CPU time)\\n{subtitle}"
set xlabel 'DoF (nv); cases of equal nv side by side, constraint rows m under each'
set ylabel 'time per call [us]'
set logscale xy
set xrange [5.5:110]
set xtics ({xtics})
set key outside right top
set grid
{labels}plot {', '.join(lines)}
""")


def suite_rows(suite, case):
    counters = next((suite[f"{case}/{a}"][2] for a in ALGORITHMS if f"{case}/{a}" in suite), {})
    return f"{counters.get('nc', 0):.0f}"


def plot_scaling(series, fixed_m, fixed_ns, out_png, tmp):
    panels = []
    for axis, fixeds, xlabel in ((0, [fixed_m], f"DoF n (m = {fixed_m} rows)"),
                                 (1, fixed_ns, "constraint rows m (n = " + ", ".join(map(str, fixed_ns)) + ")")):
        lines = []
        for (shape, alg), pts in sorted(series.items()):
            for fixed in fixeds:
                s = sweep(pts, fixed, axis)
                if len(s) < 2:
                    continue
                path = os.path.join(tmp, f"scal_{axis}_{fixed}_{shape}_{alg}.dat")
                with open(path, "w") as f:
                    f.writelines(f"{x} {t}\n" for x, t in s)
                title = f"{shape} {LABEL[alg]}" + (f", n = {fixed}" if axis == 1 else "")
                lines.append(f"'{path}' using 1:2 with linespoints title '{title}'")
        panels.append(f"set xlabel '{xlabel}'\nplot {', '.join(lines)}\n")
    return gnuplot(f"""set terminal pngcairo size 1400,600
set output '{out_png}'
set multiplot layout 1,2 title 'Scaling on synthetic robots (generic solvers, K = 3, mu = 1e4; median CPU time)'
set ylabel 'time per call [us]'
set logscale xy
set key top left
set grid
{panels[0]}{panels[1]}unset multiplot
""")


# ---------------------------------------------------------------- report
def case_tables(suite, calls, cases):
    out = ["## Per case and algorithm", "",
           "Time: median over repetitions of the mean CPU time per call (µs). Ir: instructions per call "
           "(callgrind). Pinocchio: the anchor figures of docs/benchmarks.md, same cases and settings; ratios below 1 mean faster "
           "than Pinocchio.", ""]
    for c in cases:
        first = next((suite[f"{c}/{a}"] for a in ALGORITHMS if f"{c}/{a}" in suite), None)
        if first is None:
            continue
        nv, nc = first[2].get("nv"), first[2].get("nc")
        out += [f"### {c} (nv = {nv:.0f}, constraint rows m = {nc:.0f})", "",
                "| algorithm | time µs | Ir/call | Pinocchio µs | Pinocchio Ir | time / Pinocchio | Ir / Pinocchio |",
                "|---|---|---|---|---|---|---|"]
        for a in ALGORITHMS:
            if f"{c}/{a}" not in suite:
                continue
            t = suite[f"{c}/{a}"][0]
            ir = calls.get((c, a))
            ti, ii = ANCHOR_COLUMN.get(a, (None, None))
            pt = ANCHOR[c][ti] if c in ANCHOR and ti is not None else None
            pi = ANCHOR[c][ii] if c in ANCHOR and ii is not None else None
            out.append(f"| {LABEL[a]} | {fmt_us(t)} | {fmt_ir(ir)} | {fmt_us(pt)} | {fmt_ir(pi)} | "
                       f"{fmt_ratio(t, pt)} | {fmt_ratio(ir, pi)} |")
        out.append("")
    return out


def summary_table(suite, calls, cases):
    """Generated / generic and generated / Pinocchio, per case, for cABA and proxPV."""
    out = ["## Generated solvers: ratios", "",
           f"Target (docs/benchmarks.md, \"Anchor figures\"): generated / Pinocchio at most {TARGET:.2f}, in time and in instructions. "
           "Pinocchio's times were measured on a quiet machine with AVX-512 (a newer processor than the one "
           "named above), ours on a shared one (load average above): the instruction ratios are the ones to hold "
           "against the target; the time ratios to Pinocchio carry the difference of machines "
           "(docs/benchmarks.md, \"This machine and the anchors\"). Generated / generic is measured in this run.",
           "", "| case | nv | m | cABA gen/generic time | Ir | cABA gen/Pinocchio time | Ir | "
           "PV gen/generic time | Ir | PV gen/Pinocchio time | Ir |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    any_generated = False
    for c in cases:
        row = []
        for gen, generic, col in (("gen_caba", "caba", 3), ("gen_pv", "pv", 4)):
            tg = suite.get(f"{c}/{gen}", (None,))[0]
            tb = suite.get(f"{c}/{generic}", (None,))[0]
            ig, ib = calls.get((c, gen)), calls.get((c, generic))
            any_generated |= tg is not None
            row += [fmt_ratio(tg, tb), fmt_ratio(ig, ib), fmt_ratio(tg, ANCHOR[c][col]),
                    fmt_ratio(ig, ANCHOR[c][col + 4])]
        counters = next((suite[f"{c}/{a}"][2] for a in ALGORITHMS if f"{c}/{a}" in suite), {})
        out.append(f"| {c} | {counters.get('nv', 0):.0f} | {counters.get('nc', 0):.0f} | " + " | ".join(row) + " |")
    if not any_generated:
        out += ["", "**The generated solvers were not part of this run** (PROXGEN_BENCH_GENERATED off, or "
                "`proxgen generate` not available yet): the generated columns are empty."]
    return out + [""]


def minimum_table(suite_min, cases):
    """The generated solvers' fastest repetition against Pinocchio's anchors and the generic solvers' fastest."""
    if not any(f"{c}/gen_caba" in suite_min for c in cases):
        return []
    out = ["## Generated solvers: fastest repetition", "",
           "The same ratios from the minimum over the repetitions instead of the median (the suite's `min` "
           "statistic). On this shared VM the medians move by 10-50 % between runs and the minima by a few percent "
           "(docs/benchmarks.md, \"Emitted code\"); the anchors were medians on a quiet machine, where the two "
           "agree. The target is on the medians above; this table separates this machine's load from the code.", "",
           "| case | cABA gen µs | gen/generic | gen/Pinocchio | PV gen µs | gen/generic | gen/Pinocchio |",
           "|---|---|---|---|---|---|---|"]
    for c in cases:
        row = []
        for gen, generic, col in (("gen_caba", "caba", 3), ("gen_pv", "pv", 4)):
            tg = suite_min.get(f"{c}/{gen}", (None,))[0]
            tb = suite_min.get(f"{c}/{generic}", (None,))[0]
            row += [fmt_us(tg), fmt_ratio(tg, tb), fmt_ratio(tg, ANCHOR[c][col])]
        out.append(f"| {c} | " + " | ".join(row) + " |")
    return out + [""]


def build_march(build_dir):
    """The -march of the benchmarked build (bench_config.json), or "" for the compiler's default."""
    cfg_path = os.path.join(build_dir, "bench", "bench_config.json")
    if not os.path.exists(cfg_path):
        return ""
    with open(cfg_path) as f:
        return json.load(f).get("march", "")


def cpu_description():
    """The processor as /proc/cpuinfo names it, with the vector extensions that matter here."""
    try:
        with open("/proc/cpuinfo") as f:
            info = f.read()
    except OSError:
        return "?"
    field = lambda key: (re.search(rf"^{key}\s*:\s*(.*)$", info, re.M) or [None, "?"])[1].strip()
    flags = set(field("flags").split())
    vector = [x for x in ("avx2", "fma", "avx512f") if x in flags]
    missing = [x for x in ("avx512f",) if x not in flags]
    return (f"{field('model name')} (family {field('cpu family')}, model {field('model')}; "
            f"{', '.join(vector) or 'no AVX'}{'; no ' + ', '.join(missing) if missing else ''})")


def compile_table(rows, march):
    if not rows:
        return ["## Generated solvers: compile time and object size", "",
                "No generated solvers in this build.", ""]
    out = ["## Generated solvers: compile time and object size", "",
           f"Each generated `.cpp` compiled alone with `-std=c++17 -O2{' -march=' + march if march else ''}` "
           "and proxgen_add_solver's flags (CPU time of the compiler, and wall "
           "time on the shared machine); `size` of the object in bytes.", "",
           "| case | compile CPU s | wall s | text | data | bss |", "|---|---|---|---|---|---|"]
    for case, cpu, wall, text, data, bss in rows:
        out.append(f"| {case} | {cpu:.2f} | {wall:.2f} | {text:,} | {data:,} | {bss:,} |")
    return out + [""]


def scaling_section(series, fixed_m, fixed_ns, have_plot):
    out = ["## Scaling on synthetic robots", "",
           "Serial chains and complete binary trees of n revolute joints on a fixed base, with m/3 point "
           "contacts (the chain's tip and bodies evenly spaced below it; leaves of the tree evenly spread). "
           "Generic solvers only. Exponents: least-squares slope of log(time) against log(n) at "
           f"m = {fixed_m}, and against log(m) at fixed n (m up to 39, and, at n = 128, on to 192 rows to "
           "expose the m^3 term); \"upper\" fits only the three largest sizes of the sweep. "
           "A slope against m is flattened by the part of the time that does not depend on m (ABA's O(n)), "
           "hence the sweep at a small n too.", "",
           "| shape | algorithm | sweep | exponent (all) | exponent (upper) | range |", "|---|---|---|---|---|---|"]
    rng = lambda s: f"{s[0][0]}–{s[-1][0]}" if s else "—"
    for (shape, alg), pts in sorted(series.items()):
        sweeps = [(f"time ~ n^p, m = {fixed_m}", sweep(pts, fixed_m, 0))]
        for n in fixed_ns:
            s = sweep(pts, n, 1)
            sweeps.append((f"time ~ m^q, n = {n}", [p for p in s if p[0] <= 40]))
            if any(p[0] > 40 for p in s):
                sweeps.append((f"time ~ m^q, n = {n}, all m", s))
        for label, s in sweeps:
            if len(s) < 2:
                continue
            out.append(f"| {shape} | {LABEL[alg]} | {label} | {loglog_slope(s):.2f} | "
                       f"{loglog_slope(s[-3:]):.2f} | {rng(s)} |")
    out.append("")
    out.append("Times (µs):")
    out.append("")
    out.append("| shape | algorithm | n | m | time µs |")
    out.append("|---|---|---|---|---|")
    for (shape, alg), pts in sorted(series.items()):
        for (n, m), t in sorted(pts.items()):
            out.append(f"| {shape} | {LABEL[alg]} | {n} | {m} | {fmt_us(t)} |")
    out.append("")
    if have_plot:
        out += ["![scaling](scaling.png)", ""]
    return out


def python_section(py, march):
    """The generated module's call from Python against the C++ call (python_overhead.py's JSON).
    The section carries its own date and load: run.sh measures it after the suite, and it may be
    rerun alone (--section python)."""
    load = ", ".join(f"{x:.1f}" for x in py.get("load_avg", [])) or "?"
    ver = py.get("versions", {})
    ver_text = ", ".join(f"{k} {ver[k]}" for k in ("python", "numpy", "pybind11") if k in ver)
    n = py["N"]
    mu = py.get("mu", 0)
    exponent = round(math.log10(mu)) if mu > 0 else None
    mu_text = f"1e{exponent}" if exponent is not None and mu == 10.0 ** exponent else f"{mu:g}"
    out = ["## Python", "",
           f"`bench/python_overhead.py` ({py.get('date', '?')}, host {py.get('host', '?')}, {py.get('cpus', '?')} CPUs, "
           f"load average {load} at the start; `{py.get('interpreter', '?')}`, {ver_text}): the generated module "
           f"`{py['module']}` (nq = {py['nq']}, nv = {py['nv']}, nc = {py['nc']}, {py.get('scalar', 'double')}, "
           f"K = {py.get('iterations', '?')}, mu = {mu_text}) called from Python, against the same "
           "compiled solver looped in C++ (`_cpp_seconds_per_call`: same flags, workspace and checked state). "
           f"Processor: {cpu_description()}; module compiled with `-O3 -DNDEBUG{' -march=' + march if march else ''}`. "
           f"Median over {py['repetitions']} repetitions of {py.get('calls', 100)} single-state calls and "
           f"{py['batch_repetitions']} repetitions of one {n}-state call (and {n} C++ calls), the fastest repetition "
           "in brackets; overhead = Python minus C++, of the medians (of the minima in brackets). The "
           f"{n}-state call is a loop of the scalar solver in C++ with the GIL released, not a batched kernel "
           "(docs/python.md, \"Speed\").", "",
           f"| function | C++ call µs | Python call µs | overhead µs | N = {n} in one call ms | "
           f"{n} C++ calls ms | states/s (N = {n}) |", "|---|---|---|---|---|---|---|"]
    both = lambda d: f"{d['median']:.2f} ({d['min']:.2f})"
    for fn in ("prox_pv", "constrained_aba"):
        if fn not in py:
            continue
        r = py[fn]
        out.append(f"| `{fn}` | {both(r['cpp_us'])} | {both(r['python_us'])} | {both(r['overhead_us'])} | "
                   f"{both(r['batch_ms'])} | {both(r['cpp_loop_ms'])} | {r['batch_states_per_s']:,.0f} |")
    return out + [""]


def peers_section(suite, cases, context, march, command):
    """The peers (MuJoCo; Pinocchio where the build found it) beside proxgen's solvers, all from
    one run of proxgen_bench: time per call and ratios, per case, with MuJoCo's agreement checks."""
    have = [p for p in PEERS if any(f"{c}/{p}" in suite for c in cases)]
    if not have:
        return []
    t = lambda c, a: suite.get(f"{c}/{a}", (None,))[0]
    counter = lambda c, k: suite.get(f"{c}/mujoco", (None, None, {}))[2].get(k)
    version = next((counter(c, "mj_version") for c in cases if counter(c, "mj_version")), None)
    load = ", ".join(f"{x:.1f}" for x in context.get("load_avg", [])) or "?"
    pin = "pin_caba" in have or "pin_pv" in have
    out = ["## Peers in the same run", "",
           f"`{command}` ({context.get('date', '?')}, host {context.get('host_name', '?')}, load average {load} at "
           f"the start). Processor: {cpu_description()}. proxgen's solvers compiled with "
           f"`-O3 -DNDEBUG{' -march=' + march if march else ''}`; MuJoCo "
           f"{'%d.%d.%d' % (version // 100, version // 10 % 10, version % 10) if version else '?'} is Debian's "
           "`libmujoco-dev` build (x86-64 baseline: no AVX in the library). Every figure is the median over the "
           "repetitions of the mean CPU time per call, all from one process with random interleaving, on the same "
           "1000 random states per case. MuJoCo: `mj_forward` on the case's URDF with the layout's constraints as stiff "
           "weld/connect equalities, contacts, limits and passive forces off (docs/benchmarks.md, \"Peers in the same "
           "run\", for what is and is not comparable). gen/MuJoCo below 1: the generated solver is faster.",
           "", "Checks (on 20 states of each case, in the same process, before timing): `free gap`, MuJoCo's "
           "unconstrained qacc against proxgen's ABA; `penalty gap`, MuJoCo made a penalty method of weight mu "
           "against proxgen's constrained ABA at K = 1, at v = 0; both relative to max(1, |qdd|), bound 1e-6. "
           "`Newton it.`: MuJoCo's solver iterations per call, mean over the 1000 states.", ""]
    head = "| case | nv | m | gen cABA µs | gen PV µs | generic cABA µs | MuJoCo µs | gen cABA / MuJoCo | gen PV / MuJoCo | generic cABA / MuJoCo |"
    rule = "|---|---|---|---|---|---|---|---|---|---|"
    if pin:
        head += " Pinocchio cABA µs | Pinocchio PV µs | gen cABA / Pinocchio | gen PV / Pinocchio |"
        rule += "---|---|---|---|"
    head += " Newton it. | free gap | penalty gap |"
    rule += "---|---|---|"
    out += [head, rule]
    sci = lambda x: "—" if x is None else f"{x:.1e}"
    for c in cases:
        counters = next((suite[f"{c}/{a}"][2] for a in ALGORITHMS if f"{c}/{a}" in suite), {})
        mj = t(c, "mujoco")
        row = [c, f"{counters.get('nv', 0):.0f}", f"{counters.get('nc', 0):.0f}", fmt_us(t(c, "gen_caba")),
               fmt_us(t(c, "gen_pv")), fmt_us(t(c, "caba")), fmt_us(mj), fmt_ratio(t(c, "gen_caba"), mj),
               fmt_ratio(t(c, "gen_pv"), mj), fmt_ratio(t(c, "caba"), mj)]
        if pin:
            row += [fmt_us(t(c, "pin_caba")), fmt_us(t(c, "pin_pv")), fmt_ratio(t(c, "gen_caba"), t(c, "pin_caba")),
                    fmt_ratio(t(c, "gen_pv"), t(c, "pin_pv"))]
        iters = counter(c, "mj_iter_mean")
        row += ["—" if iters is None else f"{iters:.2f}", sci(counter(c, "mj_free_gap")), sci(counter(c, "mj_cons_gap"))]
        out.append("| " + " | ".join(row) + " |")
    if pin:
        gaps = [suite.get(f"{c}/pin_caba", (None, None, {}))[2].get("pin_aba_gap") for c in cases]
        gaps = [g for g in gaps if g is not None]
        out += ["", "Pinocchio: `constrainedABA` and `pv` with `ProximalSettings(0, 1/mu, K)`, its headers compiled "
                "in this build with proxgen's flags (bench/bench_pinocchio.cpp; Pinocchio's ABA against proxgen's "
                f"on 20 states per case: at most {max(gaps):.1e} relative)." if gaps else ""]
    if not pin:
        out += ["", "Pinocchio: not in this run (CMake found no Pinocchio 3.7 install; bench/pinocchio.cmake). "
                "The anchor figures above are the Pinocchio comparison of record."]
    return out + ["", "![time against DoF](time_vs_dof.png)", ""]


def plot_subtitle(context, march, suite):
    pin = any(k.endswith("/pin_caba") or k.endswith("/pin_pv") for k in suite)
    return (f"{cpu_description()}, {context.get('date', '?')[:10]}\\nproxgen{' and Pinocchio' if pin else ''}: -O3 -DNDEBUG"
            f"{' -march=' + march if march else ' (x86-64 baseline)'}; MuJoCo: Debian's libmujoco-dev build (baseline)")


def load_python(path):
    if not path or not os.path.exists(path):
        return None
    with open(path) as f:
        return json.load(f)


# Kept sections: a "## " section of the old RESULTS.md whose heading this run does not write is
# hand-written (e.g. "Batched solvers", measured by its own command) and is kept verbatim, after
# the nearest written section above it (docs/benchmarks.md, "Hand-written sections"). The sections the
# report writes only with some inputs are listed, so an old copy of them is dropped, never kept.
REPORT_SECTIONS = ("Scaling on synthetic robots", "Python")


def split_sections(lines):
    """[(heading, lines)] cut before each "## " line outside code fences (heading None: the top)."""
    out, fenced = [(None, [])], False
    for line in lines:
        fenced = fenced != line.startswith("```")
        if not fenced and line.startswith("## "):
            out.append((line[3:].strip(), []))
        out[-1][1].append(line)
    return out


def keep_hand_written(old_path, lines):
    """lines with the hand-written sections of old_path (if it exists) put back in."""
    if not os.path.exists(old_path):
        return lines
    with open(old_path) as f:
        old = split_sections(f.read().split("\n"))
    new = split_sections(lines)
    written = {h for h, _ in new} | set(REPORT_SECTIONS)
    after, anchor = {}, None  # written heading -> the hand-written sections that followed it
    for heading, body in old:
        if heading is not None and heading not in written:
            after.setdefault(anchor, []).append(body)
        elif heading in {h for h, _ in new}:
            anchor = heading
    out = []

    def put(body):  # one blank line before and after, as between the written sections
        while body and body[-1] == "":
            body = body[:-1]
        out.extend(([""] if out and out[-1] != "" else []) + body + [""])

    for heading, body in new:  # every anchor is a heading of new (or None, its top)
        out += body
        for kept in after.get(heading, []):
            put(kept)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", required=True)
    ap.add_argument("--suite")
    ap.add_argument("--calls")
    ap.add_argument("--scaling")
    ap.add_argument("--python", help="python_overhead.py's JSON")
    ap.add_argument("--out-dir")
    ap.add_argument("--section", choices=["python", "peers"],
                    help="print that section alone on stdout (peers: and write time_vs_dof.png into --out-dir, if given)")
    ap.add_argument("--no-compile", action="store_true", help="skip timing the generated solvers' compile")
    ap.add_argument("--command", default="bench/run.sh", help="the command line to quote in the report")
    ap.add_argument("--fixed-m", type=int, default=6)
    ap.add_argument("--fixed-n", default="32,128", help="the n of the m sweeps, comma-separated")
    args = ap.parse_args()
    if args.section == "python":
        py = load_python(args.python)
        if py is None:
            ap.error("--section python needs --python FILE (an existing python_overhead.py JSON)")
        print("\n".join(python_section(py, build_march(args.build))))
        return
    if args.section == "peers":
        if not args.suite:
            ap.error("--section peers needs --suite FILE")
        suite, context = medians(args.suite)
        cases = [c for c in ANCHOR if any(f"{c}/{a}" in suite for a in ALGORITHMS)]
        march = build_march(args.build)
        if args.out_dir:
            with tempfile.TemporaryDirectory(prefix="proxgen-plot-") as tmp:
                plot_dof(suite, cases, os.path.join(args.out_dir, "time_vs_dof.png"), tmp, plot_subtitle(context, march, suite))
        print("\n".join(peers_section(suite, cases, context, march, args.command)))
        return
    if not args.suite or not args.out_dir:
        ap.error("--suite and --out-dir are required (unless --section)")

    suite, context = medians(args.suite)
    calls = load_calls(args.calls)
    cases = [c for c in ANCHOR if any(f"{c}/{a}" in suite for a in ALGORITHMS)]
    compile_rows = [] if args.no_compile else compile_generated(args.build)
    scaling = medians(args.scaling)[0] if args.scaling and os.path.exists(args.scaling) else {}
    series = scaling_series(scaling)
    fixed_ns = [int(x) for x in args.fixed_n.split(",")]

    os.makedirs(args.out_dir, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="proxgen-plot-") as tmp:
        have_dof = plot_dof(suite, cases, os.path.join(args.out_dir, "time_vs_dof.png"), tmp,
                            plot_subtitle(context, build_march(args.build), suite))
        have_scaling = bool(series) and plot_scaling(series, args.fixed_m, fixed_ns,
                                                     os.path.join(args.out_dir, "scaling.png"), tmp)

    load = context.get("load_avg", [])
    march = build_march(args.build)
    lines = ["# Benchmark results", "",
             f"Written by `{args.command}` ({context.get('date', '?')}, host {context.get('host_name', '?')}, "
             f"{context.get('num_cpus', '?')} CPUs at {context.get('mhz_per_cpu', '?')} MHz, load average "
             f"{', '.join(f'{x:.1f}' for x in load) or '?'} at the start). All numbers come from this one run; "
             "see docs/benchmarks.md for the method. K = 3 multiplier updates, mu = 1e4.", "",
             f"Processor: {cpu_description()}. Everything (generic and generated) compiled with "
             f"`-O3 -DNDEBUG{' -march=' + march if march else ''}` (`PROXGEN_MARCH`).", ""]
    lines += summary_table(suite, calls, cases)
    lines += minimum_table(medians(args.suite, "min")[0], cases)
    lines += case_tables(suite, calls, cases)
    peers = peers_section(suite, cases, context, march, args.command)
    lines += peers
    if have_dof and not peers:
        lines += ["![time against DoF](time_vs_dof.png)", ""]
    lines += compile_table(compile_rows, march)
    if series:
        lines += scaling_section(series, args.fixed_m, fixed_ns, have_scaling)
    py = load_python(args.python)
    if py is not None:
        lines += python_section(py, march)
    lines = keep_hand_written(os.path.join(args.out_dir, "RESULTS.md"), lines)
    with open(os.path.join(args.out_dir, "RESULTS.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"report: wrote {os.path.join(args.out_dir, 'RESULTS.md')}")


if __name__ == "__main__":
    main()
