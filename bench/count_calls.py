#!/usr/bin/env python3
"""Instructions per call of each (case, algorithm) under callgrind.

Runs `proxgen_bench_calls CASE ALGORITHM N` under `valgrind --tool=callgrind`
twice, with 2N calls and with N, and reports (Ir(2N) - Ir(N)) / N: loading the
model, drawing the states and building the work space cost the same in both
runs, and so does whatever the first call does once (a lazily bound symbol, a
first touch), so only the calls remain. Against a run with no call, that
once-only work counted as calls: 827 instructions per call of 20 on the iiwa's
inverse_dynamics (3,108 for 2,281; docs/benchmarks.md, "Instructions per
call"). Deterministic (same states, same code).

    count_calls.py BUILD_DIR OUT.json [--calls N] [--cases a,b] [--algorithms x,y]
    count_calls.py BUILD_DIR OUT.json --library [--calls N] [--cases a,b] [--algorithms f/variant,...]

    count_calls.py BUILD_DIR OUT.json --derivatives [--calls N] [--cases a,b] [--algorithms variant,...]

--library counts the dynamics library's benchmarks instead (proxgen_bench_joint_space
--count CASE/FUNCTION/VARIANT N, bench_joint_space.cpp): each generated function, its
generic twin, the route to delassus_inverse through the generated mass_matrix, and
Pinocchio's rnea, nonLinearEffects, crba and computeMinverse where the build has them.
--derivatives counts the derivative benchmarks (proxgen_bench_derivatives --count
CASE/VARIANT N, bench_derivatives.cpp): the generated constrained_dynamics_derivatives,
the central differences of prox_pv, their integrations alone, the generated
inverse_dynamics_derivatives and its two generic twins (body and world frame), and Pinocchio's constraintDynamics +
computeConstraintDynamicsDerivatives and computeRNEADerivatives where the build has it.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile

ALGORITHMS = ["aba", "caba", "pv", "ltl", "ltls", "gen_caba", "gen_pv"]
LIBRARY = [f"{f}/{variant}" for f in ["inverse_dynamics", "nonlinear_effects", "mass_matrix", "mass_matrix_inverse",
                                        "constraint_placements", "constraint_jacobian", "constraint_drift",
                                        "delassus", "delassus_inverse"]
           for variant in ("generated", "generic")] + ["delassus_inverse/route_mass_matrix"] + [
    # Pinocchio's, where the build found it (bench_pinocchio.cpp, pinocchioJointSpace); exit 3 otherwise.
    f"{f}/pinocchio" for f in ["inverse_dynamics", "nonlinear_effects", "mass_matrix", "mass_matrix_inverse"]] + [
    "mass_matrix/pinocchio_upper", "mass_matrix/pinocchio_world", "mass_matrix_inverse/pinocchio_upper"]
DERIVATIVES = ["cdd/generated", "fd/generated_prox_pv", "fd/integrate_only", "cdd/pinocchio", "idd/generated",
               "idd/pinocchio", "idd/generic_body", "idd/generic_world"]
# The drivers: executable in BUILD_DIR/bench, whether it takes `--count CASE/WHAT N`, and the
# default list of what to count.
DRIVERS = {
    "calls": ("proxgen_bench_calls", False, ALGORITHMS),
    "library": ("proxgen_bench_joint_space", True, LIBRARY),
    "derivatives": ("proxgen_bench_derivatives", True, DERIVATIVES),
}
NOT_BUILT = 3  # proxgen_bench_calls' (and --count's) exit code for what this build lacks


def case_names(cases_yaml):
    """The `- name:` entries of cases.yaml, in order (the file's own simple shape)."""
    with open(cases_yaml) as f:
        return re.findall(r"^\s*-\s*name:\s*(\S+)\s*$", f.read(), re.M)


def instructions(driver, case, algorithm, calls, workdir):
    """Total Ir of one run, or None when the algorithm is not built. driver is a list:
    the executable, and --count for the library's."""
    out = os.path.join(workdir, f"callgrind.{case}.{algorithm.replace('/', '.')}.{calls}")
    what = [f"{case}/{algorithm}"] if len(driver) > 1 else [case, algorithm]
    cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", *driver, *what, str(calls)]
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
    ap.add_argument("--algorithms", help="comma-separated (default: every solver, or with --library every "
                    "function/variant)")
    which = ap.add_mutually_exclusive_group()
    which.add_argument("--library", action="store_true", help="the dynamics library (proxgen_bench_joint_space)")
    which.add_argument("--derivatives", action="store_true", help="the derivatives (proxgen_bench_derivatives)")
    args = ap.parse_args()
    exe, count_flag, default_list = DRIVERS[
        "library" if args.library else "derivatives" if args.derivatives else "calls"]
    algorithms = args.algorithms.split(",") if args.algorithms else default_list

    with open(os.path.join(args.build_dir, "CMakeCache.txt")) as f:
        models = re.search(r"^PROXGEN_MODELS_DIR:PATH=(.*)$", f.read(), re.M).group(1)
    cases = args.cases.split(",") if args.cases else case_names(os.path.join(models, "cases.yaml"))
    driver = [os.path.join(args.build_dir, "bench", exe)] + (["--count"] if count_flag else [])

    results = []
    with tempfile.TemporaryDirectory(prefix="proxgen-callgrind-") as work:
        for case in cases:
            for algorithm in algorithms:
                base = instructions(driver, case, algorithm, args.calls, work)
                if base is None:
                    print(f"{case:26s} {algorithm:20s} not built", flush=True)
                    continue
                full = instructions(driver, case, algorithm, 2 * args.calls, work)
                per_call = (full - base) / args.calls
                results.append({"case": case, "algorithm": algorithm, "ir_per_call": per_call,
                                "ir_total": full, "ir_baseline": base, "calls": args.calls})
                print(f"{case:26s} {algorithm:20s} {per_call:14,.0f} Ir/call", flush=True)
    with open(args.out, "w") as f:
        json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
