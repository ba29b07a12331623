#!/usr/bin/env python3
"""Writes a synthetic URDF of a given size for the resource measurements of
docs/guarantees.md (the output is not checked in: it is tens of megabytes).

    make_big_urdf.py OUT.urdf --bytes 50e6 --shape tree|chain [--branching 3]

Every body is a 1 kg link on a revolute joint (axes cycling x, y, z), 0.1 m
from its parent; `tree` gives body i the parent (i - 1) // branching (depth
log_b n), `chain` the parent i - 1 (depth n). tests/model/test_hardening.cpp builds
the same robots in memory (syntheticTreeUrdf in tests/support.cpp) for its 2000-body tests.
"""
import argparse

LINK = ('<link name="l{i}"><inertial><origin xyz="0 0 0.05"/><mass value="1"/>'
        '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>\n')
JOINT = ('<joint name="j{i}" type="revolute"><parent link="l{p}"/><child link="l{i}"/>'
         '<origin xyz="0 0 0.1"/><axis xyz="{axis}"/>'
         '<limit lower="-1" upper="1" effort="10" velocity="1"/></joint>\n')
AXES = ["1 0 0", "0 1 0", "0 0 1"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--bytes", type=float, default=50e6)
    ap.add_argument("--shape", choices=["tree", "chain"], default="tree")
    ap.add_argument("--branching", type=int, default=3)
    a = ap.parse_args()
    with open(a.out, "w") as f:
        f.write('<?xml version="1.0"?>\n<robot name="big">\n')
        f.write(LINK.format(i=0))
        size, i = 0, 0
        while size < a.bytes:
            i += 1
            p = i - 1 if a.shape == "chain" else (i - 1) // a.branching
            text = JOINT.format(i=i, p=p, axis=AXES[i % 3]) + LINK.format(i=i)
            f.write(text)
            size += len(text)
        f.write("</robot>\n")
    print(f"{a.out}: {i} moving bodies, shape {a.shape}")


if __name__ == "__main__":
    main()
