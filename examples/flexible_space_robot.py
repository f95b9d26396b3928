#!/usr/bin/env python3
"""Damping a flexible space arm's vibration (models/flexible_space_robot.json, docs/flexible.md).

    PYTHONPATH=build/python python3 examples/flexible_space_robot.py [--t-end 5]
        [--plot flexible_space_robot.png] [--view slew.html]

A satellite floats with a two-link arm of 3 m aluminium tubes. A joint servo slews the shoulder
by 0.6 rad and the elbow by −0.9 rad in 2 s (quintic), which sets the tubes vibrating. Then:

- **motors off** (τ = 0): the arm floats and rings at the natural frequencies `femdyn check`
  lists, damped only by the aluminium (ζ ≈ 1e-4);
- **servo kept on**: the same joint PD (K_p = 2000 N m, K_d = 566 N m s) holds the end pose;
- **LQR**: a linear-quadratic regulator on the arm's linearisation about rest
  (`Model.linearize`), with the base eliminated by its momentum (zero momentum: the base's
  rates are −M_bb⁻¹ M_br of the arm's, so M* = M_rr − M_rb M_bb⁻¹ M_br, Umetani & Yoshida),
  every elastic coordinate in its state: u = −K (x − x_ref), the cost the arm's elastic energy
  plus the joints' errors.

Prints the tip's elastic deflection (the tip's position minus that of the same joints with every
strain zero) over the last second in each case, and plots it. --view writes the 3-D page of
the run with the motors off (`femdyn view`'s, each tube drawn along its centreline).
"""
import argparse
import math

import numpy as np
import scipy.linalg as sl

import femdyn
from pathlib import Path

MODEL = Path(__file__).resolve().parent.parent / "models" / "flexible_space_robot.json"
SLEW, GOAL = 2.0, {"shoulder": 0.6, "elbow": -0.9}
KP, KD = 2000.0, 2 * math.sqrt(2000.0 * 40)


def quintic(t, amplitude):
    s = min(max(t / SLEW, 0.0), 1.0)
    return (amplitude * (10 * s**3 - 15 * s**4 + 6 * s**5),
            amplitude * (30 * s**2 - 60 * s**3 + 30 * s**4) / SLEW)


class Arm:
    """The model, its joints and strains, and the controllers."""

    def __init__(self):
        self.m = femdyn.load(str(MODEL))
        m = self.m
        self.joints = [m.coordinates.index(j) for j in GOAL]
        self.joint_q = [m.configuration.index(j) for j in GOAL]
        self.rest = np.array(m.neutral_configuration())
        self.strains = np.array([i for i, c in enumerate(m.configuration)
                                 if c.rsplit(".", 1)[-1] in ("ry", "rz", "rx", "ux")])
        # The arm's rates are v[6:], its configuration q[7:] (after the base's quaternion).
        self.r = np.arange(6, m.n)
        self.rq = np.array([m.configuration.index(m.coordinates[i]) for i in self.r])
        self.K = self.lqr_gain()

    def reduced_model(self):
        """M* and K of the arm about rest, the base eliminated by zero momentum."""
        m, r = self.m, self.r
        A, _ = m.linearize(self.rest)
        M = m.equations(self.rest).M
        K = -M @ A[m.n:, :m.n]  # at rest, q̈ = −M⁻¹ K q (+ M⁻¹ τ)
        M_star = M[np.ix_(r, r)] - M[:6, r].T @ np.linalg.solve(M[:6, :6], M[:6, r])
        sym = lambda X: (X + X.T) / 2
        return sym(M_star), sym(K[np.ix_(r, r)])

    def lqr_gain(self):
        M, K = self.reduced_model()
        k = len(self.r)
        S = np.zeros((k, len(self.joints)))
        for c, j in enumerate(self.joints):
            S[j - 6, c] = 1.0
        Minv = np.linalg.inv(M)
        A = np.block([[np.zeros((k, k)), np.eye(k)], [-Minv @ K, np.zeros((k, k))]])
        B = np.vstack([np.zeros((k, len(self.joints))), Minv @ S])
        Qq = K.copy()  # the elastic energy ½ qᵀ K q, and the joints' errors
        for j in self.joints:
            Qq[j - 6, j - 6] += 2000.0
        Q, R = sl.block_diag(Qq, M), 1e-3 * np.eye(len(self.joints))
        P = sl.solve_continuous_are(A, B, Q, R)
        self.closed_loop = np.linalg.eigvals(A - B @ np.linalg.solve(R, B.T @ P))
        return np.linalg.solve(R, B.T @ P)

    def reference(self, t):
        x = np.zeros(2 * len(self.r))
        for j, name in zip(self.joints, GOAL):
            x[j - 6], x[len(self.r) + j - 6] = quintic(t, GOAL[name])
        return x

    def servo(self, t, q, v):
        tau = np.zeros(self.m.n)
        for j, jq, name in zip(self.joints, self.joint_q, GOAL):
            p, dp = quintic(t, GOAL[name])
            tau[j] = -KP * (q[jq] - p) - KD * (v[j] - dp)
        return tau

    def lqr(self, t, q, v):
        tau = np.zeros(self.m.n)
        tau[self.joints] = -self.K @ (np.r_[q[self.rq], v[self.r]] - self.reference(t))
        return tau

    def deflection(self, q):
        rigid = q.copy()
        rigid[self.strains] = 0.0
        return np.linalg.norm(self.m.frame_kinematics("tip", q)["p"]
                              - self.m.frame_kinematics("tip", rigid)["p"])

    def run(self, after, t_end):
        """The slew by the servo, then `after` (a controller); rows t, the tip's deflection."""
        sim = femdyn.Simulator(self.m, integrator="bdf", max_order=2, dt=0.002, rtol=1e-8,
                               atol=1e-10, q0=self.rest)
        out = sim.run(lambda t, q, v: self.servo(t, q, v) if t < SLEW else after(t, q, v),
                      t_end, mode="evaluation")
        self.last_run = out
        return out["t"], np.array([self.deflection(q) for q in out["q"]])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--t-end", type=float, default=5.0)
    parser.add_argument("--plot")
    parser.add_argument("--view", help="write the 3-D page of the run with the motors off")
    a = parser.parse_args()
    arm = Arm()
    cases = {"motors off": lambda t, q, v: np.zeros(arm.m.n), "servo kept on": arm.servo,
             "LQR": arm.lqr}
    runs = {}
    for name, after in cases.items():
        runs[name] = arm.run(after, a.t_end)
        if a.view and name == "motors off":  # the tubes drawn along their centrelines
            print(f"wrote {arm.m.view(arm.last_run, path=a.view, force=True)}")
    for name, (t, d) in runs.items():
        last = t >= a.t_end - 1.0
        print(f"{name:14s} tip deflection over the last second: rms {np.sqrt(np.mean(d[last]**2)):.3e}"
              f" m, max {d[last].max():.3e} m")
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 3.8))
        for name, (t, d) in runs.items():
            ax.semilogy(t, np.maximum(d, 1e-9), label=name, lw=0.8)
        ax.axvline(SLEW, color="grey", lw=0.5)
        ax.set_xlabel("t (s)")
        ax.set_ylabel("tip's elastic deflection (m)")
        ax.set_title("flexible space robot: a 2 s slew, then")
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(a.plot, dpi=120)


if __name__ == "__main__":
    main()
