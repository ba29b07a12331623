#!/usr/bin/env python3
"""How the generated delassus_inverse grows with n and m, on the scaling study's synthetic robots.

For each (shape, n, m) of the sweeps below: the model from proxgen_bench_scaling's writer
(bench/synthetic.cpp), `proxgen generate --functions delassus_inverse`, compiled with the
build's compiler and proxgen_add_solver's options at -O3 beside bench/delassus_scaling.cpp;
then its CPU time per call (median of REPETITIONS batches) and, with --callgrind, its
instructions per call ((Ir(N) - Ir(0)) / N). Fits, per shape: the log-log slope of each sweep
(all points and the three largest), and cost = a n + b m^2 + c (and, to see whether the data
want them, with m and m^3 terms too) by least squares over every point of the shape, with the
largest relative residual (docs/benchmarks.md).

    delassus_scaling.py BUILD_DIR OUT.json [--quick] [--callgrind] [--repetitions R] [--calls N]
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))

# (n, contacts): m = 3 contacts. The n sweep at m = 6; the m sweeps at n = 32 and n = 128.
N_SWEEP = [8, 16, 32, 64, 128, 256]
M_SWEEP = {32: [1, 2, 4, 6, 8, 10, 13], 128: [1, 2, 6, 13, 20]}
QUICK_N, QUICK_M = [8, 16], {16: [1, 2]}
FIXED_CONTACTS = 2


def points(quick):
    n_sweep, m_sweep = (QUICK_N, QUICK_M) if quick else (N_SWEEP, M_SWEEP)
    out = []
    for n in n_sweep:
        out.append((n, FIXED_CONTACTS, "n"))
    for n, cs in m_sweep.items():
        for c in cs:
            out.append((n, c, f"m@{n}"))
    return out


def run(cmd, **kw):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)
    if r.returncode != 0:
        sys.exit(f"delassus_scaling: {' '.join(cmd)} failed:\n{r.stderr[-3000:]}")
    return r.stdout


def callgrind_ir(exe, calls, work):
    out = os.path.join(work, "callgrind.out")
    run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", exe, "count", str(calls)])
    with open(out) as f:
        for line in f:
            if line.startswith("summary:") or line.startswith("totals:"):
                return int(line.split()[1])
    sys.exit(f"delassus_scaling: no totals in {out}")


def slope(xs, ys):
    lx, ly = [math.log(x) for x in xs], [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    sxx = sum((x - mx) ** 2 for x in lx)
    return sum((x - mx) * (y - my) for x, y in zip(lx, ly)) / sxx if sxx > 0 else float("nan")


# The models fitted: cost = sum of coefficient x term (n and m of the point).
MODELS = {
    "a n + b m^2 + c": [("n", lambda n, m: n), ("m^2", lambda n, m: m * m), ("1", lambda n, m: 1.0)],
    # The terms the O(n + m^2) claim leaves out, to see whether the data want them.
    "a n + b m + c m^2 + d m^3 + e": [("n", lambda n, m: n), ("m", lambda n, m: m), ("m^2", lambda n, m: m * m),
                                      ("m^3", lambda n, m: m ** 3), ("1", lambda n, m: 1.0)],
}


def solve(N, b):
    """N x = b by Gaussian elimination with partial pivoting (N small and square)."""
    k = len(b)
    A = [row[:] + [bb] for row, bb in zip(N, b)]
    for i in range(k):
        p = max(range(i, k), key=lambda r: abs(A[r][i]))
        A[i], A[p] = A[p], A[i]
        for r in range(i + 1, k):
            f = A[r][i] / A[i][i]
            for j in range(i, k + 1):
                A[r][j] -= f * A[i][j]
    x = [0.0] * k
    for i in reversed(range(k)):
        x[i] = (A[i][k] - sum(A[i][j] * x[j] for j in range(i + 1, k))) / A[i][i]
    return x


def fit(rows, key, model):
    """Least squares of cost = sum c_t term_t(n, m), weighted by 1/cost (relative errors)."""
    terms = MODELS[model]
    A = [[t(r["n"], r["m"]) / r[key] for _, t in terms] for r in rows]
    k = len(terms)
    x = solve([[sum(a[i] * a[j] for a in A) for j in range(k)] for i in range(k)],
              [sum(a[i] for a in A) for i in range(k)])
    res = [sum(c * a for c, a in zip(x, row)) - 1.0 for row in A]
    return {"model": model, "coefficients": {name: c for (name, _), c in zip(terms, x)},
            "max_rel_residual": max(abs(e) for e in res), "rms_rel_residual": math.sqrt(sum(e * e for e in res) / len(res))}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("build_dir")
    ap.add_argument("out")
    ap.add_argument("--quick", action="store_true", help="two sizes per sweep (the smoke test)")
    ap.add_argument("--callgrind", action="store_true", help="also instructions per call")
    ap.add_argument("--repetitions", type=int, default=21)
    ap.add_argument("--calls", type=int, default=20, help="calls per callgrind run (branch-free code: the same instructions for every state)")
    ap.add_argument("--shapes", default="chain,tree")
    args = ap.parse_args()
    build = os.path.abspath(args.build_dir)
    with open(os.path.join(build, "bench", "bench_config.json")) as f:
        config = json.load(f)
    proxgen = os.path.join(build, "generator", "proxgen")
    writer = os.path.join(build, "bench", "proxgen_bench_scaling")

    results = []
    measured = {}  # (shape, n, contacts) -> row: the sweeps share some points
    with tempfile.TemporaryDirectory(prefix="proxgen-dlinv-") as work:
        models = os.path.join(work, "models")
        # The writer registers (and so writes) every model of the scaling study; the
        # filter runs none of its benchmarks.
        run([writer, "--out", models, "--benchmark_filter=^$"] + (["--quick"] if args.quick else []))
        for shape in args.shapes.split(","):
            for n, c, sweep in points(args.quick):
                if (shape, n, c) in measured:
                    results.append(dict(measured[(shape, n, c)], sweep=sweep))
                    continue
                urdf = os.path.join(models, f"{shape}_n{n}.urdf")
                layout = os.path.join(models, f"{shape}_n{n}_c{c}.yaml")
                if not os.path.exists(layout):
                    sys.exit(f"delassus_scaling: {layout} was not written (add ({n}, {c}) to bench_scaling.cpp)")
                ns = f"dlinv_{shape}_n{n}_c{c}"
                src = os.path.join(work, ns)
                os.makedirs(src, exist_ok=True)
                run([proxgen, "generate", urdf, "--layout", layout, "--out", src, "--name", ns,
                     "--functions", "delassus_inverse"])
                exe = os.path.join(src, "driver")
                cmd = [config["cxx"], "-std=c++17", "-O3", "-DNDEBUG", *config["solver_options"],
                       *([f"-march={config['march']}"] if config["march"] else []),
                       "-I", config["runtime_include"], "-I", src,
                       f"-DPROXGEN_SCALING_HEADER=\"{ns}.hpp\"", f"-DPROXGEN_SCALING_NS={ns}",
                       os.path.join(HERE, "delassus_scaling.cpp"), os.path.join(src, f"{ns}.cpp"), "-o", exe]
                run(cmd)
                row = json.loads(run([exe, "time", str(args.repetitions)]))
                row.update({"shape": shape, "n": n, "m": 3 * c, "sweep": sweep})
                if args.callgrind:
                    full = callgrind_ir(exe, args.calls, work)
                    base = callgrind_ir(exe, 0, work)
                    row["ir_per_call"] = (full - base) / args.calls
                results.append(row)
                measured[(shape, n, c)] = row
                ir = f"{row['ir_per_call']:12,.0f} Ir" if "ir_per_call" in row else ""
                print(f"{shape:5s} n={n:4d} m={3 * c:3d} {row['median_us']:9.3f} us {ir}", flush=True)

    fits = []
    for shape in args.shapes.split(","):
        rows = [r for r in results if r["shape"] == shape]
        for key in ["median_us"] + (["ir_per_call"] if args.callgrind else []):
            for sweep in sorted({r["sweep"] for r in rows}):
                pts = sorted((r for r in rows if r["sweep"] == sweep), key=lambda r: (r["n"], r["m"]))
                var = "n" if sweep == "n" else "m"
                xs, ys = [r[var] for r in pts], [r[key] for r in pts]
                fits.append({"shape": shape, "cost": key, "sweep": sweep, "variable": var,
                             "range": [xs[0], xs[-1]], "slope_all": slope(xs, ys),
                             "slope_upper": slope(xs[-3:], ys[-3:])})
            # Every distinct (n, m) once (the sweeps share n = 32, m = 6 and n = 128, m = 6).
            distinct = {(r["n"], r["m"]): r for r in rows}
            for model in MODELS:
                fits.append({"shape": shape, "cost": key, **fit(list(distinct.values()), key, model)})
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "w") as f:
        json.dump({"points": results, "fits": fits}, f, indent=1)
    for f in fits:
        print(json.dumps(f))


if __name__ == "__main__":
    main()
