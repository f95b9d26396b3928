"""A task-space (operational-space) controller: the finger's tip moved to a point (docs/control.md).

    PYTHONPATH=build/python /usr/bin/python3 examples/control_task_space.py [--t-end 1]
        [--mode hold|evaluation] [--plot task_space.png]

The tip's position x = p(q) has the translational rows J (3 x 4) of its Jacobian and
xdd = J qdd + Jdot v (model.frame_kinematics("tip", q, qd): "J", "bias"). With M^s, h and Q at
tau = 0 from model.equations(q, qd), the controller (Khatib's operational-space law)

    Lambda = (J M^-1 J^T)^-1                        the tip's inertia (3 x 3)
    F      = Lambda (K_p (x_d - x) - K_d J v - Jdot v)
    tau    = J^T F + h - Q + N^T M (K_0 (q_0 - q) - D_0 v),   N^T = I - J^T Jbar^T,
    Jbar   = M^-1 J^T Lambda                        (the dynamically consistent inverse)

makes the tip obey e'' + K_d e' + K_p e = 0 (e = x_d - x), while the finger's fourth degree
of freedom (redundant for a point) is held near the posture q_0 in the null space of the task,
without disturbing the tip. K_p = w^2, K_d = 2 w, w = 20 rad/s. The target is the tip's position
at another bent posture, 6.5 cm away. Prints the distance to it; writes a plot of it.
"""
import argparse
import pathlib

import numpy as np

import femdyn

ROOT = pathlib.Path(__file__).resolve().parents[1]
FRAME = "tip"
OMEGA = 20.0  # rad/s


def operational_space(model, x_d, q_0, kp=OMEGA**2, kd=2 * OMEGA, k0=100.0, d0=20.0):
    n = model.n

    def controller(t, q, v):
        k = model.frame_kinematics(FRAME, q, v)
        J, x, Jdv = k["J"][:3], k["p"], k["bias"][:3]
        eq = model.equations(q, v)  # M^s, h, Q at tau = 0
        M_inv = np.linalg.inv(eq.M)
        Lam = np.linalg.inv(J @ M_inv @ J.T)
        F = Lam @ (kp * (x_d - x) - kd * (J @ v) - Jdv)
        J_bar = M_inv @ J.T @ Lam
        N_T = np.eye(n) - J.T @ J_bar.T
        posture = N_T @ (eq.M @ (k0 * (q_0 - q) - d0 * v))
        return J.T @ F + eq.h - eq.Q + posture
    return controller


def run(t_end=1.0, dt=1e-3, mode="hold", integrator="rk4"):
    """The run and the tip's distance to the target: dict t, error (m), target, run."""
    model = femdyn.load(str(ROOT / "models" / "finger.json"))
    q0 = np.array([0.0, 0.3, 0.4, 0.3])         # start
    q_target = np.array([0.2, 0.7, 0.9, 0.6])   # the target is the tip at this posture
    x_d = model.frame_kinematics(FRAME, q_target)["p"]
    sim = femdyn.Simulator(model, integrator=integrator, dt=dt, q0=q0)
    result = sim.run(operational_space(model, x_d, q_0=q0), t_end, mode=mode)
    error = np.array([np.linalg.norm(model.frame_kinematics(FRAME, q)["p"] - x_d)
                      for q in result["q"]])
    return {"t": result["t"], "error": error, "target": x_d, "run": result}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--t-end", type=float, default=1.0)
    parser.add_argument("--dt", type=float, default=1e-3, help="control period (s)")
    parser.add_argument("--mode", choices=["hold", "evaluation"], default="hold")
    parser.add_argument("--plot", default="task_space.png")
    args = parser.parse_args()
    r = run(args.t_end, args.dt, args.mode)
    t, e = r["t"], r["error"]
    print("target", r["target"], "m")
    for when in (0.0, 0.1, 0.25, 0.5, args.t_end):
        if when <= args.t_end:
            i = min(np.searchsorted(t, when), len(t) - 1)
            print(f"t = {t[i]:6.3f} s   distance to the target {e[i]:.3e} m")
    s = r["run"]["stats"]
    print(f"controller calls {s['controller_calls']}, wall time {s['wall_time']:.2f} s")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.semilogy(t, np.maximum(e, 1e-12))
    ax.set_xlabel("t (s)")
    ax.set_ylabel("|x - x_d| (m)")
    ax.set_title(f"Operational-space control of the finger's tip ({args.mode}, "
                 f"dt = {args.dt * 1e3:g} ms)")
    fig.tight_layout()
    fig.savefig(args.plot, dpi=100)
    print("plot:", args.plot)


if __name__ == "__main__":
    main()
