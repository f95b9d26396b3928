"""LQR holding the dexterous finger at a bent posture against gravity (docs/derivatives.md).

    PYTHONPATH=build/python python3 examples/lqr_finger.py [--t-end 3]

The finger (models/finger.json) under gravity along -y is held at q_d by

    tau = tau_ff - K (x - x_d),   x = (q, qd),   x_d = (q_d, 0),

tau_ff = tau(q_d, 0, 0) from inverse dynamics (gravity and the joint springs at rest), and K the
LQR gain of the linearisation at (q_d, 0, tau_ff): A, B from model.linearize (the analytic
derivatives). The links weigh grams (M^s ~ 1e-5 kg m^2), so the Riccati equation is solved for
the scaled input w = M^-1 tau (tau = M w, M = M^s(q_d), B_w = B M ~ [0; 1]):
P from scipy.linalg.solve_continuous_are(A, B_w, Q, R_w), K_w = R_w^-1 B_w^T P, K = M K_w, with
Q = diag(1, 1/OMEGA^2) and R_w = 1/OMEGA^4, which puts the closed loop near OMEGA rad/s (a double
integrator x'' = w under these weights has its poles at OMEGA (-1 ± i)/sqrt 2). The loop runs on femdyn.Simulator (rk4, the controller
sampled every dt = 1 ms and held) from q_d + 0.1 rad on every joint; prints the closed loop's
eigenvalues and the error |x - x_d| as it decays.
"""
import argparse
import pathlib

import numpy as np
import scipy.linalg

import femdyn

ROOT = pathlib.Path(__file__).resolve().parents[1]
GRAVITY = [0.0, -9.81, 0.0]
Q_D = np.array([0.2, 0.8, 0.6, 0.4])  # rad: abduction, mcp, pip, dip
OMEGA = 20.0  # rad/s


def design(model, q_d=Q_D, omega=OMEGA):
    """tau_ff, K and the closed-loop matrix A - B K at the posture q_d."""
    n = model.n
    tau_ff = model.inverse_dynamics(q_d, np.zeros(n), np.zeros(n))
    A, B = model.linearize(q_d, np.zeros(n), tau_ff)
    M = model.mass_matrix(q_d)
    Bw = B @ M
    Q = np.diag(np.r_[np.ones(n), np.ones(n) / omega**2])
    Rw = np.eye(n) / omega**4
    P = scipy.linalg.solve_continuous_are(A, Bw, Q, Rw)
    K = M @ np.linalg.solve(Rw, Bw.T @ P)
    return tau_ff, K, A - B @ K


def run(t_end=3.0, dt=1e-3, offset=0.1):
    """The closed-loop run: dict t, error (|x - x_d|_inf at each row), eigenvalues, tau_ff."""
    model = femdyn.load(str(ROOT / "models" / "finger.json"), gravity=GRAVITY)
    tau_ff, K, closed = design(model)
    x_d = np.r_[Q_D, np.zeros(model.n)]
    sim = femdyn.Simulator(model, integrator="rk4", dt=dt, q0=Q_D + offset)
    result = sim.run(lambda t, q, qd: tau_ff - K @ (np.r_[q, qd] - x_d), t_end)
    error = np.abs(np.c_[result["q"], result["qd"]] - x_d).max(axis=1)
    return {"t": result["t"], "error": error, "eigenvalues": np.linalg.eigvals(closed),
            "tau_ff": tau_ff}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--t-end", type=float, default=3.0)
    args = parser.parse_args()
    r = run(args.t_end)
    print("feed-forward tau_ff (N m):", np.array2string(r["tau_ff"], precision=4))
    ev = r["eigenvalues"]
    print("closed-loop eigenvalues: max Re", f"{ev.real.max():.3f}", "1/s, |lambda| in",
          f"[{np.abs(ev).min():.1f}, {np.abs(ev).max():.1f}] rad/s")
    for when in (0.0, 0.25, 0.5, 1.0, 2.0, args.t_end):
        i = min(np.searchsorted(r["t"], when), len(r["t"]) - 1)
        print(f"t = {r['t'][i]:5.2f} s   |x - x_d| = {r['error'][i]:.3e}")


if __name__ == "__main__":
    main()
