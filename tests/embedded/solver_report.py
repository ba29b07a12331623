#!/usr/bin/env python3
"""Tables of the generated-solver firmware for docs/embedded.md, from a check.sh build root.

    tests/embedded/solver_report.py BUILD_ROOT      (e.g. build/embedded, after check.sh)

For every fw_solver_<case>.elf in BUILD_ROOT/cortex-m7 (double) and BUILD_ROOT/cortex-m4f
(float) it measures:
  - flash of the solver: .text* + .rodata* of the solver's object file (arm-none-eabi-size -A);
    the firmware's whole flash (text + data, <fw>.size.txt) for context;
  - stack: the worst path from <case>::constrained_aba and <case>::prox_pv (<fw>.stack.txt,
    stack_report.py: -fstack-usage/-fcallgraph-info frames, library code from the disassembly);
  - workspace: sizeof(Workspace), and the errors, from a run under qemu (run-qemu.sh).
Prints Markdown tables to stdout.
"""
import glob
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
TARGETS = [("cortex-m7", "mps2-an500", "double"), ("cortex-m4f", "mps2-an386", "float")]
SUMMARY_RE = re.compile(
    r"^max (constrained_aba|prox_pv) mu (\S+) K (\d+): qdd (\S+) lambda (\S+) tol (\S+) "
    r"estimate (\S+) err/estimate (\S+) u\*mu/m (\S+) (\S+)$")


def section_sizes(size_tool, obj):
    out = subprocess.run([size_tool, "-A", obj], check=True, capture_output=True, text=True).stdout
    total = 0
    for line in out.splitlines():
        cols = line.split()
        if len(cols) >= 2 and cols[1].isdigit() and (cols[0].startswith(".text") or cols[0].startswith(".rodata")):
            total += int(cols[1])
    return total


def solver_flash(build, case):
    objs = glob.glob(os.path.join(build, "CMakeFiles", f"fw_solver_{case}.dir", "**", f"{case}.cpp.obj"),
                     recursive=True)
    return section_sizes("arm-none-eabi-size", objs[0]) if objs else None


def firmware_flash(build, case):
    try:
        with open(os.path.join(build, f"fw_solver_{case}.size.txt")) as fh:
            m = re.search(r"flash (\d+) bytes", fh.readline())
            return int(m.group(1)) if m else None
    except OSError:
        return None


def solver_stack(build, case):
    try:
        with open(os.path.join(build, f"fw_solver_{case}.stack.txt")) as fh:
            text = fh.read()
    except OSError:
        return None, None
    out = []
    for fn in ("constrained_aba", "prox_pv"):
        m = re.search(rf"worst stack from {re.escape(case)}::{fn}: (\d+) bytes", text)
        out.append(int(m.group(1)) if m else None)
    return tuple(out)


def run(machine, elf):
    res = subprocess.run([os.path.join(HERE, "run-qemu.sh"), machine, elf, "300"], capture_output=True, text=True)
    info = {"rc": res.returncode, "summary": {}}
    for line in res.stdout.splitlines():
        m = re.match(r"^workspace: (\d+) bytes", line)
        if m:
            info["workspace"] = int(m.group(1))
        m = re.match(r"^lightest support body: (\S+) (\S+) kg; layout mu (\S+)", line)
        if m:
            info["light"], info["mass"], info["mu"] = m.group(1), float(m.group(2)), float(m.group(3))
        m = SUMMARY_RE.match(line)
        if m:
            alg, mu, k = m.group(1), float(m.group(2)), int(m.group(3))
            info["summary"][(alg, mu, k)] = {
                "qdd": float(m.group(4)), "lambda": float(m.group(5)), "tol": float(m.group(6)),
                "ratio": float(m.group(8)), "mass": float(m.group(9)), "status": m.group(10)}
    return info


def fmt_err(s):
    return f"{s['qdd']:.1e} / {s['lambda']:.1e}"


def main(argv):
    if len(argv) != 1:
        print(__doc__, file=sys.stderr)
        return 2
    root = argv[0]
    cases = sorted({os.path.basename(p)[len("fw_solver_"):-len(".elf")]
                    for cpu, _, _ in TARGETS for p in glob.glob(os.path.join(root, cpu, "fw_solver_*.elf"))})
    data = {}
    for case in cases:
        for cpu, machine, scalar in TARGETS:
            build = os.path.join(root, cpu)
            elf = os.path.join(build, f"fw_solver_{case}.elf")
            if not os.path.exists(elf):
                continue
            d = run(machine, elf)
            d["flash"] = solver_flash(build, case)
            d["fw_flash"] = firmware_flash(build, case)
            d["stack"] = solver_stack(build, case)
            data[(case, scalar)] = d

    print("| case | scalar | solver flash (.text+.rodata) | firmware flash | stack cABA / PV | "
          "sizeof(Workspace) | qemu run |")
    print("|---|---|---|---|---|---|---|")
    for (case, scalar), d in sorted(data.items()):
        st = d["stack"]
        print(f"| {case} | {scalar} | {d['flash']} | {d['fw_flash']} | {st[0]} / {st[1]} | "
              f"{d.get('workspace')} | {'pass' if d['rc'] == 0 else 'FAIL rc=%d' % d['rc']} |")

    print("\nErrors at the layout's mu, max over the states, qdd / lambda "
          "(relErr against the generic solver in double):\n")
    print("| case | scalar | u mu/m | cABA K=3 | cABA K=100 | PV K=3 | PV K=100 |")
    print("|---|---|---|---|---|---|---|")
    for (case, scalar), d in sorted(data.items()):
        mu = d.get("mu")
        cells = []
        for alg in ("constrained_aba", "prox_pv"):
            for k in (3, 100):
                s = d["summary"].get((alg, mu, k))
                cells.append(fmt_err(s) + ("" if s["status"] == "ok" else f" ({s['status']})") if s else "-")
        mass = d["summary"].get(("constrained_aba", mu, 3), {}).get("mass")
        print(f"| {case} | {scalar} | {mass:.1e} | " + " | ".join(cells) + " |")

    print("\nFloat over mu at K = 100, max over states of max(qdd, lambda) error; "
          "cABA | PV (* = not checked: tolerance >= 1):\n")
    mus = sorted({k[1] for d in data.values() for k in d["summary"]})
    print("| case | m (kg) | " + " | ".join(f"mu={mu:.0e}" for mu in mus) + " |")
    print("|---|---|" + "---|" * len(mus))
    for (case, scalar), d in sorted(data.items()):
        if scalar != "float":
            continue
        cells = []
        for mu in mus:
            parts = []
            for alg in ("constrained_aba", "prox_pv"):
                s = d["summary"].get((alg, mu, 100))
                if not s:
                    parts.append("-")
                    continue
                e = max(s["qdd"], s["lambda"])
                parts.append(f"{e:.0e}" + ("*" if s["status"] == "not-checked" else ""))
            cells.append(" \\| ".join(parts))
        print(f"| {case} | {d.get('mass', 0):.3g} | " + " | ".join(cells) + " |")

    worst = {}
    for (case, scalar), d in data.items():
        for key, s in d["summary"].items():
            if s["ratio"] == s["ratio"] and s["ratio"] != float("inf"):
                if s["ratio"] > worst.get(scalar, (0, None))[0]:
                    worst[scalar] = (s["ratio"], f"{case} {key[0]} mu={key[1]:.0e} K={key[2]}")
    print()
    for scalar, (r, where) in sorted(worst.items()):
        print(f"largest error / estimate ({scalar}, finite answers): {r:.3g} at {where}")
    failed = [k for k, d in data.items() if d["rc"] != 0]
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
