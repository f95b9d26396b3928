"""Computed torque plus PD on the hand: the index fingertip follows a path (docs/control.md).

    PYTHONPATH=build/python /usr/bin/python3 examples/control_computed_torque.py [--t-end 2]
        [--plot computed_torque.png]

The path is the fingertip's under a smooth joint trajectory q_d(t): the index finger's joints
and the wrist swing about a bent posture, the other fingers hold theirs. The controller is
sampled every dt and held (zero-order hold, femdyn.Simulator.run), in joint space:

    tau = M^s(q) (qdd_d + K_d (qd_d - qd) + K_p (q_d - q)) + h(q, qd) - Q(q, qd, 0)

with M^s, h and Q (gravity, springs, dampers at tau = 0) from model.equations(q, qd). The
closed loop is then e'' + K_d e' + K_p e = 0 for e = q_d - q, up to the hold: K_p = w^2,
K_d = 2 w (critical damping, w = 40 rad/s). The fingertip starts 9 mm off the path (the index
finger's joints 0.05 rad off); the error |p(q) - p(q_d)| of the fingertip
(model.frame_kinematics("index_tip", q)["p"]) decays in 0.25 s and then stays near 1e-5 m, the
error the hold itself makes at dt = 1 ms. Prints the error at a few times; writes a plot of it against time.
"""
import argparse
import pathlib

import numpy as np

import femdyn

ROOT = pathlib.Path(__file__).resolve().parents[1]
FRAME = "index_tip"
OMEGA = 40.0  # rad/s, the closed loop's natural frequency


class Trajectory:
    """q_d(t) = q_c + a sin(2 pi f t + phi) on the index finger and the wrist: q_d, qd_d, qdd_d."""

    def __init__(self, model):
        names = model.coordinates
        moving = [i for i, c in enumerate(names) if c.startswith(("index_", "wrist_"))]
        self.q_c = np.zeros(model.n)
        for i, c in enumerate(names):  # a bent posture, fingers flexed a little
            if c.endswith(("mcp", "pip", "dip")):
                self.q_c[i] = 0.5
        self.a = np.zeros(model.n)
        self.phi = np.zeros(model.n)
        self.a[moving] = 0.25
        self.phi[moving] = np.linspace(0, np.pi, len(moving))
        self.w = 2 * np.pi * 1.0  # 1 Hz

    def __call__(self, t):
        s = np.sin(self.w * t + self.phi)
        c = np.cos(self.w * t + self.phi)
        return self.q_c + self.a * s, self.w * self.a * c, -self.w**2 * self.a * s


def computed_torque(model, trajectory, kp=OMEGA**2, kd=2 * OMEGA):
    def controller(t, q, qd):
        q_d, qd_d, qdd_d = trajectory(t)
        eq = model.equations(q, qd)  # M^s, h, and Q at tau = 0
        return eq.M @ (qdd_d + kd * (qd_d - qd) + kp * (q_d - q)) + eq.h - eq.Q
    return controller


def fingertip_error(model, trajectory, t, q):
    """|p(q(t)) - p(q_d(t))| of the fingertip at each row."""
    return np.array([np.linalg.norm(model.frame_kinematics(FRAME, qi)["p"]
                                    - model.frame_kinematics(FRAME, trajectory(ti)[0])["p"])
                     for ti, qi in zip(t, q)])


def run(t_end=2.0, dt=1e-3, kp=OMEGA**2, kd=2 * OMEGA, check=True):
    """The run and the fingertip's tracking error: dict t, error (m), run (Simulator.run's)."""
    model = femdyn.load(str(ROOT / "models" / "hand.json"))
    trajectory = Trajectory(model)
    q0, qd0, _ = trajectory(0.0)
    index = [i for i, c in enumerate(model.coordinates) if c.startswith("index_")]
    q0 = q0.copy()
    q0[index] += 0.05  # start off the path
    sim = femdyn.Simulator(model, integrator="rk4", dt=dt, q0=q0, qd0=qd0)
    result = sim.run(computed_torque(model, trajectory, kp, kd), t_end, check=check)
    return {"t": result["t"], "error": fingertip_error(model, trajectory, result["t"], result["q"]),
            "run": result}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--t-end", type=float, default=2.0)
    parser.add_argument("--dt", type=float, default=1e-3, help="control period (s)")
    parser.add_argument("--plot", default="computed_torque.png")
    args = parser.parse_args()
    r = run(args.t_end, args.dt)
    t, e = r["t"], r["error"]
    for when in (0.0, 0.1, 0.25, 0.5, 1.0, args.t_end):
        if when <= args.t_end:
            i = min(np.searchsorted(t, when), len(t) - 1)
            print(f"t = {t[i]:6.3f} s   fingertip error {e[i]:.3e} m")
    late = e[t >= min(0.5, args.t_end)]
    print(f"max error after {t[len(t) - len(late)]:g} s: {late.max():.3e} m; controller calls "
          f"{r['run']['stats']['controller_calls']}, wall time {r['run']['stats']['wall_time']:.2f} s")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.semilogy(t, np.maximum(e, 1e-12))
    ax.axhline(1e-4, color="gray", linestyle="--", linewidth=0.8, label="1e-4 m")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("fingertip error (m)")
    ax.set_title(f"Computed torque + PD on the hand, dt = {args.dt * 1e3:g} ms (ZOH)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.plot, dpi=100)
    print("plot:", args.plot)


if __name__ == "__main__":
    main()
