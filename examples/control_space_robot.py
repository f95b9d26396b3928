"""The space robot's index fingertip moved to a point while the satellite floats (docs/control.md).

    PYTHONPATH=build/python /usr/bin/python3 examples/control_space_robot.py [--t-end 3]
        [--plot space_robot_control.png]

Nothing holds the satellite: the joint torques are internal, so the momentum stays zero and every
motion of the arm turns and shifts the satellite. Umetani and Yoshida's generalized Jacobian J*
(model.generalized_jacobian) maps the arm's rates alone to the tip's velocity with the base
floating (docs/notation.md#momentum), ẋ = J* v_m. The controller (resolved rates on J*):

    v_arm,d = J*_arm⁺ K (x_d − x)              damped least squares on the arm's 7 columns of J*
    a_arm   = K_v (v_arm,d − v_arm),   a_fingers = K_p (q_f0 − q_f) − K_d v_f   (held still)

and the torques that give those accelerations to the arm and the fingers with the base free:
the base's six rows of M^s v̇ + h = Q + τ carry no torque (τ_b = 0), so

    v̇_b = M_bb⁻¹ (Q_b − h_b − M_bm a_m),     τ_m = M_mb v̇_b + M_mm a_m + h_m − Q_m.

With ė = −K e the tip converges exponentially, the satellite turning under it. The target is
fixed in inertial space. Prints the distance to the target and the satellite's rotation; writes a
plot of both.
"""
import argparse
import pathlib

import numpy as np

import femdyn

ROOT = pathlib.Path(__file__).resolve().parents[1]
FRAME = "index_tip"
ARM = [f"joint{k}" for k in range(1, 8)]


def controller_for(model, x_d, q_fingers, k=4.0, k_v=40.0, k_p=400.0, k_d=40.0, damping=1e-3):
    names = model.coordinates
    arm = np.array([names.index(a) for a in ARM])
    fingers = np.array([i for i in range(6, model.n) if names[i] not in ARM])
    configuration = model.configuration
    finger_q = np.array([configuration.index(names[i]) for i in fingers])

    def controller(t, q, v):
        g = model.generalized_jacobian(FRAME, q, v)
        x = model.frame_kinematics(FRAME, q)["p"]
        # J*'s columns are v's entries 6 … n − 1; the arm's are joint1 … joint7.
        J_arm = g["J"][:3, arm - 6]
        e = x_d - x
        v_arm = J_arm.T @ np.linalg.solve(J_arm @ J_arm.T + damping * np.eye(3), k * e)
        a = np.zeros(model.n)
        a[arm] = k_v * (v_arm - v[arm])
        a[fingers] = k_p * (q_fingers - q[finger_q]) - k_d * v[fingers]
        eq = model.equations(q, v)  # M^s, h, Q at τ = 0
        M, rhs = eq.M, eq.Q - eq.h
        m = np.arange(6, model.n)
        vdot_b = np.linalg.solve(M[:6, :6], rhs[:6] - M[:6, m] @ a[m])
        tau = np.zeros(model.n)
        tau[m] = M[m, :6] @ vdot_b + M[np.ix_(m, m)] @ a[m] - rhs[m]
        return tau
    return controller


def rotation_angle(q):
    """The satellite's rotation from its start (its quaternion q[3:7], w first), rad."""
    return 2 * np.arccos(np.clip(np.abs(q[3]), 0, 1))


def run(t_end=3.0, dt=1e-3, mode="hold", k=4.0):
    """The run: dict t, error (m), satellite angle (rad), momentum (6,) rows, target, run."""
    model = femdyn.load(str(ROOT / "models" / "space_robot.json"))
    q0 = model.neutral_configuration()
    names = model.configuration
    bent = {"joint2": 0.6, "joint4": -1.2, "joint6": 0.7}
    for name, value in bent.items():
        q0[names.index(name)] = value
    # The target: 10 cm from where the tip starts, in inertial space.
    x0 = model.frame_kinematics(FRAME, q0)["p"]
    x_d = x0 + np.array([0.06, -0.05, -0.06])
    finger_q = [i for i, name in enumerate(names) if i >= 7 and name not in ARM]
    sim = femdyn.Simulator(model, integrator="rk4", dt=dt, q0=q0)
    result = sim.run(controller_for(model, x_d, q0[finger_q], k=k), t_end, mode=mode)
    q = result["q"]
    error = np.array([np.linalg.norm(model.frame_kinematics(FRAME, qi)["p"] - x_d) for qi in q])
    momentum = np.array([model.centroidal(qi, vi)["momentum"]
                         for qi, vi in zip(q, result["qd"])])
    return {"t": result["t"], "error": error, "angle": np.array([rotation_angle(qi) for qi in q]),
            "momentum": momentum, "target": x_d, "run": result}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--t-end", type=float, default=3.0)
    parser.add_argument("--plot", default="space_robot_control.png")
    args = parser.parse_args()
    r = run(args.t_end)
    t, e, angle = r["t"], r["error"], r["angle"]
    for when in (0.0, 0.5, 1.0, 2.0, args.t_end):
        if when <= args.t_end:
            i = min(np.searchsorted(t, when), len(t) - 1)
            print(f"t = {t[i]:6.3f} s   distance to the target {e[i]:.3e} m   "
                  f"satellite turned {np.degrees(angle[i]):.3f} deg")
    print(f"largest |momentum| along the run {np.abs(r['momentum']).max():.2e} (from 0)")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(6.4, 5.0), sharex=True)
    top.semilogy(t, e)
    top.set_ylabel("tip to target (m)")
    top.set_title("space robot: the index fingertip to a point, the satellite floating")
    bottom.plot(t, np.degrees(angle))
    bottom.set_ylabel("satellite turned (deg)")
    bottom.set_xlabel("t (s)")
    for ax in (top, bottom):
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.plot, dpi=120)
    print("wrote", args.plot)


if __name__ == "__main__":
    main()
