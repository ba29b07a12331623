#!/usr/bin/env python3
"""Counts the instructions a firmware executes between fw::trace_begin() and fw::trace_end()
(support/include/fw/trace.hpp), running it under qemu with a one-instruction-per-block exec
trace. qemu is not cycle-accurate: this is an instruction count, not a time.

usage: count_insns.py MACHINE ELF [--timeout S] [--top N] [--qemu qemu-system-arm]
Prints the firmware's own output, then one line per marked region:
    region 1: 1234 instructions
and, per region, the functions that executed the most instructions (exclusive counts).
The count includes ~3 instructions of the marker calls. Exit status: the firmware's.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile
import threading


def qemu_one_insn_args(qemu):
    out = subprocess.run([qemu, "--version"], capture_output=True, text=True).stdout
    m = re.search(r"version (\d+)\.", out)
    if m and int(m.group(1)) >= 8:
        return ["-accel", "tcg,one-insn-per-tb=on"]
    return ["-singlestep"]  # qemu <= 7


def main(argv):
    ap = argparse.ArgumentParser(description="instruction counts between trace markers")
    ap.add_argument("machine")
    ap.add_argument("elf")
    ap.add_argument("--timeout", type=float, default=300)
    ap.add_argument("--top", type=int, default=8)
    ap.add_argument("--qemu", default=os.environ.get("QEMU_SYSTEM_ARM", "qemu-system-arm"))
    args = ap.parse_args(argv)

    regions = []  # (total, {symbol: count})
    with tempfile.TemporaryDirectory() as tmp:
        fifo = os.path.join(tmp, "exec.log")
        os.mkfifo(fifo)
        cmd = [args.qemu, "-M", args.machine, "-nographic",
               "-semihosting-config", "enable=on,target=native", "-kernel", args.elf,
               *qemu_one_insn_args(args.qemu), "-d", "nochain,exec", "-D", fifo]
        proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL)

        def parse():
            active = None
            with open(fifo, encoding="utf-8", errors="replace") as fh:
                for line in fh:
                    if not line.startswith("Trace"):
                        continue
                    sym = line.rsplit(" ", 1)[-1].strip()
                    if sym == "fw_trace_begin":
                        active = [0, {}]
                        continue
                    if active is None:
                        continue
                    if sym == "fw_trace_end":
                        regions.append(active)
                        active = None
                        continue
                    active[0] += 1
                    active[1][sym] = active[1].get(sym, 0) + 1

        reader = threading.Thread(target=parse, daemon=True)
        reader.start()
        try:
            rc = proc.wait(timeout=args.timeout)
        except subprocess.TimeoutExpired:
            proc.kill()
            print(f"count_insns: TIMEOUT after {args.timeout}s", file=sys.stderr)
            rc = 124
        reader.join(timeout=60)

    sys.stdout.flush()
    for i, (total, per_sym) in enumerate(regions, 1):
        print(f"region {i}: {total} instructions")
        for sym, n in sorted(per_sym.items(), key=lambda kv: -kv[1])[: args.top]:
            print(f"    {n:9d}  {sym}")
    if not regions:
        print("count_insns: no fw_trace_begin/fw_trace_end region executed", file=sys.stderr)
    return rc


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
