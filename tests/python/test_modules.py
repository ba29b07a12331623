"""Each generated module against the package's generic solvers, and its many-state
path against its single-state path."""

import os

import numpy as np
import pytest

import proxgen
from conftest import CASES_FILE, QUADRUPED_DIR, SOURCE_DIR, module, random_state, rel_err, require_models

# (module, how to load the same System in the package, scalar)
MODULES = [
    ("quadruped", lambda: proxgen.load(os.path.join(QUADRUPED_DIR, "quadruped.urdf"),
                                       os.path.join(QUADRUPED_DIR, "layout.yaml")), "double"),
    ("quadruped_float", lambda: proxgen.load(os.path.join(QUADRUPED_DIR, "quadruped.urdf"),
                                             os.path.join(QUADRUPED_DIR, "layout.yaml")), "float"),
    ("hostile_names", lambda: proxgen.load(os.path.join(SOURCE_DIR, "tests", "data", "hostile", "names.urdf"),
                                           os.path.join(SOURCE_DIR, "tests", "data", "hostile", "names.yaml")), "double"),
    ("iiwa_h6", lambda: proxgen.load_case(CASES_FILE, "iiwa_h6"), "double"),
    ("solo_f3x2", lambda: proxgen.load_case(CASES_FILE, "solo_f3x2"), "double"),
]
# The tolerances of `proxgen verify`: the generated code runs the same recursions in
# another order of operations, so it differs from the generic solver by about
# cond * eps. In double, 1e-8 relative leaves cond up to ~1e7 (measured here: errors
# below 1e-10 at mu = 1e4, so cond ~ 5e5 for the quadruped). In float (eps = 6e-8)
# that cond would give 3e-2: the float solver itself loses that much at mu = 1e4
# (a property of float, not of the module). So the float module is compared at
# mu = 100, where the double errors (below 5e-13) put cond near 5e3 and the float
# error near 3e-4, against the generic solver on the inputs rounded to float as
# the module rounds them; 1e-2 leaves a factor 30.
TOLERANCE = {"double": 1e-8, "float": 1e-2}
SETTINGS = {"double": ({}, {"iterations": 1, "mu": 100.0}, {"iterations": 12}),
            "float": ({"mu": 100.0}, {"iterations": 1, "mu": 100.0}, {"iterations": 12, "mu": 100.0})}
PAIRS = (("prox_pv", "pv"), ("constrained_aba", "caba"))


def load(name, loader):
    if name in ("iiwa_h6", "solo_f3x2"):
        require_models()
    return module(name), loader()


@pytest.mark.parametrize("name,loader,scalar", MODULES, ids=[m[0] for m in MODULES])
def test_module_describes_its_robot(name, loader, scalar):
    m, robot = load(name, loader)
    assert (m.nq, m.nv, m.nc) == (robot.nq, robot.nv, robot.nc)
    assert m.joint_names == robot.joint_names and m.constraint_names == robot.constraint_names
    for j in robot.joints.values():
        assert m.joints[j.name] == {"type": j.type, "idx_q": j.idx_q, "nq": j.nq, "idx_v": j.idx_v, "nv": j.nv}
    for c in robot.constraints.values():
        assert m.constraints[c.name] == {"type": c.type, "row": c.row, "rows": c.rows}
    assert m.scalar == scalar and m.mu == robot.mu and m.iterations == robot.iterations


@pytest.mark.parametrize("name,loader,scalar", MODULES, ids=[m[0] for m in MODULES])
def test_module_matches_the_generic_solvers(name, loader, scalar, rng):
    m, robot = load(name, loader)
    for _ in range(10):
        q, v, tau = random_state(robot, rng, exact_quaternion=False)
        rounded = [x.astype(np.float32).astype(np.float64) for x in (q, v, tau)] if scalar == "float" else (q, v, tau)
        for fn, algorithm in PAIRS:
            for kw in SETTINGS[scalar]:
                qdd, lam = getattr(m, fn)(q, v, tau, **kw)
                ref_qdd, ref_lam = robot.eval(*rounded, algorithm, **kw)
                assert qdd.shape == (robot.nv,) and lam.shape == (robot.nc,)
                assert qdd.dtype == (np.float32 if scalar == "float" else np.float64)
                assert rel_err(qdd, ref_qdd) < TOLERANCE[scalar], (fn, kw)
                assert rel_err(lam, ref_lam) < TOLERANCE[scalar], (fn, kw)


@pytest.mark.parametrize("name,loader,scalar", MODULES, ids=[m[0] for m in MODULES])
def test_many_states_are_the_single_states(name, loader, scalar, rng):
    m, robot = load(name, loader)
    states = [random_state(robot, rng, exact_quaternion=False) for _ in range(7)]
    Q, V, T = (np.array([s[k] for s in states]) for k in range(3))
    for fn, _ in PAIRS:
        qdd, lam = getattr(m, fn)(Q, V, T, iterations=4)
        assert qdd.shape == (7, robot.nv) and lam.shape == (7, robot.nc)
        for k in range(7):
            one_qdd, one_lam = getattr(m, fn)(*states[k], iterations=4)
            # The same solver on the same inputs: identical bits (a solver reading a
            # workspace entry left over from the previous state would break this).
            assert np.array_equal(qdd[k], one_qdd) and np.array_equal(lam[k], one_lam)
    # A single state given as a batch of one keeps the batch axis.
    qdd, lam = m.prox_pv(Q[:1], V[:1], T[:1])
    assert qdd.shape == (1, robot.nv)


def test_module_normalises_the_quaternion_as_the_package(rng):
    m, robot = load(*MODULES[0][:2])
    q, v, tau = random_state(robot, rng, exact_quaternion=False)
    scaled = q.copy()
    scaled[3:7] *= 3.0
    # q / |q| differs from the unit quaternion by round-off only: 1e-12 relative
    # (a few ulp in q, amplified by the solve as in TOLERANCE).
    assert rel_err(m.prox_pv(scaled, v, tau)[0], m.prox_pv(q, v, tau)[0]) < 1e-12
    assert rel_err(m.prox_pv(scaled, v, tau)[0], robot.eval(scaled, v, tau, "pv")[0]) < TOLERANCE["double"]
