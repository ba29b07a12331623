#!/usr/bin/env python3
"""Worst-case stack depth of a firmware ELF, from gcc's call-graph output.

Sources of information, best first:
  1. .ci files written by gcc -fcallgraph-info=su (gcc >= 10): for every function compiled in
     the project, its frame size (static / dynamic / dynamic,bounded) and the calls it makes,
     after inlining.
  2. The ELF's disassembly (arm-none-eabi-objdump -d), for code compiled elsewhere (newlib,
     libm, libgcc, libstdc++): frame size estimated from the prologue (push, vpush, sub sp) and
     calls from bl / b.w to other functions. Marked "est." in the report; an over-estimate.
  3. .su files (-fstack-usage) alone, when there are no .ci files: the largest frames only.

The worst path from each root (default: Reset_Handler, i.e. everything the firmware runs in
thread mode; and main) is the longest path in the call graph weighted by frame size. Recursion,
indirect calls and dynamic frames cannot be bounded this way: they are listed as warnings.
Exception handlers run on top of the thread's stack: add the largest handler path if
interrupts are enabled (test firmware enables none).

usage: stack_report.py [--elf fw.elf] [--objdump arm-none-eabi-objdump]
                       [--root NAME]... [--top N] [--out FILE] DIR_OR_FILE...
--root: a symbol, or part of a demangled name ("demo::cholesky_solve"); repeatable.
DIR_OR_FILE: object directories (searched recursively for .ci and .su) or single files.
Exit status 0; 2 on bad arguments.
"""
import argparse
import os
import re
import subprocess
import sys

NODE_RE = re.compile(r'^node:\s*\{\s*title:\s*"((?:[^"\\]|\\.)*)"\s*label:\s*"((?:[^"\\]|\\.)*)"(.*)\}\s*$')
EDGE_RE = re.compile(r'^edge:\s*\{\s*sourcename:\s*"((?:[^"\\]|\\.)*)"\s*targetname:\s*"((?:[^"\\]|\\.)*)"')
STACK_RE = re.compile(r'(\d+) bytes \(([a-z,]+)\)')
INDIRECT = "__indirect_call"


class Func:
    __slots__ = ("name", "pretty", "where", "frame", "kind", "source", "callees")

    def __init__(self, name):
        self.name = name
        self.pretty = name
        self.where = ""
        self.frame = None  # bytes, None = unknown
        self.kind = ""     # static | dynamic | dynamic,bounded | est. | est.,dynamic
        self.source = ""   # ci | elf
        self.callees = set()


def walk(paths, ext):
    for p in paths:
        if os.path.isfile(p):
            if p.endswith(ext):
                yield p
            continue
        for root, _dirs, files in os.walk(p):
            for f in sorted(files):
                if f.endswith(ext):
                    yield os.path.join(root, f)


def read_ci(paths, funcs, canon):
    count = 0
    for path in walk(paths, ".ci"):
        count += 1
        with open(path, encoding="utf-8", errors="replace") as fh:
            for line in fh:
                line = line.strip()
                m = NODE_RE.match(line)
                if m:
                    key, label = canon(m.group(1)), m.group(2)
                    parts = label.split("\\n")
                    st = STACK_RE.search(label)
                    f = funcs.get(key)
                    if f is None:
                        f = funcs[key] = Func(key)
                    if parts and (st or f.pretty == key):
                        f.pretty = parts[0]
                    if len(parts) > 1 and not f.where:
                        f.where = parts[1]
                    if st:
                        size = int(st.group(1))
                        if f.source != "ci" or f.frame is None or size > f.frame:
                            f.frame, f.kind, f.source = size, st.group(2), "ci"
                        f.where = parts[1] if len(parts) > 1 else f.where
                    continue
                m = EDGE_RE.match(line)
                if m:
                    src, dst = canon(m.group(1)), canon(m.group(2))
                    funcs.setdefault(src, Func(src)).callees.add(dst)
    return count


def read_su(paths):
    rows = []
    for path in walk(paths, ".su"):
        with open(path, encoding="utf-8", errors="replace") as fh:
            for line in fh:
                cols = line.rstrip("\n").split("\t")
                if len(cols) >= 3 and cols[1].isdigit():
                    rows.append((int(cols[1]), cols[2], cols[0]))
    return rows


FUNC_HDR_RE = re.compile(r"^([0-9a-f]+) <(.+)>:$")
INSN_RE = re.compile(r"^\s*[0-9a-f]+:\s+(\S+)\s*(.*)$")
TARGET_RE = re.compile(r"<([^>+]+)(\+0x[0-9a-f]+)?>")
REG_RANGE_RE = re.compile(r"([rsd])(\d+)(?:-[rsd]?(\d+))?")


def count_regs(operands):
    inner = operands[operands.find("{") + 1: operands.find("}")]
    total = 0
    for tok in inner.split(","):
        tok = tok.strip()
        m = REG_RANGE_RE.match(tok)
        if m:
            kind, a, b = m.group(1), int(m.group(2)), m.group(3)
            n = (int(b) - a + 1) if b is not None else 1
            total += n * (8 if kind == "d" else 4)
        elif tok in ("lr", "ip", "fp", "sl", "sb", "pc", "sp"):
            total += 4
    return total


SYM_RE = re.compile(r"^([0-9a-f]+)\s.*\sF\s+\S+\s+[0-9a-f]+\s+(.+)$")


def read_symbols(elf, objdump):
    """Function symbols of the ELF: name -> set of addresses (aliases such as C1/C2 share one)."""
    try:
        out = subprocess.run([objdump, "-t", elf], check=True, capture_output=True,
                             text=True).stdout
    except (OSError, subprocess.CalledProcessError) as e:
        print(f"stack_report: cannot read symbols of {elf}: {e}", file=sys.stderr)
        return {}
    names = {}
    for line in out.splitlines():
        m = SYM_RE.match(line)
        if m:
            names.setdefault(m.group(2).strip(), set()).add(int(m.group(1), 16) & ~1)
    return names


def make_canon(symbols):
    """Maps a .ci title or symbol name to one key per function: '@<address>' when the ELF has
    exactly one function of that name (merges aliases and file-qualified local names)."""
    def canon(title):
        bare = title.rsplit(":", 1)[-1]  # .ci titles of local functions are "file:symbol"
        addrs = symbols.get(bare)
        if addrs and len(addrs) == 1:
            return "@%x" % next(iter(addrs))
        return title
    return canon


def read_elf(elf, objdump, funcs, symbols):
    try:
        out = subprocess.run([objdump, "-d", "--no-show-raw-insn", elf], check=True,
                             capture_output=True, text=True).stdout
    except (OSError, subprocess.CalledProcessError) as e:
        print(f"stack_report: cannot disassemble {elf}: {e}", file=sys.stderr)
        return 0
    cur = None
    cur_elf_only = False
    n = 0
    for line in out.splitlines():
        m = FUNC_HDR_RE.match(line)
        if m:
            name = m.group(2)
            if name.startswith("$") or name.startswith(".L"):
                continue
            n += 1
            key = "@%x" % (int(m.group(1), 16) & ~1)
            cur = funcs.get(key)
            if cur is None:
                cur = funcs[key] = Func(key)
            if cur.pretty == key:
                cur.pretty = name
            if cur.source != "ci":
                cur.source, cur.frame, cur.kind = "elf", 0, "est."
            cur_elf_only = cur.source == "elf"
            continue
        if cur is None:
            continue
        m = INSN_RE.match(line)
        if not m:
            continue
        op, args = m.group(1), m.group(2)
        base = op.split(".")[0]
        if cur_elf_only:
            if base in ("push", "vpush") or (base.startswith("stmdb") and args.startswith("sp!")):
                cur.frame += count_regs(args)
            elif base in ("str", "strd") and re.search(r"\[sp,\s*#-(\d+)\]!", args):
                cur.frame += int(re.search(r"\[sp,\s*#-(\d+)\]!", args).group(1))
            elif base in ("sub", "subw") and re.match(r"sp,\s*(sp,\s*)?#", args):
                cur.frame += int(re.search(r"#(\d+)", args).group(1))
            elif base in ("sub", "subw") and re.match(r"sp,\s*(sp,\s*)?[rl]", args):
                cur.kind = "est.,dynamic"
        t = TARGET_RE.search(args)
        if base in ("bl", "b") or (base.startswith("b") and base[1:] in (
                "eq", "ne", "cs", "cc", "hs", "lo", "mi", "pl", "vs", "vc",
                "hi", "ls", "ge", "lt", "gt", "le", "al")):
            if t and t.group(2) is None:
                addr = re.match(r"\s*([0-9a-f]+)", args)
                key = "@%x" % (int(addr.group(1), 16) & ~1) if addr else t.group(1)
                if key != cur.name:
                    cur.callees.add(key)
        elif base == "blx" and not t:
            cur.callees.add(INDIRECT)
        elif base == "bx" and args.strip() not in ("lr",):
            cur.callees.add(INDIRECT)
    return n


def worst_paths(funcs, root):
    memo = {}
    warnings = set()
    on_stack = set()

    def visit(name):
        if name in memo:
            return memo[name]
        if name == INDIRECT:
            warnings.add("indirect call(s): not followed")
            return (0, [])
        f = funcs.get(name)
        if f is None:
            warnings.add(f"no frame information for {name} (counted as 0)")
            memo[name] = (0, [name])
            return memo[name]
        if name in on_stack:
            warnings.add(f"recursion through {f.pretty}: depth unbounded (one level counted)")
            return (0, [])
        on_stack.add(name)
        if f.kind and "dynamic" in f.kind and "bounded" not in f.kind:
            warnings.add(f"dynamic (unbounded) frame in {f.pretty}")
        best = (0, [])
        for c in sorted(f.callees):
            if c == INDIRECT:
                warnings.add(f"indirect call(s) in {f.pretty}: not followed")
                continue
            r = visit(c)
            if r[0] > best[0]:
                best = r
        on_stack.discard(name)
        res = ((f.frame or 0) + best[0], [name] + best[1])
        memo[name] = res
        return res

    total, path = visit(root)
    return total, path, sorted(warnings)


def fmt_path(funcs, path):
    lines = []
    cum = 0
    for name in path:
        f = funcs.get(name)
        frame = (f.frame or 0) if f else 0
        cum += frame
        kind = f.kind if f else "unknown"
        pretty = f.pretty if f else name
        if len(pretty) > 60:
            pretty = pretty[:57] + "..."
        where = f.where if f and f.where else ""
        lines.append(f"  {frame:7d} {cum:7d}  {pretty:<60s} [{kind}] {where}")
    return lines


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("paths", nargs="*", help="object directories or .ci/.su files")
    ap.add_argument("--elf", help="linked firmware, for library code and final call edges")
    ap.add_argument("--objdump", default="arm-none-eabi-objdump")
    ap.add_argument("--root", action="append",
                    help="root function: symbol, or part of a demangled name (e.g. "
                         "'arm::prox_pv'); repeatable; default Reset_Handler and main")
    ap.add_argument("--top", type=int, default=10, help="largest frames to list")
    ap.add_argument("--out", help="write the report here as well as to stdout")
    args = ap.parse_args(argv)
    if not args.paths and not args.elf:
        ap.error("give object directories and/or --elf")

    funcs = {}
    symbols = read_symbols(args.elf, args.objdump) if args.elf else {}
    canon = make_canon(symbols)
    n_ci = read_ci(args.paths, funcs, canon)
    n_elf = read_elf(args.elf, args.objdump, funcs, symbols) if args.elf else 0
    report = []
    title = args.elf or ", ".join(args.paths)
    report.append(f"stack report for {title}")
    report.append(f"  sources: {n_ci} .ci file(s), {n_elf} function(s) disassembled from the ELF")
    if n_ci == 0:
        report.append("  no .ci files (gcc without -fcallgraph-info?): frames below are from .su only")
        rows = sorted(read_su(args.paths), reverse=True)
        for size, kind, where in rows[: args.top]:
            report.append(f"  {size:7d}  {where} [{kind}]")
        if not n_elf:
            text = "\n".join(report) + "\n"
            sys.stdout.write(text)
            if args.out:
                with open(args.out, "w") as fh:
                    fh.write(text)
            return 0
    # Only keep functions that exist in the final image, when we have it (drops inlined ones).
    roots = args.root or ["Reset_Handler", "main"]
    for root in roots:
        if canon(root) in funcs:
            keys = [canon(root)]
        else:  # a demangled name or a part of one, e.g. "arm::prox_pv"
            keys = sorted(k for k, f in funcs.items() if root in f.pretty and f.source)
        if not keys:
            report.append(f"\nroot {root}: not found")
            continue
        for key in keys:
            total, path, warns = worst_paths(funcs, key)
            label = root if len(keys) == 1 else funcs[key].pretty
            report.append(f"\nworst stack from {label}: {total} bytes")
            report.append(f"  {'frame':>7s} {'cumul':>7s}  function")
            report.extend(fmt_path(funcs, path))
            for w in warns:
                report.append(f"  warning: {w}")
    handlers = [k for k, f in funcs.items()
                if re.search(r"\b\w+_Handler\b", f.pretty) and "Reset_Handler" not in f.pretty]
    if handlers:
        worst_h = max((worst_paths(funcs, h)[0], funcs[h].pretty) for h in handlers)
        report.append(f"\nlargest exception-handler path: {worst_h[1]} {worst_h[0]} bytes "
                      "(+32..104 bytes of hardware exception frame) - on top of the thread stack")
    ci_funcs = sorted((f for f in funcs.values() if f.source == "ci" and f.frame is not None),
                      key=lambda f: -f.frame)
    report.append(f"\nlargest frames compiled here (-fcallgraph-info / -fstack-usage):")
    for f in ci_funcs[: args.top]:
        report.append(f"  {f.frame:7d}  {f.pretty} [{f.kind}] {f.where}")
    text = "\n".join(report) + "\n"
    sys.stdout.write(text)
    if args.out:
        with open(args.out, "w") as fh:
            fh.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
