"""The proxgen package against the `proxgen` binary: the same System, the same
generic solvers, the same files."""

import filecmp
import json
import os

import numpy as np
import pytest

import proxgen
from conftest import (CASES_FILE, QUADRUPED_DIR, random_state, rel_err, require_models, run_proxgen,
                      shared_case_names)

URDF = os.path.join(QUADRUPED_DIR, "quadruped.urdf")
LAYOUT = os.path.join(QUADRUPED_DIR, "layout.yaml")


def test_load_gives_the_slot_map_of_the_generated_header(quadruped):
    # generated/quadruped/quadruped.hpp's joint table: a free flyer at q[0..6] v[0..5],
    # then 12 revolute joints one slot each, LF, LH, RF, RH legs in tree order.
    r = quadruped
    assert (r.nq, r.nv, r.nc) == (19, 18, 12)
    assert r.joint_names[0] == "root_joint" and r.joints["root_joint"].type == "free_flyer"
    assert r.joints["root_joint"][3:7] == (0, 7, 0, 6)
    assert r.joint_names[1:4] == ("LF_HAA", "LF_HFE", "LF_KFE")
    assert r.joints["LH_HAA"].idx_q == 10 and r.joints["LH_HAA"].idx_v == 9
    assert r.constraint_names == ("lf_foot", "rf_foot", "lh_foot", "rh_foot")
    assert [(c.row, c.rows) for c in r.constraints.values()] == [(0, 3), (3, 3), (6, 3), (9, 3)]
    assert r.floating_base and r.mu == 1e4 and r.iterations == 3
    # Every slot is covered exactly once.
    assert sorted(k for j in r.joints.values() for k in range(j.idx_v, j.idx_v + j.nv)) == list(range(r.nv))
    assert sorted(k for j in r.joints.values() for k in range(j.idx_q, j.idx_q + j.nq)) == list(range(r.nq))


def test_a_layout_dict_is_the_layout_file(quadruped, rng):
    d = {"base": "floating", "gravity": [0, 0, -9.81], "mu": 1.0e4, "iterations": 3,
         "constraints": [{"name": n, "link": l, "type": "3d"} for n, l in
                         (("lf_foot", "LF_foot"), ("rf_foot", "RF_foot"), ("lh_foot", "LH_foot"), ("rh_foot", "RH_foot"))]}
    other = proxgen.load(URDF, d)
    q, v, tau = random_state(quadruped, rng)
    for algorithm in proxgen.ALGORITHMS:
        a, b = quadruped.eval(q, v, tau, algorithm), other.eval(q, v, tau, algorithm)
        # The same System from the same numbers: the same bits.
        assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


def test_no_layout_is_the_unconstrained_robot(rng):
    fixed = proxgen.load(URDF)
    assert (fixed.nq, fixed.nv, fixed.nc) == (12, 12, 0) and not fixed.floating_base
    floating = proxgen.load(URDF, floating_base=True)
    assert (floating.nq, floating.nv, floating.nc) == (19, 18, 0)
    q, v, tau = random_state(floating, rng)
    qdd, lam = floating.eval(q, v, tau, "caba")
    assert lam.shape == (0,) and qdd.shape == (18,)
    # Without constraints every algorithm is the plain ABA: the same answer to round-off
    # (1e-12 relative: the methods' orders of operations differ, the problem is the
    # unconstrained M qdd = tau - h with M well conditioned for this robot).
    for algorithm in ("pv", "ltl", "ltls", "dense"):
        assert rel_err(floating.eval(q, v, tau, algorithm)[0], qdd) < 1e-12


@pytest.mark.parametrize("case", shared_case_names() or ["(no models)"])
def test_eval_matches_the_cli_on_the_shared_cases(case, tmp_path, rng):
    require_models()
    import yaml
    with open(CASES_FILE) as f:
        entry = next(c for c in yaml.safe_load(f)["cases"] if c["name"] == case)
    layout = {k: v for k, v in entry.items() if k not in ("name", "model")}
    layout_path = tmp_path / "layout.yaml"
    layout_path.write_text(json.dumps(layout))
    urdf = proxgen.case_urdf(CASES_FILE, case)
    robot = proxgen.load_case(CASES_FILE, case)
    assert robot.nc == proxgen.load(urdf, str(layout_path)).nc
    states = [random_state(robot, rng) for _ in range(3)]
    state_path = tmp_path / "states.json"
    state_path.write_text(json.dumps([robot.named(q=q, v=v, tau=tau) for q, v, tau in states]))
    for algorithm in proxgen.ALGORITHMS:
        for options in ([], ["--iterations", "7", "--mu", "250"]):
            p = run_proxgen("eval", urdf, "--layout", str(layout_path), "--state", str(state_path),
                            "--algorithm", algorithm, *options)
            assert p.returncode == 0, p.stderr
            results = json.loads(p.stdout)
            kw = {"iterations": 7, "mu": 250} if options else {}
            for (q, v, tau), result in zip(states, results):
                qdd, lam = robot.eval(q, v, tau, algorithm, **kw)
                named = robot.named(qdd=qdd, lam=lam)
                # Bit for bit: the same library code on the same inputs (JSON carries
                # doubles exactly both ways; the quaternions have norm exactly 1, so
                # normalising them cannot differ either).
                assert named["qdd"] == result["qdd"], (algorithm, options)
                assert named["lam"] == result["lambda"], (algorithm, options)
                assert robot.residual(q, v, qdd) == result["residual"]
                assert result["iterations"] == kw.get("iterations", robot.iterations)


def test_many_states_are_the_single_states(quadruped, rng):
    states = [random_state(quadruped, rng, exact_quaternion=False) for _ in range(5)]
    Q, V, T = (np.array([s[k] for s in states]) for k in range(3))
    for algorithm in proxgen.ALGORITHMS:
        qdd, lam = quadruped.eval(Q, V, T, algorithm)
        assert qdd.shape == (5, 18) and lam.shape == (5, 12)
        for k, (q, v, tau) in enumerate(states):
            one = quadruped.eval(q, v, tau, algorithm)
            # The same calls in the same order on the same Data: identical.
            assert np.array_equal(qdd[k], one[0]) and np.array_equal(lam[k], one[1])


def test_state_and_named_are_inverses(quadruped, rng):
    q, v, tau = random_state(quadruped, rng)
    named = quadruped.named(q=q, v=v, tau=tau)
    assert named["q"]["root_joint"] == list(q[:7]) and named["q"]["LF_HAA"] == q[7]
    q2, v2, tau2 = quadruped.state(named)
    assert np.array_equal(q2, q) and np.array_equal(v2, v) and np.array_equal(tau2, tau)
    q3, v3, tau3 = quadruped.state(q=named["q"], v=named["v"])
    assert np.array_equal(q3, q) and np.array_equal(v3, v) and not tau3.any()  # missing tau: zeros


def test_state_normalises_the_quaternion_as_eval(quadruped):
    named = quadruped.named(q=quadruped.neutral, v=np.zeros(18))
    named["q"]["root_joint"][3:7] = [0, 0, 0, 2.0]
    q, _, _ = quadruped.state(named)
    assert list(q[3:7]) == [0, 0, 0, 1.0]


def test_generate_in_process_writes_the_cli_files(tmp_path):
    a, b = tmp_path / "lib", tmp_path / "cli"
    written = proxgen.generate(URDF, LAYOUT, str(a), name="quadruped", python=True)
    assert [os.path.basename(p) for p in written] == ["quadruped.hpp", "quadruped.cpp", "quadruped_c.h", "quadruped_c.cpp",
                                                      "quadruped_python.cpp"]
    p = run_proxgen("generate", URDF, "--layout", LAYOUT, "--out", str(b), "--name", "quadruped", "--python")
    assert p.returncode == 0, p.stderr
    for name in ("quadruped.hpp", "quadruped.cpp", "quadruped_c.h", "quadruped_c.cpp", "quadruped_python.cpp"):
        assert filecmp.cmp(a / name, b / name, shallow=False), name
    assert not (tmp_path / "plain").exists()
    assert len(proxgen.generate(URDF, LAYOUT, tmp_path / "plain")) == 4  # no python: the C++ and the C files


def test_generate_by_case(tmp_path):
    require_models()
    written = proxgen.generate(cases=CASES_FILE, case="iiwa_h3", out=str(tmp_path))
    assert [os.path.basename(p) for p in written] == ["iiwa_h3.hpp", "iiwa_h3.cpp", "iiwa_h3_c.h", "iiwa_h3_c.cpp"]


def test_verify_runs_the_cli(tmp_path):
    result = proxgen.verify(URDF, LAYOUT, samples=2, seed=3)
    assert result.ok, result.stderr
    bad = proxgen.verify(str(tmp_path / "missing.urdf"), LAYOUT)
    assert not bad.ok and bad.returncode == 1 and "missing.urdf" in bad.stderr
    with pytest.raises(ValueError, match="missing.urdf"):
        proxgen.verify(str(tmp_path / "missing.urdf"), LAYOUT, check=True)


def test_executable_honours_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("PROXGEN_EXECUTABLE", str(tmp_path / "elsewhere"))
    assert proxgen.executable() == str(tmp_path / "elsewhere")
    monkeypatch.delenv("PROXGEN_EXECUTABLE")
    assert os.access(proxgen.executable(), os.X_OK)
