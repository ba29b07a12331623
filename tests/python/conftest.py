"""Test support for the Python suites: where the shared models, the generated
modules and the `proxgen` binary are (ctest sets the environment: see
tests/python/CMakeLists.txt), the shared cases, and random states."""

import importlib
import json
import os
import subprocess

import numpy as np
import pytest

import proxgen

MODELS_DIR = os.environ.get("PROXGEN_TEST_MODELS_DIR", "")
SOURCE_DIR = os.environ.get("PROXGEN_TEST_SOURCE_DIR",
                            os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
UNDER_CI = os.environ.get("CI") == "true"
CASES_FILE = os.path.join(MODELS_DIR, "cases.yaml") if MODELS_DIR else ""
QUADRUPED_DIR = os.path.join(SOURCE_DIR, "generated", "quadruped")


def require_models():
    """Skips (fails under CI=true) without the shared models, like PROXGEN_REQUIRE_MODELS."""
    if not CASES_FILE or not os.path.isfile(CASES_FILE):
        if UNDER_CI:
            pytest.fail("shared models folder missing (PROXGEN_MODELS_DIR)")
        pytest.skip("needs the shared models folder: configure with -DPROXGEN_MODELS_DIR=...")


def shared_case_names():
    """The nine cases of cases.yaml (empty without the models), through the library's loader."""
    if not CASES_FILE or not os.path.isfile(CASES_FILE):
        return []
    return proxgen.case_names(CASES_FILE)


def proxgen_binary():
    return proxgen.executable()


def run_proxgen(*args):
    return subprocess.run([proxgen_binary(), *args], capture_output=True, text=True)


def module(name):
    """A generated module built by tests/python/CMakeLists.txt (skipped if not built there)."""
    wanted = os.environ.get("PROXGEN_TEST_MODULES", "").split(",")
    try:
        return importlib.import_module(name)
    except ImportError:
        if name in wanted and (UNDER_CI or name not in ("iiwa_h6", "solo_f3x2")):
            raise
        pytest.skip(f"module {name} not built (run through ctest)")


# Quaternions whose norm is exactly 1 in binary (components 0, +-0.5, +-1): the
# package and `proxgen eval` then normalise them to the same bits whatever the
# order of their sums, so the two see identical inputs.
EXACT_QUATERNIONS = [np.array(x, dtype=float) for x in
                     ([0, 0, 0, 1], [1, 0, 0, 0], [0, 1, 0, 0], [0.5, 0.5, 0.5, 0.5], [-0.5, 0.5, -0.5, 0.5],
                      [0.5, -0.5, -0.5, -0.5], [0, 0, 1, 0])]


def random_state(robot, rng, exact_quaternion=True):
    """q inside the joint limits ([-1, 1] without), base position in [-1, 1]^3, a unit
    quaternion (exact-norm set, or uniform), v and tau uniform in [-1, 1]."""
    q = np.zeros(robot.nq)
    for j in robot.joints.values():
        if j.type == "free_flyer":
            q[j.idx_q:j.idx_q + 3] = rng.uniform(-1, 1, 3)
            if exact_quaternion:
                q[j.idx_q + 3:j.idx_q + 7] = EXACT_QUATERNIONS[rng.integers(len(EXACT_QUATERNIONS))]
            else:
                quat = rng.normal(size=4)
                q[j.idx_q + 3:j.idx_q + 7] = quat / np.linalg.norm(quat)
        elif j.limits is not None and j.limits[1] > j.limits[0]:
            q[j.idx_q] = rng.uniform(j.limits[0], j.limits[1])
        else:
            q[j.idx_q] = rng.uniform(-1, 1)
    return q, rng.uniform(-1, 1, robot.nv), rng.uniform(-1, 1, robot.nv)


EPS = np.finfo(float).eps

# tests/numerics.hpp's round-off model: each of these is a chain of backward-stable
# eliminations, so its relative error is c n eps kappa_s, c = 10, kappa_s the condition
# of the Jacobi-scaled matrix that is (in effect) factored.
C = 10.0


def scaled_condition(A):
    """tests/numerics.hpp's scaledCondition: the condition number of D^-1/2 A D^-1/2,
    D = diag(A), on its range (eigenvalues at or below n eps times the largest are zero)."""
    d = np.diag(A)
    s = np.where(d > 0, 1 / np.sqrt(np.where(d > 0, d, 1)), 1.0)
    ev = np.linalg.eigvalsh(s[:, None] * A * s[None, :])
    top = ev.max()
    return top / ev[ev > len(A) * EPS * top].min()


def rel_err(a, b):
    """max |a - b| / max(1, max |b|), as tests/support.hpp's relErr."""
    a, b = np.asarray(a), np.asarray(b)
    if b.size == 0:
        return 0.0
    return float(np.max(np.abs(a - b)) / max(1.0, float(np.max(np.abs(b)))))


@pytest.fixture
def quadruped():
    return proxgen.load(os.path.join(QUADRUPED_DIR, "quadruped.urdf"), os.path.join(QUADRUPED_DIR, "layout.yaml"))


@pytest.fixture
def rng():
    return np.random.default_rng(17)


def write_json(path, obj):
    with open(path, "w") as f:
        json.dump(obj, f)
