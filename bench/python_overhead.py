#!/usr/bin/env python3
"""Per-call overhead of a generated module's Python call against the C++ call
alone, and the throughput of many states (docs/python.md, "Speed").

  PYTHONPATH=build/python:build/tests/python/modules/quadruped \\
      /usr/bin/python3 bench/python_overhead.py [--module quadruped] [--out python.json]

bench/run.sh runs it and bench/report.py writes the "Python" section of
bench/RESULTS.md from its JSON.

For each function: the C++ solver looped in C++ on one state
(NAME._cpp_seconds_per_call: same compiler, flags and workspace as the
module), the module's single-state call from Python (timeit), their difference
(the overhead: argument checks, numpy arrays in and out, the call), and one
call on N = 1000 states against N C++ calls. A repetition times the C++ loop
and the Python calls one after the other (100 calls each; one N-state call and
N C++ calls for the batch), so both see the same load. Reported: the median
over the repetitions (as the suite's) and the minimum (the undisturbed cost on
a shared machine, where a short run is likely to see no preemption); the
overhead is the Python figure minus the C++ one, median from medians and
minimum from minima (a difference within one repetition would carry whichever
of the two runs was preempted).
"""

import argparse
import datetime
import importlib
import json
import os
import platform
import statistics
import sys
import timeit

import numpy as np


def random_states(m, n, rng):
    q = rng.uniform(-0.5, 0.5, (n, m.nq))
    for name, j in m.joints.items():
        if j["type"] == "free_flyer":
            quat = rng.normal(size=(n, 4))
            q[:, j["idx_q"] + 3:j["idx_q"] + 7] = quat / np.linalg.norm(quat, axis=1, keepdims=True)
    return q, rng.uniform(-1, 1, (n, m.nv)), rng.uniform(-1, 1, (n, m.nv))


def seconds(stmt, names, number):
    # A statement string, not a lambda: the lambda's own call would count as overhead.
    return timeit.timeit(stmt, globals=names, number=number) / number


def stats(xs, scale):
    return {"median": statistics.median(xs) * scale, "min": min(xs) * scale}


def versions():
    out = {"python": platform.python_version(), "numpy": np.__version__}
    try:
        import pybind11  # the headers the module was built with, when installed as a Python package
        out["pybind11"] = pybind11.__version__
    except ImportError:
        pass
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--module", default="quadruped")
    p.add_argument("--repetitions", type=int, default=300, help="repetitions of 100 single-state calls")
    p.add_argument("--batch-repetitions", type=int, default=50, help="repetitions of one N-state call")
    p.add_argument("--n", type=int, default=1000)
    p.add_argument("--out", help="write the JSON there too (bench/report.py reads it)")
    args = p.parse_args()
    m = importlib.import_module(args.module)
    rng = np.random.default_rng(0)
    Q, V, T = random_states(m, args.n, rng)
    q, v, tau = Q[0].copy(), V[0].copy(), T[0].copy()
    out = {"module": args.module, "nq": m.nq, "nv": m.nv, "nc": m.nc, "N": args.n,
           "mu": m.mu, "iterations": m.iterations, "scalar": m.scalar,
           "repetitions": args.repetitions, "batch_repetitions": args.batch_repetitions, "calls": 100,
           "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
           "host": platform.node(), "cpus": os.cpu_count(), "load_avg": list(os.getloadavg()),
           "interpreter": sys.executable, "versions": versions()}
    for fn in ("prox_pv", "constrained_aba"):
        f = getattr(m, fn)
        f(q, v, tau)  # warm up (first-call costs, page faults)
        f(Q, V, T)
        names = {"f": f, "q": q, "v": v, "tau": tau, "Q": Q, "V": V, "T": T}
        cpp, one = [], []
        for _ in range(args.repetitions):
            cpp.append(m._cpp_seconds_per_call(fn, q, v, tau, 100))
            one.append(seconds("f(q, v, tau)", names, 100))
        cpp_many, many = [], []
        for _ in range(args.batch_repetitions):
            cpp_many.append(m._cpp_seconds_per_call(fn, q, v, tau, args.n) * args.n)
            many.append(seconds("f(Q, V, T)", names, 1))
        out[fn] = {"cpp_us": stats(cpp, 1e6), "python_us": stats(one, 1e6),
                   "overhead_us": {k: (py - c) * 1e6 for k, py, c in (("median", statistics.median(one), statistics.median(cpp)),
                                                                       ("min", min(one), min(cpp)))},
                   "batch_ms": stats(many, 1e3), "cpp_loop_ms": stats(cpp_many, 1e3),
                   "batch_states_per_s": args.n / statistics.median(many)}
    text = json.dumps(out, indent=2)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text + "\n")
    print(text)


if __name__ == "__main__":
    main()
