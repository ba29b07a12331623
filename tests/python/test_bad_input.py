"""Bad input is a Python exception naming the argument, never a crash, in the
package and in a generated module alike (docs/python.md, "Bad input")."""

import os

import numpy as np
import pytest

import proxgen
from conftest import QUADRUPED_DIR, module, random_state

URDF = os.path.join(QUADRUPED_DIR, "quadruped.urdf")
LAYOUT = os.path.join(QUADRUPED_DIR, "layout.yaml")


def solver(robot, which):
    """f(q, v, tau, **kw): the package's proxPV or the generated module's."""
    if which == "package":
        return lambda q, v, tau, **kw: robot.eval(q, v, tau, "pv", **kw)
    return module("quadruped").prox_pv


@pytest.fixture
def good(quadruped, rng):
    return random_state(quadruped, rng)


WHICH = pytest.mark.parametrize("which", ["package", "module"])


@WHICH
@pytest.mark.parametrize("arg,shape", [("q", (18,)), ("q", (19, 1)), ("v", (19,)), ("tau", (17,)), ("q", ()),
                                       ("q", (2, 3, 19)), ("q", (0, 19))])
def test_wrong_shape_is_a_value_error(quadruped, good, which, arg, shape):
    args = dict(zip(("q", "v", "tau"), good))
    args[arg] = np.ones(shape)
    with pytest.raises(ValueError, match=rf"^{arg}: expected shape \(n[qv],\) = \(1[89],\) or \(N, 1[89]\)"):
        solver(quadruped, which)(**args)


@WHICH
def test_batches_must_agree(quadruped, good, which):
    q, v, tau = good
    with pytest.raises(ValueError, match=r"^v: has shape \(18,\), but q has 2 states"):
        solver(quadruped, which)(np.array([q, q]), v, tau)
    with pytest.raises(ValueError, match=r"^tau: has shape \(3, 18\), but q has 2 states"):
        solver(quadruped, which)(np.array([q, q]), np.array([v, v]), np.array([tau] * 3))
    with pytest.raises(ValueError, match=r"^v: has shape \(1, 18\), but q is one state"):
        solver(quadruped, which)(q, v[None, :], tau)


@WHICH
@pytest.mark.parametrize("bad,expected", [(lambda x: x.astype(complex), "dtype complex128"),
                                          (lambda x: x > 0, "dtype bool"),
                                          (lambda x: x.astype(str), "dtype <U"),
                                          (lambda x: x.astype(object), "dtype object"),
                                          (lambda x: "not an array", "dtype <U"),
                                          (lambda x: None, "dtype object"),
                                          (lambda x: [[1.0, 2.0], [3.0]], "got list")])
def test_wrong_dtype_is_a_type_error(quadruped, good, which, bad, expected):
    q, v, tau = good
    with pytest.raises(TypeError, match=rf"^v: expected (real numbers|an array).*{expected}"):
        solver(quadruped, which)(q, bad(v), tau)


@WHICH
@pytest.mark.parametrize("arg", ["q", "v", "tau"])
@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_non_finite_is_a_value_error(quadruped, good, which, arg, value):
    args = dict(zip(("q", "v", "tau"), (x.copy() for x in good)))
    args[arg][5] = value
    with pytest.raises(ValueError, match=rf"^{arg}\[5\] is not finite"):
        solver(quadruped, which)(**args)
    batch = {k: np.array([x, x]) for k, x in dict(zip(("q", "v", "tau"), good)).items()}
    batch[arg][1, 4] = value
    with pytest.raises(ValueError, match=rf"^{arg}\[1, 4\] is not finite"):
        solver(quadruped, which)(**batch)


@WHICH
def test_zero_quaternion_is_a_value_error(quadruped, good, which):
    q, v, tau = good
    q = q.copy()
    q[3:7] = 0
    with pytest.raises(ValueError, match=r"^q: the free-flyer quaternion \[qx qy qz qw\] at q\[3:7\] has zero norm"):
        solver(quadruped, which)(q, v, tau)
    with pytest.raises(ValueError, match=r"^q\[1\]: the free-flyer quaternion"):
        solver(quadruped, which)(np.array([good[0], q]), np.array([v, v]), np.array([tau, tau]))


@WHICH
def test_other_layouts_of_the_same_numbers_are_accepted(quadruped, good, which):
    """Non-contiguous, Fortran-order, read-only, integer, float32 and list inputs are
    read (copied where needed), and give the answer of the float64 array they equal."""
    f = solver(quadruped, which)
    q, v, tau = good
    ref = f(q, v, tau)
    strided = np.zeros((19, 2))
    strided[:, 0] = q
    readonly = v.copy()
    readonly.flags.writeable = False
    out = f(strided[:, 0], readonly, list(tau))
    assert np.array_equal(out[0], ref[0]) and np.array_equal(out[1], ref[1])
    assert not readonly.flags.writeable and np.array_equal(strided[:, 0], q)  # inputs untouched
    fortran = np.asfortranarray(np.array([q, q]))
    many = f(fortran, np.array([v, v]), np.array([tau, tau]))
    assert np.array_equal(many[0][1], ref[0])
    ints = f(np.round(q).astype(np.int32) * 0 + quadruped.neutral.astype(np.int64), np.arange(18), np.zeros(18, np.uint8))
    assert np.array_equal(ints[0], f(quadruped.neutral, np.arange(18.0), np.zeros(18))[0])
    f32 = f(q.astype(np.float32), v, tau)
    assert np.array_equal(f32[0], f(q.astype(np.float32).astype(np.float64), v, tau)[0])


@WHICH
@pytest.mark.parametrize("kw,error,message", [
    ({"mu": 0.0}, ValueError, r"^mu: the penalty must be > 0"),
    ({"mu": -1}, ValueError, r"^mu: the penalty must be > 0"),
    ({"mu": float("nan")}, ValueError, r"^mu: is not finite"),
    ({"mu": float("inf")}, ValueError, r"^mu: is not finite"),
    ({"mu": "1e4"}, TypeError, r"^mu: expected a real number > 0, got str"),
    ({"mu": True}, TypeError, r"^mu: expected a real number > 0, got bool"),
    ({"mu": [1.0]}, TypeError, r"^mu: expected a real number > 0, got list"),
    ({"iterations": -1}, ValueError, r"^iterations: -1 is outside \[0, 1000000\]"),
    ({"iterations": 10**6 + 1}, ValueError, r"^iterations: 1000001 is outside"),
    ({"iterations": 2**70}, ValueError, r"^iterations: \d+ is outside"),
    ({"iterations": 1.5}, TypeError, r"^iterations: expected an integer in \[0, 1000000\], got float"),
    ({"iterations": 3.0}, TypeError, r"^iterations: expected an integer"),
    ({"iterations": "3"}, TypeError, r"^iterations: expected an integer"),
    ({"iterations": True}, TypeError, r"^iterations: expected an integer"),
])
def test_bad_settings(quadruped, good, which, kw, error, message):
    with pytest.raises(error, match=message):
        solver(quadruped, which)(*good, **kw)


@WHICH
def test_good_settings_types(quadruped, good, which):
    f = solver(quadruped, which)
    ref = f(*good, iterations=5, mu=300.0)
    assert np.array_equal(f(*good, iterations=np.int64(5), mu=np.float32(300.0))[0], ref[0])
    assert np.array_equal(f(*good, iterations=5, mu=300)[0], ref[0])


def test_unknown_algorithm(quadruped, good):
    with pytest.raises(ValueError, match=r"^algorithm: unknown algorithm 'PV' \(expected caba, pv, ltl, ltls or dense\)"):
        quadruped.eval(*good, algorithm="PV")
    with pytest.raises(TypeError, match=r"^algorithm: expected a str"):
        quadruped.eval(*good, algorithm=1)


def test_unknown_joint_names_in_a_state(quadruped):
    named = quadruped.named(q=quadruped.neutral, v=np.zeros(18))
    named["v"]["LF_KNEE"] = 1.0
    with pytest.raises(ValueError, match=r"^state: v\.'LF_KNEE': is not a joint of the model"):
        quadruped.state(named)
    del named["v"]["LF_KNEE"]
    del named["q"]["RH_KFE"]
    with pytest.raises(ValueError, match=r"^state: q\.'RH_KFE': missing"):
        quadruped.state(named)


@pytest.mark.parametrize("change,error,message", [
    (lambda s: s["q"].update(LF_HAA=float("nan")), ValueError, r"q\.'LF_HAA': is not finite"),
    (lambda s: s["q"].update(LF_HAA="0.1"), ValueError, r"q\.'LF_HAA': expected a number, got string"),
    (lambda s: s["q"].update(LF_HAA=True), ValueError, r"q\.'LF_HAA': expected a number, got boolean"),
    (lambda s: s["q"].update(root_joint=[0, 0, 0, 0, 0, 0, 0]), ValueError, r"quaternion .* has zero norm"),
    (lambda s: s["q"].update(root_joint=[0, 0, 0]), ValueError, r"q\.'root_joint': expected a list of 7 numbers"),
    (lambda s: s.update(qdd={}), ValueError, r"'qdd': unknown key \(expected q, v, tau\)"),
    (lambda s: s["v"].update({3: 1.0}), TypeError, r"keys must be str \(joint names\), got int"),
    (lambda s: s["v"].update(LF_HAA=object()), TypeError, r"state\.v\.LF_HAA: expected a dict, a list or a number"),
])
def test_bad_values_in_a_state(quadruped, change, error, message):
    named = quadruped.named(q=quadruped.neutral, v=np.zeros(18))
    change(named)
    with pytest.raises(error, match=message):
        quadruped.state(named)


def test_state_arguments(quadruped):
    with pytest.raises(TypeError, match=r"^state: expected a dict"):
        quadruped.state([1, 2])
    with pytest.raises(TypeError, match=r"^state: pass one dict or the keywords"):
        quadruped.state({}, q={})
    with pytest.raises(ValueError, match=r"^q: expected shape \(19,\)"):
        quadruped.named(q=np.zeros(18))
    with pytest.raises(TypeError, match=r"^lam: expected real numbers"):
        quadruped.named(lam=np.zeros(12, complex))


def test_library_errors_are_value_errors_with_the_cli_message(tmp_path):
    with pytest.raises(ValueError, match=r"missing\.urdf"):
        proxgen.load(str(tmp_path / "missing.urdf"), LAYOUT)
    with pytest.raises(ValueError, match=r"layout dict.*unknown key 'constraint'"):
        proxgen.load(URDF, {"base": "floating", "constraint": []})
    with pytest.raises(ValueError, match=r"layout dict.*'NO_SUCH_LINK'"):
        proxgen.load(URDF, {"base": "floating", "constraints": [{"name": "x", "link": "NO_SUCH_LINK", "type": "3d"}]})
    with pytest.raises(TypeError, match=r"^layout: the dict must hold only"):
        proxgen.load(URDF, {"mu": float("nan")})
    with pytest.raises(TypeError, match=r"^urdf: expected a path"):
        proxgen.load(3)
    bad = tmp_path / "bad.yaml"
    bad.write_text("base: floating\nconstraints:\n  - {name: a, link: LF_foot, type: 4d}\n")
    with pytest.raises(ValueError, match=r"bad\.yaml:3: .*unknown constraint type '4d'"):
        proxgen.load(URDF, str(bad))


def test_generate_bad_input_leaves_nothing(tmp_path):
    with pytest.raises(ValueError, match=r"^scalar: expected 'double' or 'float'"):
        proxgen.generate(URDF, LAYOUT, str(tmp_path / "a"), scalar="half")
    with pytest.raises(ValueError, match=r"missing\.yaml"):
        proxgen.generate(URDF, str(tmp_path / "missing.yaml"), str(tmp_path / "b"), python=True)
    with pytest.raises(ValueError, match=r"^generate: needs urdf and layout"):
        proxgen.generate(URDF, out=str(tmp_path / "c"))
    with pytest.raises(ValueError, match=r"^generate: cases and case go together"):
        proxgen.generate(URDF, LAYOUT, str(tmp_path / "d"), case="x")
    assert sorted(os.listdir(tmp_path)) == []
