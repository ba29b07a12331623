#!/usr/bin/env python3
"""The example quadruped (generated/quadruped/, a Mini Cheetah) standing on four
point contacts, simulated for two seconds at 1 kHz with its generated solver.

The feet are held to their places on the ground by the layout's constraints
(examples/python/quadruped_stand.yaml: Baumgarte gains kp, kd and a target per
foot), the joints by a PD controller around the stance; prox_pv gives the
accelerations and the contact multipliers of each step. Semi-implicit Euler:
v += dt qdd first, then q from the new v, the free flyer on its manifold (the
base position moves by dt R v_lin, in the world, and the quaternion by the
exponential map of dt w). Writes a PNG of the base height, the constraint drift
(how far the feet are from their targets) and the vertical contact forces.

Needs the module: cmake --build build --target pymod_quadruped_baumgarte, then
  PYTHONPATH=build/python:build/tests/python/modules/quadruped_baumgarte \\
      python3 examples/python/quadruped_stand.py --out stand.png
(docs/python.md). --write-layout recomputes the layout's targets.
"""

import argparse
import json
import os
import sys

import numpy as np

import proxgen

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
URDF = os.path.join(ROOT, "generated", "quadruped", "quadruped.urdf")
LAYOUT = os.path.join(HERE, "quadruped_stand.yaml")
FEET = (("lf_foot", "LF_foot"), ("rf_foot", "RF_foot"), ("lh_foot", "LH_foot"), ("rh_foot", "RH_foot"))

# Stance: hips level, thighs forward 0.8 rad, knees back 1.6 rad (feet under the hips).
STANCE = {"HAA": 0.0, "HFE": 0.8, "KFE": -1.6}
# Baumgarte gains: a critically damped foot error e'' + kd e' + kp e = 0 with
# omega = 50 rad/s (settling ~0.1 s, omega dt = 0.05 at 1 kHz: well inside
# semi-implicit Euler's stability limit omega dt < 2).
OMEGA = 50.0
KP, KD = OMEGA ** 2, 2 * OMEGA
# Joint PD (N m / rad, N m s / rad): holds the 6 DoF the contacts leave free.
JOINT_KP, JOINT_KD = 60.0, 2.0


def stance_q(robot, height):
    q = np.zeros(robot.nq)
    q[2] = height
    q[6] = 1.0  # identity quaternion [qx qy qz qw]
    for name, j in robot.joints.items():
        if j.type != "free_flyer":
            q[j.idx_q] = STANCE[name.split("_")[1]]
    return q


def foot_positions(robot, q):
    frames = robot.constraint_frames(q)
    return {name: frames[name][1] for name, _ in FEET}


def stance(robot):
    """The initial q (the lowest foot on z = 0) and the feet's places there."""
    feet = foot_positions(robot, stance_q(robot, 0.0))
    q0 = stance_q(robot, -min(p[2] for p in feet.values()))
    return q0, foot_positions(robot, q0)


def write_layout(path):
    free = proxgen.load(URDF, {"base": "floating", "constraints": [{"name": n, "link": l, "type": "3d"} for n, l in FEET]})
    q0, feet = stance(free)
    lines = ["# The example quadruped standing on four point feet, held to their places by",
             "# Baumgarte gains (critically damped, omega = 50 rad/s: kp = omega^2, kd = 2 omega).",
             "# The targets are the feet at the stance of examples/python/quadruped_stand.py",
             f"# (base at z = {q0[2]!r}); regenerate with: quadruped_stand.py --write-layout",
             "base: floating", "gravity: [0, 0, -9.81]", "mu: 1.0e4", "iterations: 3", "constraints:"]
    for name, link in FEET:
        p = feet[name]
        lines.append(f"  - {{name: {name}, link: {link}, type: 3d, kp: {KP!r}, kd: {KD!r},")
        lines.append(f"     target: {{xyz: [{p[0]!r}, {p[1]!r}, {p[2]!r}]}}}}")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def quaternion_multiply(a, b):
    """Hamilton product of [x y z w] quaternions."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return np.array([aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz])


def quaternion_exp(w):
    """exp of the rotation vector w as an [x y z w] quaternion."""
    angle = np.linalg.norm(w)
    if angle < 1e-12:
        return np.array([0.5 * w[0], 0.5 * w[1], 0.5 * w[2], 1.0]) / np.sqrt(1 + 0.25 * angle ** 2)
    axis = w / angle
    return np.concatenate([np.sin(angle / 2) * axis, [np.cos(angle / 2)]])


def rotation(quat):
    x, y, z, w = quat
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def integrate(q, v, dt):
    """q advanced by dt along v: the free flyer on SE(3)'s factors (position in the
    world by R v_lin, orientation by the exponential map of the body rate), the
    joints additively."""
    out = q.copy()
    R = rotation(q[3:7])
    out[0:3] = q[0:3] + dt * (R @ v[0:3])
    quat = quaternion_multiply(q[3:7], quaternion_exp(dt * v[3:6]))
    out[3:7] = quat / np.linalg.norm(quat)
    out[7:] = q[7:] + dt * v[6:]
    return out


def simulate(solver, robot, duration=2.0, dt=1e-3, push=True):
    """Runs the stand; returns the time series (t, base height, drift, forces, residual)."""
    q0, targets = stance(robot)
    q, v = q0.copy(), np.zeros(robot.nv)
    steps = int(round(duration / dt))
    log = {"t": [], "height": [], "drift": [], "force_z": [], "residual": [], "speed": []}
    for k in range(steps):
        t = k * dt
        tau = np.zeros(robot.nv)
        tau[6:] = JOINT_KP * (q0[7:] - q[7:]) - JOINT_KD * v[6:]
        if push and 0.5 <= t < 0.6:
            tau[6:] += 1.5 * np.sin(2 * np.pi * 10 * t)  # a 0.1 s wobble of every joint
        qdd, lam = solver.prox_pv(q, v, tau)
        frames = robot.constraint_frames(q, v)
        log["t"].append(t)
        log["height"].append(q[2])
        log["drift"].append(max(np.linalg.norm(frames[name][1] - targets[name]) for name, _ in FEET))
        # The force on the robot at foot C is -lambda in C's coordinates: -R_C lambda in the world.
        log["force_z"].append([-(frames[name][0] @ lam[c.row:c.row + 3])[2]
                               for name, c in ((n, robot.constraints[n]) for n, _ in FEET)])
        log["residual"].append(robot.residual(q, v, qdd))
        log["speed"].append(np.linalg.norm(v))
        v = v + dt * qdd
        q = integrate(q, v, dt)
    return {key: np.array(values) for key, values in log.items()}


def plot(log, path, mass):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    axes[0].plot(log["t"], log["height"])
    axes[0].set_ylabel("base height (m)")
    axes[1].semilogy(log["t"], np.maximum(log["drift"], 1e-16))
    axes[1].set_ylabel("max foot drift (m)")
    for k, (name, _) in enumerate(FEET):
        axes[2].plot(log["t"], log["force_z"][:, k], label=name)
    axes[2].plot(log["t"], log["force_z"].sum(axis=1), "k--", label="sum")
    axes[2].axhline(mass * 9.81, color="gray", lw=0.5, label="m g")
    axes[2].set_ylabel("vertical contact force (N)")
    axes[2].set_xlabel("time (s)")
    axes[2].legend(ncol=3, fontsize=8)
    axes[0].set_title("proxgen: example quadruped standing (prox_pv, 1 kHz, semi-implicit Euler)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def total_mass(urdf):
    import xml.etree.ElementTree as ET
    return sum(float(m.get("value")) for m in ET.parse(urdf).getroot().iter("mass"))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--duration", type=float, default=2.0, help="simulated seconds (default 2)")
    p.add_argument("--dt", type=float, default=1e-3, help="time step (default 1e-3 s)")
    p.add_argument("--out", default="quadruped_stand.png", help="PNG to write")
    p.add_argument("--summary", help="also write the run's figures as JSON here")
    p.add_argument("--no-push", action="store_true", help="no wobble at t = 0.5 s")
    p.add_argument("--write-layout", action="store_true", help="recompute quadruped_stand.yaml's targets and exit")
    args = p.parse_args(argv)
    if args.write_layout:
        write_layout(LAYOUT)
        print(f"wrote {LAYOUT}")
        return 0
    import quadruped_baumgarte as solver  # the generated module (PYTHONPATH: see above)
    robot = proxgen.load(URDF, LAYOUT)
    log = simulate(solver, robot, args.duration, args.dt, push=not args.no_push)
    mass = total_mass(URDF)
    plot(log, args.out, mass)
    summary = {"steps": len(log["t"]), "max_drift": float(log["drift"].max()),
               "final_drift": float(log["drift"][-1]), "max_residual": float(log["residual"].max()),
               "max_speed": float(log["speed"].max()),
               "min_height": float(log["height"].min()), "max_height": float(log["height"].max()),
               "final_force_sum": float(log["force_z"][-1].sum()), "weight": mass * 9.81}
    if args.summary:
        with open(args.summary, "w") as f:
            json.dump(summary, f, indent=2)
    print(json.dumps(summary, indent=2))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
