#!/usr/bin/env python3
"""Per-call overhead of a generated module's Python call against the C++ call
alone, and the throughput of many states (docs/python.md, "Speed").

  PYTHONPATH=build/python:build/tests/python/modules/quadruped \\
      /usr/bin/python3 bench/python_overhead.py [--module quadruped] [--repeats 7]

For each function: the C++ solver looped in C++ on one state
(NAME._cpp_seconds_per_call: same compiler, flags and workspace as the
module), the module's single-state call from Python (timeit, best of
--repeats), their difference (the overhead: argument checks, numpy arrays in
and out, the call), and one call on N = 1000 states against 1000 C++ calls.
Each figure is the minimum over many short runs (--repeats runs of 100 calls,
--batch-repeats runs of one N-state call): on a shared machine a short run is
likely to see no preemption, and the minimum is the undisturbed cost.
"""

import argparse
import importlib
import json
import timeit

import numpy as np


def random_states(m, n, rng):
    q = rng.uniform(-0.5, 0.5, (n, m.nq))
    for name, j in m.joints.items():
        if j["type"] == "free_flyer":
            quat = rng.normal(size=(n, 4))
            q[:, j["idx_q"] + 3:j["idx_q"] + 7] = quat / np.linalg.norm(quat, axis=1, keepdims=True)
    return q, rng.uniform(-1, 1, (n, m.nv)), rng.uniform(-1, 1, (n, m.nv))


def best(stmt, names, number, repeats):
    # A statement string, not a lambda: the lambda's own call would count as overhead.
    return min(timeit.repeat(stmt, globals=names, number=number, repeat=repeats)) / number


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--module", default="quadruped")
    p.add_argument("--repeats", type=int, default=300)
    p.add_argument("--batch-repeats", type=int, default=50)
    p.add_argument("--n", type=int, default=1000)
    args = p.parse_args()
    m = importlib.import_module(args.module)
    rng = np.random.default_rng(0)
    Q, V, T = random_states(m, args.n, rng)
    q, v, tau = Q[0].copy(), V[0].copy(), T[0].copy()
    out = {"module": args.module, "nq": m.nq, "nv": m.nv, "nc": m.nc, "N": args.n}
    for fn in ("prox_pv", "constrained_aba"):
        f = getattr(m, fn)
        f(q, v, tau)  # warm up (first-call costs, page faults)
        cpp = min(m._cpp_seconds_per_call(fn, q, v, tau, 100) for _ in range(args.repeats))
        names = {"f": f, "q": q, "v": v, "tau": tau, "Q": Q, "V": V, "T": T}
        one = best("f(q, v, tau)", names, 100, args.repeats)
        many = best("f(Q, V, T)", names, 1, args.batch_repeats)
        cpp_many = min(m._cpp_seconds_per_call(fn, q, v, tau, args.n) for _ in range(args.batch_repeats))
        out[fn] = {"cpp_us": cpp * 1e6, "python_us": one * 1e6, "overhead_us": (one - cpp) * 1e6,
                   "batch_ms": many * 1e3, "cpp_loop_ms": cpp_many * args.n * 1e3,
                   "batch_states_per_s": args.n / many}
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
