"""The library functions and the solvers' run-time options in a generated module: the
quadruped generated with FUNCTIONS all (module quadruped_all) against the package's
generic twins, its many-state path against its single-state path, the schedule
(active=) and the warm start (lambda0=), and a module that holds the mass matrix alone."""

import numpy as np
import pytest

from conftest import C, EPS, module, random_state, rel_err, scaled_condition

LIBRARY = ("inverse_dynamics", "nonlinear_effects", "mass_matrix", "mass_matrix_inverse", "constraint_placements",
           "constraint_jacobian", "constraint_drift", "delassus", "delassus_inverse", "constraint_wrenches",
           "inverse_dynamics_derivatives", "forward_dynamics_derivatives", "constrained_dynamics_derivatives")


@pytest.fixture
def m():
    return module("quadruped_all")


def test_the_module_holds_what_the_solver_holds(m):
    assert m.functions == ("constrained_aba", "prox_pv") + LIBRARY
    mass = module("quadruped_mass")
    assert mass.functions == ("mass_matrix",)
    assert not hasattr(mass, "prox_pv") and not hasattr(mass, "inverse_dynamics")
    # The binding is the same compiled function over the same input: the same bits.
    q = np.zeros(mass.nq)
    q[6] = 1.0
    assert np.array_equal(mass.mass_matrix(q), m.mass_matrix(q))


def test_every_function_is_its_generic_twin(m, quadruped, rng):
    for _ in range(5):
        q, v, tau = random_state(quadruped, rng, exact_quaternion=False)
        qdd, lam = quadruped.eval(q, v, tau, "pv", iterations=20)
        M = quadruped.mass_matrix(q)
        J = quadruped.constraint_jacobian(q)
        # The recursions without a solve (RNEA, CRBA, the kinematics, the products of
        # the Delassus recursion): the generated code sums the same products in another
        # order, off by c nv eps times the size of the terms summed (the bounds of
        # generator/verify/compare.cpp). Those sizes are |M||qdd| + |J^T||lam| + |h| for
        # the torques (at most ~1e3 here: a 25 kg robot's gravity and unit-scale
        # accelerations), O(1) for placements and rows: 1e3 * C nv eps = 4e-11.
        torque_size = np.max(np.abs(M) @ np.abs(qdd) + np.abs(J.T) @ np.abs(lam)) + np.max(np.abs(tau)) + 1e2
        sums = C * quadruped.nv * EPS * max(1.0, torque_size)
        assert rel_err(m.inverse_dynamics(q, v, qdd, lam), quadruped.inverse_dynamics(q, v, qdd, lam)) <= sums
        assert rel_err(m.nonlinear_effects(q, v), quadruped.nonlinear_effects(q, v)) <= sums
        assert rel_err(m.mass_matrix(q), M) <= sums
        assert rel_err(m.constraint_placements(q), quadruped.constraint_placements(q)) <= sums
        assert rel_err(m.constraint_jacobian(q), J) <= sums
        assert rel_err(m.constraint_drift(q, v), quadruped.constraint_drift(q, v)) <= sums
        assert rel_err(m.delassus(q), quadruped.delassus(q)) <= sums
        # The solves: c nv eps kappa_s(M) for M^-1 (relative to its largest entry), and
        # for (G + I/mu)^-1 = mu I - mu^2 J M_mu^-1 J^T the absolute c nv eps
        # kappa_s(M_mu) mu of test_dynamics.py's test_the_inverses_are_inverses.
        Minv = quadruped.mass_matrix_inverse(q)
        assert rel_err(m.mass_matrix_inverse(q), Minv) <= C * quadruped.nv * EPS * scaled_condition(M)
        for mu in (quadruped.mu, 1.0):
            ginv = C * quadruped.nv * EPS * scaled_condition(M + mu * J.T @ J) * mu
            assert np.max(np.abs(m.delassus_inverse(q, mu) - quadruped.delassus_inverse(q, mu))) <= ginv
        # The wrenches of the package's lam: -R lam_point per foot, no torque about the
        # frame's origin (a 3d point), R the frame's rotation (docs/dynamics.md).
        W = m.constraint_wrenches(q, lam)
        X = quadruped.constraint_placements(q)
        for k, name in enumerate(quadruped.constraint_names):
            row = quadruped.constraints[name].row
            assert rel_err(W[k, :3], -X[k, :3, :3] @ lam[row:row + 3]) <= sums
            assert np.array_equal(W[k, 3:], np.zeros(3))


def test_many_states_are_the_single_states(m, quadruped, rng):
    states = [random_state(quadruped, rng, exact_quaternion=False) for _ in range(5)]
    Q, V, T = (np.array([s[k] for s in states]) for k in range(3))
    lam = np.array([m.prox_pv(*s)[1] for s in states])
    calls = {
        "inverse_dynamics": lambda k: (Q[k], V[k], T[k], lam[k]),
        "nonlinear_effects": lambda k: (Q[k], V[k]),
        "constraint_drift": lambda k: (Q[k], V[k]),
        "constraint_wrenches": lambda k: (Q[k], lam[k]),
        "inverse_dynamics_derivatives": lambda k: (Q[k], V[k], T[k], lam[k]),
        "forward_dynamics_derivatives": lambda k: (Q[k], V[k], T[k]),
        "constrained_dynamics_derivatives": lambda k: (Q[k], V[k], T[k]),
    }
    for name in LIBRARY:
        args = calls.get(name, lambda k: (Q[k],))
        many = getattr(m, name)(*(np.array([args(k)[i] for k in range(5)]) for i in range(len(args(0)))))
        for k in range(5):
            one = getattr(m, name)(*args(k))
            # The derivatives return several arrays: each is compared alike.
            for many_part, one_part in (zip(many, one) if isinstance(one, tuple) else [(many, one)]):
                assert many_part.shape == (5,) + one_part.shape, name
                # The same compiled function on the same inputs (the workspace reused):
                # identical bits, or a leftover from the previous state shows.
                assert np.array_equal(many_part[k], one_part), name


def test_the_derivatives_are_derivatives(m, quadruped, rng):
    nv = quadruped.nv
    for _ in range(3):
        q, v, tau = random_state(quadruped, rng, exact_quaternion=False)
        qdd, lam = m.prox_pv(q, v, tau)
        dq, dv = m.inverse_dynamics_derivatives(q, v, qdd, lam)
        size = np.max(np.abs(m.inverse_dynamics(q, v, qdd, lam))) + 1e2  # the torques' terms, as above
        # tau is quadratic in v: its central difference is exact for any step, up to
        # the round-off of the two evaluations, c nv eps size / h (times 10 for the
        # terms of both calls and the difference).
        h = 0.5
        roundoff = 10 * C * nv * EPS * size / h
        for k in range(nv):
            e = np.zeros(nv)
            e[k] = h
            fd = (m.inverse_dynamics(q, v + e, qdd, lam) - m.inverse_dynamics(q, v - e, qdd, lam)) / (2 * h)
            assert np.max(np.abs(dv[:, k] - fd)) <= roundoff, k
        # The joint angles (velocity slot k >= 6 is configuration slot k + 1, after the
        # quaternion; q (+) dq is q + dq there): central differences at h, whose
        # truncation (h^2 times the third derivative over 6) is measured as
        # |D(2h) - D(h)| / 3 (D(2h) carries four times D(h)'s); a margin of 3 on it,
        # plus the round-off at this step.
        def D(step, k):
            e = np.zeros(quadruped.nq)
            e[k + 1] = step
            return (m.inverse_dynamics(q + e, v, qdd, lam) - m.inverse_dynamics(q - e, v, qdd, lam)) / (2 * step)
        h = 1e-4
        for k in range(6, nv):
            d1, d2 = D(h, k), D(2 * h, k)
            bound = np.max(np.abs(d2 - d1)) + 10 * C * nv * EPS * size / h
            assert np.max(np.abs(dq[:, k] - d1)) <= bound, k
        # The free motion: dqdd/dtau is M^-1 written by the same generated function (the
        # same bits); qdd solves M qdd + h = tau (c nv eps kappa_s(M) |M^-1| |tau - h|);
        # dqdd_dq = -M^-1 dtau_dq at that qdd, numpy's product of the same factors off
        # by c nv eps times |M^-1| |dtau_dq| (the order of the sums).
        fqdd, fdq, fdv, fdtau = m.forward_dynamics_derivatives(q, v, tau)
        Minv = m.mass_matrix_inverse(q)
        assert np.array_equal(fdtau, Minv)
        M, hv = m.mass_matrix(q), m.nonlinear_effects(q, v)
        assert rel_err(fqdd, np.linalg.solve(M, tau - hv)) <= (
            C * nv * EPS * scaled_condition(M) * np.max(np.abs(Minv)) * max(1.0, np.max(np.abs(tau - hv))))
        tq, tv = m.inverse_dynamics_derivatives(q, v, fqdd)
        for got, t in ((fdq, tq), (fdv, tv)):
            assert np.max(np.abs(got + Minv @ t)) <= C * nv * EPS * np.max(np.abs(Minv) @ np.abs(t))


def test_an_inactive_constraint_exerts_no_force(m, quadruped, rng):
    q, v, tau = random_state(quadruped, rng, exact_quaternion=False)
    active = [True, False, True, True]
    rows = slice(quadruped.constraints[quadruped.constraint_names[1]].row,
                 quadruped.constraints[quadruped.constraint_names[1]].row + 3)
    for solve in (m.prox_pv, m.constrained_aba):
        _, lam_all = solve(q, v, tau)
        qdd, lam = solve(q, v, tau, active=active)
        # The schedule's promise (docs/algorithms.md, section 4.4): exactly zero, not small.
        assert np.array_equal(lam[rows], np.zeros(3))
        assert np.max(np.abs(lam_all[rows])) > 1e-3  # the foot pushes when it is active
    J = m.constraint_jacobian(q, active=np.array(active))
    assert np.array_equal(J[rows], np.zeros_like(J[rows]))
    assert np.array_equal(np.delete(J, np.arange(rows.start, rows.stop), axis=0),
                          np.delete(m.constraint_jacobian(q), np.arange(rows.start, rows.stop), axis=0))
    # inverse_dynamics does not read the inactive rows: as if their lam were 0.
    lam_zeroed = lam_all.copy()
    lam_zeroed[rows] = 0.0
    assert np.array_equal(m.inverse_dynamics(q, v, qdd, lam_all, active=active), m.inverse_dynamics(q, v, qdd, lam_zeroed))


def test_the_warm_start_continues_the_iteration(m, quadruped, rng):
    q, v, tau = random_state(quadruped, rng, exact_quaternion=False)
    # mu = 1 makes each update count (the iteration contracts by about 1/(1 + mu g)):
    # one update from the K-th iterate is iterate K + 1, in the same operations up to
    # the order of the first update's sums (the K-step solve starts from an exact 0);
    # 1e-10 relative is cond * eps with cond ~ 1e6, far below the gap between
    # iterates that the second assertion demands.
    _, lam3 = m.prox_pv(q, v, tau, mu=1.0, iterations=3)
    qdd4, lam4 = m.prox_pv(q, v, tau, mu=1.0, iterations=4)
    qdd_warm, lam_warm = m.prox_pv(q, v, tau, mu=1.0, iterations=1, lambda0=lam3)
    assert rel_err(lam_warm, lam4) < 1e-10 and rel_err(qdd_warm, qdd4) < 1e-10
    _, lam_cold = m.prox_pv(q, v, tau, mu=1.0, iterations=1)
    assert rel_err(lam_cold, lam4) > 1e-6


def test_bad_options_name_the_argument(m):
    q = np.zeros(m.nq)
    q[6] = 1.0
    v = np.zeros(m.nv)
    with pytest.raises(ValueError, match="active: expected one flag per constraint, shape \\(4,\\)"):
        m.prox_pv(q, v, v, active=[True, False])
    with pytest.raises(ValueError, match=r"active\[1\]: expected a bool or 0/1, got 2"):
        m.constraint_jacobian(q, active=[1, 2, 1, 1])
    with pytest.raises(TypeError, match="active: expected bools or 0/1"):
        m.delassus(q, active=[0.5, 1.0, 1.0, 1.0])
    with pytest.raises(ValueError, match=r"lambda0: expected shape \(nc,\) = \(12,\)"):
        m.prox_pv(q, v, v, lambda0=np.zeros(3))
    with pytest.raises(ValueError, match=r"lambda0\[2\] is not finite"):
        m.constrained_aba(q, v, v, lambda0=np.array([0, 0, np.nan] + [0] * 9))
    with pytest.raises(ValueError, match="lam: expected shape"):
        m.constraint_wrenches(q, np.zeros(2))
    with pytest.raises(ValueError, match="has zero norm"):
        m.mass_matrix(np.zeros(m.nq))


def solve_roundoff(m, q, lam):
    """What one prox_pv solve is off by: C n eps kappa(M) kappa(G + I/mu) times the size of
    its answer (n = nv + nc)."""
    M, J = m.mass_matrix(q), m.constraint_jacobian(q)
    G = J @ np.linalg.solve(M, J.T) + np.eye(m.nc) / m.mu
    return C * (m.nv + m.nc) * EPS * scaled_condition(M) * scaled_condition(G) * max(1.0, np.max(np.abs(lam)))


def test_constrained_dynamics_derivatives_along_v_and_tau_are_the_solve_s(m, quadruped, rng):
    """Along v and tau, G does not move, so the tangents' K proximal steps are exactly the
    derivative of prox_pv's K steps: central differences of m.prox_pv check them with no
    truncation error (the K-step solution is linear in tau and quadratic in v)."""
    nv, nc = m.nv, m.nc
    for _ in range(3):
        q, v, tau = random_state(quadruped, rng, exact_quaternion=False)
        qdd, lam, dq, dv, dtau, lq, lv, ltau = m.constrained_dynamics_derivatives(q, v, tau)
        assert dq.shape == (nv, nv) and lq.shape == (nc, nv)
        # The same prox_pv call inside: the same bits.
        qdd0, lam0 = m.prox_pv(q, v, tau)
        assert np.array_equal(qdd, qdd0) and np.array_equal(lam, lam0)
        # A central difference of two solves is off by solve_roundoff / h.
        delta = solve_roundoff(m, q, lam)
        h = 1e-2
        for k in range(nv):
            e = np.zeros(nv)
            e[k] = h
            for x, got_qdd, got_lam in ((0, dv, lv), (1, dtau, ltau)):
                plus = m.prox_pv(q, v + e, tau) if x == 0 else m.prox_pv(q, v, tau + e)
                minus = m.prox_pv(q, v - e, tau) if x == 0 else m.prox_pv(q, v, tau - e)
                assert np.max(np.abs(got_qdd[:, k] - (plus[0] - minus[0]) / (2 * h))) <= delta / h, (x, k)
                assert np.max(np.abs(got_lam[:, k] - (plus[1] - minus[1]) / (2 * h))) <= delta / h, (x, k)


def test_constrained_dynamics_derivatives_follow_the_schedule(m, quadruped, rng):
    """An inactive constraint counts as absent: its multiplier rows and their tangents are
    exactly zero, and the others are the derivatives of prox_pv with that schedule (checked
    along tau, where central differences of the K-step solve are exact, as above)."""
    nv, nc = m.nv, m.nc
    active = [True, False, True, True]
    name = quadruped.constraint_names[1]
    rows = slice(quadruped.constraints[name].row, quadruped.constraints[name].row + 3)
    q, v, tau = random_state(quadruped, rng, exact_quaternion=False)
    qdd, lam, dq, dv, dtau, lq, lv, ltau = m.constrained_dynamics_derivatives(q, v, tau, active=active)
    qdd0, lam0 = m.prox_pv(q, v, tau, active=active)
    assert np.array_equal(qdd, qdd0) and np.array_equal(lam, lam0)
    for L in (lq, lv, ltau):
        assert np.array_equal(L[rows], np.zeros((3, nv)))
    delta = solve_roundoff(m, q, lam)
    h = 1e-2
    for k in range(nv):
        e = np.zeros(nv)
        e[k] = h
        plus, minus = m.prox_pv(q, v, tau + e, active=active), m.prox_pv(q, v, tau - e, active=active)
        assert np.max(np.abs(dtau[:, k] - (plus[0] - minus[0]) / (2 * h))) <= delta / h, k
        assert np.max(np.abs(ltau[:, k] - (plus[1] - minus[1]) / (2 * h))) <= delta / h, k
    # The schedule changes the answer: with every foot the tangents differ.
    assert np.max(np.abs(m.constrained_dynamics_derivatives(q, v, tau)[4] - dtau)) > 1e-6
