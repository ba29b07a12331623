"""The dynamics library of the package (Robot.inverse_dynamics ... delassus_inverse)
against `proxgen eval --compute`, numpy identities, and bad input."""

import json
import os

import numpy as np
import pytest

import proxgen
from conftest import (C, CASES_FILE, EPS, QUADRUPED_DIR, SOURCE_DIR, random_state, require_models, run_proxgen,
                      scaled_condition)

URDF = os.path.join(QUADRUPED_DIR, "quadruped.urdf")

# The examples (the quadruped on its four feet, and examples/python's Baumgarte layout)
# and two shared cases (a 6d hand on a fixed arm, a floating base on two 3d feet).
SYSTEMS = ["quadruped", "quadruped_stand", "iiwa_h6", "solo_f3x2"]


def load_system(name, tmp_path):
    """(robot, urdf, layout path) of one of SYSTEMS; the shared cases need the models."""
    if name == "quadruped":
        layout = os.path.join(QUADRUPED_DIR, "layout.yaml")
        return proxgen.load(URDF, layout), URDF, layout
    if name == "quadruped_stand":
        layout = os.path.join(SOURCE_DIR, "examples", "python", "quadruped_stand.yaml")
        return proxgen.load(URDF, layout), URDF, layout
    require_models()
    import yaml
    with open(CASES_FILE) as f:
        entry = next(c for c in yaml.safe_load(f)["cases"] if c["name"] == name)
    layout = tmp_path / "layout.yaml"
    layout.write_text(json.dumps({k: v for k, v in entry.items() if k not in ("name", "model")}))
    return proxgen.load_case(CASES_FILE, name), proxgen.case_urdf(CASES_FILE, name), str(layout)


def compute(urdf, layout, states, quantity, tmp_path, *options):
    path = tmp_path / f"{quantity}.json"
    path.write_text(json.dumps(states))
    p = run_proxgen("eval", urdf, "--layout", layout, "--state", str(path), "--compute", quantity, *options)
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout)


def matrix(result):
    return np.array(result["values"], dtype=float).reshape(len(result["rows"]), len(result["cols"]))


@pytest.mark.parametrize("name", SYSTEMS)
def test_every_quantity_is_the_cli_bit_for_bit(name, tmp_path, rng):
    robot, urdf, layout = load_system(name, tmp_path)
    states = []
    for _ in range(3):
        q, v, _ = random_state(robot, rng)  # exact-norm quaternions: both sides normalise to the same bits
        states.append((q, v, rng.uniform(-1, 1, robot.nv), rng.uniform(-1, 1, robot.nc)))
    plain = [robot.named(q=q, v=v) for q, v, _, _ in states]
    # Every comparison is exact: the same library functions on the same doubles (JSON
    # carries them exactly both ways: Python and nlohmann print shortest round-trip forms).
    for quantity, method, key in (("mass_matrix", robot.mass_matrix, "M"),
                                  ("mass_matrix_inverse", robot.mass_matrix_inverse, "Minv"),
                                  ("jacobian", robot.constraint_jacobian, "J"),
                                  ("delassus", robot.delassus, "G")):
        for (q, _, _, _), result in zip(states, compute(urdf, layout, plain, quantity, tmp_path)):
            got = method(q)
            assert got.shape == matrix(result[key]).shape and np.array_equal(got, matrix(result[key])), quantity
    for options, mu in (([], None), (["--mu", "250"], 250.0)):
        for (q, _, _, _), result in zip(states, compute(urdf, layout, plain, "delassus_inverse", tmp_path, *options)):
            assert np.array_equal(robot.delassus_inverse(q, mu), matrix(result["Ginv"])), options
            assert result["mu"] == (robot.mu if mu is None else mu)
    for (q, v, _, _), result in zip(states, compute(urdf, layout, plain, "nonlinear_effects", tmp_path)):
        assert robot.named(tau=robot.nonlinear_effects(q, v))["tau"] == result["h"]
    for (q, v, _, _), result in zip(states, compute(urdf, layout, plain, "drift", tmp_path)):
        assert robot.named(lam=robot.constraint_drift(q, v))["lam"] == result["gamma"]
    for (q, _, _, _), result in zip(states, compute(urdf, layout, plain, "placements", tmp_path)):
        X = robot.constraint_placements(q)
        assert X.shape == (len(robot.constraint_names), 4, 4)
        for k, c in enumerate(robot.constraint_names):
            assert X[k, :3, :3].tolist() == result["placements"][c]["rotation"]
            assert X[k, :3, 3].tolist() == result["placements"][c]["position"]
            assert X[k, 3].tolist() == [0.0, 0.0, 0.0, 1.0]
    # inverse_dynamics with and without lambda.
    with_lam = []
    for (q, v, qdd, lam), s in zip(states, plain):
        named = robot.named(qdd=qdd, lam=lam)
        with_lam.append(dict(s, qdd=named["qdd"], **{"lambda": named["lam"]}))
    for (q, v, qdd, lam), result in zip(states, compute(urdf, layout, with_lam, "inverse_dynamics", tmp_path)):
        assert robot.named(tau=robot.inverse_dynamics(q, v, qdd, lam))["tau"] == result["tau"]
    without = [dict(s, qdd=robot.named(qdd=qdd)["qdd"]) for (_, _, qdd, _), s in zip(states, plain)]
    for (q, v, qdd, _), result in zip(states, compute(urdf, layout, without, "inverse_dynamics", tmp_path)):
        assert robot.named(tau=robot.inverse_dynamics(q, v, qdd))["tau"] == result["tau"]




@pytest.mark.parametrize("name", SYSTEMS)
def test_the_inverses_are_inverses(name, tmp_path, rng):
    robot, _, _ = load_system(name, tmp_path)
    for _ in range(3):
        q, _, _ = random_state(robot, rng, exact_quaternion=False)
        M, Minv = robot.mass_matrix(q), robot.mass_matrix_inverse(q)
        assert np.array_equal(Minv, Minv.T)  # documented: exactly symmetric
        # Minv's entries are off by c nv eps kappa_s(M) |Minv| at most; M times that
        # error is at most |M|_inf (row sums) times it.
        err_minv = C * robot.nv * EPS * scaled_condition(M) * np.max(np.abs(Minv))
        assert np.max(np.abs(M @ Minv - np.eye(robot.nv))) <= np.max(np.abs(M).sum(axis=1)) * err_minv
        if robot.nc == 0:
            continue
        G = robot.delassus(q)
        J = robot.constraint_jacobian(q)
        # G from the pieces against numpy's products of the same pieces: only the order
        # of the sums differs, a relative nv eps per entry (c = 10 for the two products).
        assert np.max(np.abs(G - J @ Minv @ J.T)) <= C * robot.nv * EPS * max(1.0, np.max(np.abs(G)))
        for mu in (robot.mu, 1.0, 250.0):
            Ginv = robot.delassus_inverse(q, mu)
            assert np.array_equal(Ginv, Ginv.T)
            # As DelassusInverseInvertsTheDampedDelassus (tests/algorithms/
            # test_dynamics_library.cpp, docs/dynamics.md): Ginv = mu I - mu^2 Omega,
            # Omega = J M_mu^-1 J^T with |Omega| <= 1/mu; an error c nv eps kappa_s(M_mu)
            # |Omega| in Omega is c nv eps kappa_s(M_mu) mu in Ginv, and |A|_inf times that
            # in the residual, A = G + I/mu.
            A = G + np.eye(robot.nc) / mu
            err_ginv = C * robot.nv * EPS * scaled_condition(M + mu * J.T @ J) * mu
            residual = A @ Ginv - np.eye(robot.nc)
            assert np.max(np.abs(residual)) <= np.max(np.abs(A).sum(axis=1)) * err_ginv, mu


@pytest.mark.parametrize("name", SYSTEMS)
def test_inverse_dynamics_of_the_solution_is_the_torque(name, tmp_path, rng):
    robot, _, _ = load_system(name, tmp_path)
    pushed = 0  # states where the forces matter: the negative checks below ran
    for _ in range(3):
        q, v, tau = random_state(robot, rng, exact_quaternion=False)
        qdd, lam = robot.eval(q, v, tau, "pv", iterations=200)
        back = robot.inverse_dynamics(q, v, qdd, lam)
        # proxPV returns qdd = qdd_free - M^-1 J^T lam for the lam it returns, at every
        # iteration count, so M qdd + h + J^T lam = tau holds exactly in exact arithmetic.
        # Both sides are backward-stable (ABA is elimination on M, RNEA a sum of body
        # forces): c nv eps times the size of the terms summed, |M||qdd| + |h| +
        # |J^T||lam| + |tau| (as InverseDynamicsReturnsTauAtTheProxPvSolution).
        M = robot.mass_matrix(q)
        J = robot.constraint_jacobian(q)
        h = robot.nonlinear_effects(q, v)
        size = (np.max(np.abs(M) @ np.abs(qdd)) + np.max(np.abs(h)) + np.max(np.abs(tau))
                + (np.max(np.abs(J.T) @ np.abs(lam)) if robot.nc else 0.0))
        bound = C * robot.nv * EPS * max(1.0, size)
        assert np.max(np.abs(back - tau)) <= bound
        # The check can fail: dropping (or flipping) J^T lam is off by |J^T lam|, far
        # above the bound whenever the constraints push the joints at all.
        if robot.nc and np.max(np.abs(J.T @ lam)) > 1000 * bound:
            assert np.max(np.abs(robot.inverse_dynamics(q, v, qdd) - tau)) > 100 * bound
            assert np.max(np.abs(robot.inverse_dynamics(q, v, qdd, -lam) - tau)) > 100 * bound
            pushed += 1
    assert pushed > 0 or robot.nc == 0


def test_nonlinear_effects_is_inverse_dynamics_at_rest(quadruped, rng):
    q, v, _ = random_state(quadruped, rng)
    h = quadruped.nonlinear_effects(q, v)
    # Both are the library's rnea at qdd = 0 without constraint forces (rnea.hpp,
    # inverse_dynamics.cpp): the same operations, the same bits.
    assert np.array_equal(quadruped.inverse_dynamics(q, v, np.zeros(18)), h)
    assert np.max(np.abs(h)) > 1.0  # gravity on an 18-dof robot: h is not trivially zero


def test_bad_input_names_the_argument(quadruped):
    r = quadruped
    q, v = r.neutral, np.zeros(18)
    with pytest.raises(ValueError, match=r"^q: expected one state, shape \(nq,\) = \(19,\), got \(18,\)"):
        r.mass_matrix(np.zeros(18))
    with pytest.raises(ValueError, match=r"^q: expected one state.*got \(2, 19\)"):
        r.delassus(np.array([q, q]))
    with pytest.raises(ValueError, match=r"^v: expected one state, shape \(nv,\) = \(18,\)"):
        r.nonlinear_effects(q, np.zeros(19))
    with pytest.raises(ValueError, match=r"^qdd: expected one state"):
        r.inverse_dynamics(q, v, np.zeros(17))
    with pytest.raises(ValueError, match=r"^lam: expected one state, shape \(nc,\) = \(12,\), got \(13,\)"):
        r.inverse_dynamics(q, v, v, np.zeros(13))
    bad = v.copy()
    bad[4] = np.nan
    with pytest.raises(ValueError, match=r"^v\[4\] is not finite"):
        r.constraint_drift(q, bad)
    with pytest.raises(ValueError, match=r"^qdd\[4\] is not finite"):
        r.inverse_dynamics(q, v, bad)
    with pytest.raises(TypeError, match=r"^qdd: expected real numbers"):
        r.inverse_dynamics(q, v, ["a"] * 18)
    with pytest.raises(TypeError, match=r"^lam: expected real numbers"):
        r.inverse_dynamics(q, v, v, np.zeros(12, dtype=bool))
    with pytest.raises(TypeError, match=r"^q: expected real numbers .* got dtype object"):
        r.constraint_jacobian(object())
    zero = q.copy()
    zero[3:7] = 0
    with pytest.raises(ValueError, match=r"^q: the free-flyer quaternion .* has zero norm"):
        r.constraint_placements(zero)
    with pytest.raises(ValueError, match=r"^mu: the penalty must be > 0"):
        r.delassus_inverse(q, 0.0)
    with pytest.raises(ValueError, match=r"^mu: is not finite"):
        r.delassus_inverse(q, float("inf"))
    with pytest.raises(TypeError, match=r"^mu: expected a real number > 0"):
        r.delassus_inverse(q, "1")
    # Overflow inside the library is refused, not returned (as `eval --compute`).
    with pytest.raises(ValueError, match=r"^nonlinear_effects: is not finite at this state"):
        r.nonlinear_effects(q, np.full(18, 1e300))


def test_the_quaternion_is_normalised(quadruped):
    q = quadruped.neutral.copy()
    scaled = q.copy()
    scaled[3:7] *= 2.0  # [0 0 0 2]: normalised to exactly [0 0 0 1]
    for method in (quadruped.mass_matrix, quadruped.constraint_jacobian, quadruped.constraint_placements):
        assert np.array_equal(method(scaled), method(q))
