"""examples/python/quadruped_stand.py: the layout's targets are the stance's feet,
and a run keeps the constraint drift within the bound of its Baumgarte loop."""

import importlib.util
import json
import os

import numpy as np
import pytest

import proxgen
from conftest import SOURCE_DIR, module

EXAMPLE = os.path.join(SOURCE_DIR, "examples", "python", "quadruped_stand.py")


def load_example():
    spec = importlib.util.spec_from_file_location("quadruped_stand_example", EXAMPLE)
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    return example


def test_the_layout_targets_are_the_stance_feet(rng):
    ex = load_example()
    robot = proxgen.load(ex.URDF, ex.LAYOUT)
    q0, feet = ex.stance(robot)
    assert min(p[2] for p in feet.values()) == 0.0  # the lowest foot on the ground
    # At the stance and at rest the Baumgarte target a* = -kd v_C - kp R^T (p_C - p*) is
    # exactly 0 when the layout's targets are the feet (printed with repr, they read
    # back as the same doubles the kinematics gives): the solve is then bit for bit the
    # one without gains. A target off by one ulp (4e-17 m) would change it.
    plain = proxgen.load(ex.URDF, {"base": "floating", "constraints": [{"name": n, "link": l, "type": "3d"}
                                                                       for n, l in ex.FEET]})
    tau = rng.uniform(-1, 1, robot.nv)
    for algorithm in ("pv", "caba"):
        a, b = robot.eval(q0, np.zeros(robot.nv), tau, algorithm), plain.eval(q0, np.zeros(robot.nv), tau, algorithm)
        assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    solver = module("quadruped_baumgarte")
    assert solver.constraint_names == robot.constraint_names and solver.nc == 12


def test_a_run_keeps_the_drift_bounded(tmp_path):
    ex = load_example()
    solver = module("quadruped_baumgarte")
    robot = proxgen.load(ex.URDF, ex.LAYOUT)
    log = ex.simulate(solver, robot, duration=1.0, dt=1e-3, push=True)  # through the wobble at 0.5-0.6 s
    drift, residual, speed = log["drift"], log["residual"], log["speed"]
    assert drift[0] == 0.0 and np.all(np.isfinite(drift))
    # The bound. Each foot error e (world, 3) obeys e'' + kd e' + kp e = r: the solver
    # asks for a* = -kd e' - kp e, and r is what it misses by, the residual
    # ||J qdd + gamma - a*|| it reports (finite mu and K = 3), plus what semi-implicit
    # Euler adds: a step moves the foot by dt J v + (dt^2 / 2) v^T (d^2 p / dq^2) v, the
    # second term at most (dt^2 / 2) L |v|^2 with L = 0.5 m (longer than any lever arm
    # from a joint of this robot to a foot: hip to foot 0.42 m, base half-length 0.19 m),
    # an acceleration error of (L / 2) |v|^2. With e(0) = e'(0) = 0 and the critically
    # damped loop's impulse response t exp(-omega t), whose integral is 1 / omega^2 = 1 / kp,
    # |e| <= sup r / kp. Another 25 % for the discrete loop (omega dt = 0.05: its impulse
    # response sums to within a few % of the continuous one) and for C's frame rotating
    # against the world's (the residual is measured in C).
    r = residual.max() + 0.5 * 0.5 * speed.max() ** 2
    bound = 1.25 * r / ex.KP
    assert drift.max() <= bound, (drift.max(), bound)
    # And the bound is not vacuous: the feet stay within 1 mm of their places.
    assert bound < 1e-3, bound
    # The wobble is over by 0.6 s: the drift decays again (the loop settles in ~0.1 s).
    assert drift[-1] < 0.5 * drift.max()


def test_the_script_writes_the_plot(tmp_path):
    module("quadruped_baumgarte")
    ex = load_example()
    png, summary = tmp_path / "stand.png", tmp_path / "summary.json"
    assert ex.main(["--duration", "0.3", "--out", str(png), "--summary", str(summary)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    s = json.loads(summary.read_text())
    assert s["steps"] == 300
