"""proxgen from Python: the generic solvers of a robot, and the code generator.

    robot = proxgen.load("robot.urdf", layout="layout.yaml")
    qdd, lam = robot.eval(q, v, tau, algorithm="pv")
    M, J = robot.mass_matrix(q), robot.constraint_jacobian(q)   # the dynamics library
    proxgen.generate("robot.urdf", "layout.yaml", "out", python=True)

See docs/python.md for the conventions and the bad-input policy.
"""

import json
import os
import shutil
import subprocess
from collections import namedtuple

from . import _proxgen
from ._proxgen import version as __version__  # noqa: F401

__all__ = ["load", "load_case", "case_names", "case_urdf", "generate", "verify", "executable", "Robot", "Joint", "ConstraintRows"]

Joint = namedtuple("Joint", "name type link idx_q nq idx_v nv limits")
ConstraintRows = namedtuple("ConstraintRows", "name type link row rows")

ALGORITHMS = ("caba", "pv", "ltl", "ltls", "dense")


def _path(value, argument):
    if isinstance(value, os.PathLike):
        value = os.fspath(value)
    if not isinstance(value, str):
        raise TypeError(f"{argument}: expected a path (str or os.PathLike), got {type(value).__name__}")
    return value


class Robot:
    """A robot and its constraint layout, with the generic solvers of the library.

    Attributes: name, nq, nv, nc, mu, iterations (the layout's defaults), floating_base,
    joint_names (tree order), constraint_names (layout order), joints and constraints
    (dicts by name: the slot map, Joint(idx_q, nq, idx_v, nv, ...) and
    ConstraintRows(row, rows, ...)), neutral (q at the neutral configuration).
    """

    def __init__(self, system):
        self._sys = system
        self.name = system.name
        self.nq, self.nv, self.nc = system.nq, system.nv, system.nc
        self.mu, self.iterations = system.mu, system.iterations
        self.floating_base = system.floating_base
        self.gravity = system.gravity
        self.warnings = tuple(system.warnings)
        joints = [Joint(j["name"], j["type"], j["link"], j["idx_q"], j["nq"], j["idx_v"], j["nv"], j.get("limits"))
                  for j in system.joints]
        rows = [ConstraintRows(c["name"], c["type"], c["link"], c["row"], c["rows"]) for c in system.constraints]
        self.joint_names = tuple(j.name for j in joints)
        self.constraint_names = tuple(c.name for c in rows)
        self.joints = {j.name: j for j in joints}
        self.constraints = {c.name: c for c in rows}
        self.neutral = system.neutral

    def __repr__(self):
        return f"<proxgen.Robot {self.name!r}: nq={self.nq} nv={self.nv} nc={self.nc}>"

    def eval(self, q, v, tau, algorithm="pv", iterations=None, mu=None):
        """(qdd, lam) of a generic solver, as `proxgen eval`: caba, pv, ltl, ltls or dense.

        q: (nq,) or (N, nq); v, tau: (nv,) or (N, nv). iterations and mu default to the
        layout's. The free-flyer quaternion is normalised (a zero norm is a ValueError).
        """
        return self._sys.eval(q, v, tau, algorithm, iterations, mu)

    def constraint_frames(self, q, v=None):
        """{name: (R, p, V)} for every constraint frame C at (q, v): its world placement
        (R 3x3, p 3) and its twist V (6: [linear; angular] in C's coordinates; zeros
        without v)."""
        import numpy as np
        return self._sys.constraint_frames(q, np.zeros(self.nv) if v is None else v)

    def residual(self, q, v, qdd):
        """||J qdd + gamma - aStar||: how far qdd is from meeting the constraint rows at
        (q, v), as the "residual" of `proxgen eval`."""
        return self._sys.residual(q, v, qdd)

    # The dynamics library (docs/dynamics.md), as `proxgen eval --compute`: one state per
    # call (q (nq,), v and qdd (nv,), lam (nc,)), new numpy arrays out, the quaternion
    # normalised, bad input a ValueError/TypeError naming the argument (docs/python.md).

    def inverse_dynamics(self, q, v, qdd, lam=None):
        """tau = M(q) qdd + h(q, v) + J(q)^T lam (nv,): the torques that give qdd while the
        constraints push with lam (nc, layout order; None: no constraint forces)."""
        return self._sys.inverse_dynamics(q, v, qdd, lam)

    def nonlinear_effects(self, q, v):
        """h(q, v) (nv,): Coriolis, centrifugal and gravity torques (tau at qdd = 0)."""
        return self._sys.nonlinear_effects(q, v)

    def mass_matrix(self, q):
        """M(q) (nv, nv): the joint-space inertia matrix (CRBA)."""
        return self._sys.mass_matrix(q)

    def mass_matrix_inverse(self, q):
        """M(q)^-1 (nv, nv), by the O(n^2) ABA-based recursion, exactly symmetric."""
        return self._sys.mass_matrix_inverse(q)

    def constraint_placements(self, q):
        """(nconstraints, 4, 4): each constraint frame's world placement [R p; 0 0 0 1],
        layout order (the rotation and position `eval --compute placements` prints)."""
        return self._sys.constraint_placements(q)

    def constraint_jacobian(self, q):
        """J(q) (nc, nv): the constraint rows in each constraint's own frame, layout order
        (6d: [linear; angular], 3d: linear), as the solvers hold them."""
        return self._sys.constraint_jacobian(q)

    def constraint_drift(self, q, v):
        """gamma(q, v) (nc,): J qdd + gamma is the constraint rows' acceleration."""
        return self._sys.constraint_drift(q, v)

    def delassus(self, q):
        """G = J M^-1 J^T (nc, nc), layout order."""
        return self._sys.delassus(q)

    def delassus_inverse(self, q, mu=None):
        """(G + I/mu)^-1 (nc, nc) for mu > 0 (default: the layout's mu), by the Woodbury
        identity on the penalised recursion (absolute round-off about eps mu)."""
        return self._sys.delassus_inverse(q, mu)

    def state(self, state=None, *, q=None, v=None, tau=None):
        """(q, v, tau) arrays from values keyed by joint name.

        Either one dict {"q": {...}, "v": {...}, "tau": {...}} (the state format of
        `proxgen eval --state`) or the keyword arguments q=, v=, tau=. Every joint must
        appear in q and v; a joint missing from tau gets 0; a free flyer takes a list of 7
        (x y z qx qy qz qw) in q and of 6 in v and tau.
        """
        if state is None:
            state = {"q": q, "v": v}
            if tau is not None:
                state["tau"] = tau
        elif q is not None or v is not None or tau is not None:
            raise TypeError("state: pass one dict or the keywords q=, v=, tau=, not both")
        return self._sys.state(state)

    def named(self, q=None, v=None, tau=None, qdd=None, lam=None):
        """The inverse of state(): each given array as a dict keyed by joint name (q, v,
        tau, qdd) or constraint name (lam, always lists of rows), in one dict keyed by
        the argument names. A single value for one-slot joints, a list otherwise."""
        out = {}
        for key, x, width in (("q", q, self.nq), ("v", v, self.nv), ("tau", tau, self.nv), ("qdd", qdd, self.nv),
                              ("lam", lam, self.nc)):
            if x is None:
                continue
            values = _vector(x, width, key)
            if key == "lam":
                out[key] = {c.name: values[c.row:c.row + c.rows] for c in self.constraints.values()}
                continue
            at, n = ("idx_q", "nq") if key == "q" else ("idx_v", "nv")
            d = {}
            for j in self.joints.values():
                start, size = getattr(j, at), getattr(j, n)
                d[j.name] = values[start] if size == 1 else values[start:start + size]
            out[key] = d
        return out


def _vector(x, width, argument):
    import numpy as np
    try:
        a = np.asarray(x)
    except Exception as e:  # ragged lists and the like
        raise TypeError(f"{argument}: expected an array of {width} real numbers ({e})") from None
    if a.dtype.kind not in "fiu":
        raise TypeError(f"{argument}: expected real numbers (a float or integer dtype), got dtype {a.dtype}")
    if a.shape != (width,):
        raise ValueError(f"{argument}: expected shape ({width},), got {a.shape}")
    return [float(e) for e in a]


def load(urdf, layout=None, *, floating_base=False):
    """A Robot from a URDF and a layout: a YAML file path, a dict with the layout's keys
    (base, gravity, mu, iterations, constraints), or None (no constraints; the base is
    fixed unless floating_base=True)."""
    urdf = _path(urdf, "urdf")
    if layout is None:
        return Robot(_proxgen.load_without_layout(urdf, bool(floating_base)))
    if floating_base:
        raise ValueError("floating_base: only without a layout (a layout says `base: floating`)")
    if isinstance(layout, dict):
        try:
            text = json.dumps(layout, allow_nan=False)  # JSON is YAML: the library's parser reads it
        except (TypeError, ValueError) as e:
            raise TypeError(f"layout: the dict must hold only str keys, numbers, lists and dicts ({e})") from None
        return Robot(_proxgen.load_layout_text(urdf, text, "<layout dict>"))
    return Robot(_proxgen.load(urdf, _path(layout, "layout")))


def load_case(cases, name):
    """The Robot of one case of a cases file (cases.yaml: a list of layouts with name and model)."""
    return Robot(_proxgen.load_case(_path(cases, "cases"), name))


def case_names(cases):
    """The names of the cases of a cases file, in file order."""
    return _proxgen.case_names(_path(cases, "cases"))


def case_urdf(cases, name):
    """The URDF path of one case (resolved relative to the cases file)."""
    return _proxgen.case_urdf(_path(cases, "cases"), name)


def generate(urdf=None, layout=None, out=None, name=None, scalar="double", python=False, *, cases=None, case=None):
    """`proxgen generate` in process: writes NAME.hpp, NAME.cpp (and NAME_python.cpp with
    python=True) into `out`; returns the paths written. Either urdf and layout (files) or
    cases and case. Bad input raises ValueError with the CLI's message."""
    if out is None:
        raise TypeError("out: the output folder is required")
    by_case = cases is not None or case is not None
    if by_case and (cases is None or case is None or urdf is not None or layout is not None):
        raise ValueError("generate: cases and case go together, without urdf or layout")
    if not by_case and (urdf is None or layout is None):
        raise ValueError("generate: needs urdf and layout (or cases and case)")
    if scalar not in ("double", "float"):
        raise ValueError(f"scalar: expected 'double' or 'float', got {scalar!r}")
    if name is not None and not isinstance(name, str):
        raise TypeError(f"name: expected a str, got {type(name).__name__}")
    return _proxgen.generate(_path(urdf, "urdf") if urdf is not None else "",
                             _path(layout, "layout") if layout is not None else "",
                             _path(cases, "cases") if cases is not None else "",
                             case if case is not None else "", _path(out, "out"), name or "", scalar, bool(python))


def executable():
    """The `proxgen` command verify() runs: $PROXGEN_EXECUTABLE, else the one this package
    was built or installed with, else `proxgen` on PATH. Raises FileNotFoundError if none."""
    env = os.environ.get("PROXGEN_EXECUTABLE")
    if env:
        return env
    try:
        from . import _paths
        candidate = _paths.executable()
        if candidate and os.access(candidate, os.X_OK):
            return candidate
    except ImportError:
        pass
    found = shutil.which("proxgen")
    if found:
        return found
    raise FileNotFoundError("proxgen: no `proxgen` executable (set PROXGEN_EXECUTABLE or put it on PATH)")


VerifyResult = namedtuple("VerifyResult", "ok returncode stdout stderr")


def verify(urdf=None, layout=None, *, cases=None, case=None, samples=None, scalar=None, tolerance=None, seed=None,
           keep=None, check=False):
    """`proxgen verify` (generate, compile and compare with the generic solvers), run as a
    subprocess of executable(). Returns VerifyResult(ok, returncode, stdout, stderr);
    with check=True a failure raises ValueError with the command's error output."""
    args = [executable(), "verify"]
    if urdf is not None:
        args.append(_path(urdf, "urdf"))
    for flag, value in (("--layout", layout), ("--cases", cases), ("--keep", keep)):
        if value is not None:
            args += [flag, _path(value, flag[2:])]
    for flag, value in (("--case", case), ("--samples", samples), ("--scalar", scalar), ("--tolerance", tolerance),
                        ("--seed", seed)):
        if value is not None:
            if isinstance(value, bool) or not isinstance(value, (str, int, float)):
                raise TypeError(f"{flag[2:]}: expected a str or a number, got {type(value).__name__}")
            args += [flag, str(value)]
    p = subprocess.run(args, capture_output=True, text=True)
    result = VerifyResult(p.returncode == 0, p.returncode, p.stdout, p.stderr)
    if check and not result.ok:
        raise ValueError(p.stderr.strip() or f"proxgen verify exited with {p.returncode}")
    return result
