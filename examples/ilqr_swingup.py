"""iLQR swing-up of the planar double pendulum from femdyn's derivatives (docs/derivatives.md).

    PYTHONPATH=build/python python3 examples/ilqr_swingup.py [--plot docs/derivatives/ilqr_swingup.png]

models/double_pendulum_planar.json (two aluminium bars, 0.6 m and 0.4 m, gravity along -y)
with a torque on both joints, from hanging, q = (-pi/2, 0), to upright, q = (pi/2, 0), at rest,
in T = 2.5 s. The dynamics are discretised as the classical Runge-Kutta 4 step of length h with
the torque held over it, x' = F(x, u), which is what femdyn.Simulator's rk4 does, and F's
Jacobians follow from each stage's A_i, B_i (model.derivatives_batch at the stage states):

    dk1 = A1 dx + B1 du,   dk2 = A2 (dx + h/2 dk1) + B2 du,   dk3 = A3 (dx + h/2 dk2) + B3 du,
    dk4 = A4 (dx + h dk3) + B4 du,   dx' = dx + h/6 (dk1 + 2 dk2 + 2 dk3 + dk4).

iLQR (Li and Todorov 2004; Tassa, Erez and Todorov 2012): cost sum_k h u_k^T R u_k +
(x_N - x_goal)^T Q_f (x_N - x_goal); a backward pass of the quadratic value function with
Levenberg-Marquardt regularisation mu on Q_uu, a forward pass with a backtracking line search.
The optimised controls and their feedback gains K_k are then run on femdyn.Simulator (rk4, the
controller sampled every h and held), tau = u_k + K_k (x - x_k).
"""
import argparse
import pathlib

import numpy as np

import femdyn

ROOT = pathlib.Path(__file__).resolve().parents[1]
T, H = 2.5, 0.02
START = np.array([-np.pi / 2, 0.0, 0.0, 0.0])
GOAL = np.array([np.pi / 2, 0.0, 0.0, 0.0])
R = 0.01 * np.eye(2)
QF = np.diag([1e3, 1e3, 1e2, 1e2])


def f(model, x, u):
    """(v, qdd) at x = (q, v) under u."""
    return np.r_[x[2:], model.forward_dynamics(x[:2], x[2:], u)]


def rollout(model, x0, u):
    """States x_0..x_N of the RK4 step with u held."""
    x = np.empty((len(u) + 1, 4))
    x[0] = x0
    for k, uk in enumerate(u):
        k1 = f(model, x[k], uk)
        k2 = f(model, x[k] + H / 2 * k1, uk)
        k3 = f(model, x[k] + H / 2 * k2, uk)
        k4 = f(model, x[k] + H * k3, uk)
        x[k + 1] = x[k] + H / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return x


def stage(model, x, u):
    """f and its A (N, 4, 4), B (N, 4, 2) at N states, from the batch derivatives."""
    d = model.derivatives_batch(x[:, :2], x[:, 2:], u)
    N = len(x)
    A = np.zeros((N, 4, 4))
    A[:, :2, 2:] = np.eye(2)
    A[:, 2:, :2] = d["dqdd_dq"]
    A[:, 2:, 2:] = d["dqdd_dv"]
    B = np.zeros((N, 4, 2))
    B[:, 2:] = d["Minv"]
    return np.c_[x[:, 2:], d["qdd"]], A, B


def step_jacobians(model, x, u):
    """F_x (N, 4, 4), F_u (N, 4, 2) of the RK4 step at each (x_k, u_k)."""
    eye = np.eye(4)
    k1, A1, B1 = stage(model, x, u)
    k2, A2, B2 = stage(model, x + H / 2 * k1, u)
    k3, A3, B3 = stage(model, x + H / 2 * k2, u)
    _, A4, B4 = stage(model, x + H * k3, u)
    d1x, d1u = A1, B1
    d2x, d2u = A2 @ (eye + H / 2 * d1x), A2 @ (H / 2 * d1u) + B2
    d3x, d3u = A3 @ (eye + H / 2 * d2x), A3 @ (H / 2 * d2u) + B3
    d4x, d4u = A4 @ (eye + H * d3x), A4 @ (H * d3u) + B4
    return eye + H / 6 * (d1x + 2 * d2x + 2 * d3x + d4x), H / 6 * (d1u + 2 * d2u + 2 * d3u + d4u)


def cost(x, u):
    e = x[-1] - GOAL
    return H * np.einsum("ki,ij,kj->", u, R, u) + e @ QF @ e


def backward(model, x, u, mu):
    """Feed-forward steps d_k and gains K_k, and the expected decrease terms."""
    Fx, Fu = step_jacobians(model, x[:-1], u)
    Vx, Vxx = QF @ (x[-1] - GOAL), QF.copy()
    N = len(u)
    d, K = np.zeros((N, 2)), np.zeros((N, 2, 4))
    dV = np.zeros(2)
    for k in range(N - 1, -1, -1):
        Qx = Fx[k].T @ Vx
        Qu = 2 * H * R @ u[k] + Fu[k].T @ Vx
        Qxx = Fx[k].T @ Vxx @ Fx[k]
        Quu = 2 * H * R + Fu[k].T @ Vxx @ Fu[k]
        Qux = Fu[k].T @ Vxx @ Fx[k]
        Quu_reg = Quu + mu * np.eye(2)
        d[k] = -np.linalg.solve(Quu_reg, Qu)
        K[k] = -np.linalg.solve(Quu_reg, Qux)
        dV += [d[k] @ Qu, 0.5 * d[k] @ Quu @ d[k]]
        Vx = Qx + K[k].T @ Quu @ d[k] + K[k].T @ Qu + Qux.T @ d[k]
        Vxx = Qxx + K[k].T @ Quu @ K[k] + K[k].T @ Qux + Qux.T @ K[k]
        Vxx = 0.5 * (Vxx + Vxx.T)
    return d, K, dV


def forward(model, x, u, d, K, alpha):
    """The new controls u + alpha d + K (x_new - x) and their states; None if the motion runs
    away (speeds beyond 1e3 rad/s: a step too long for the line search)."""
    xn = np.empty_like(x)
    un = np.empty_like(u)
    xn[0] = x[0]
    for k in range(len(u)):
        un[k] = u[k] + alpha * d[k] + K[k] @ (xn[k] - x[k])
        xn[k + 1] = rollout(model, xn[k], un[k:k + 1])[1]
        if not np.abs(xn[k + 1]).max() < 1e3:
            return None, None
    return xn, un


def ilqr(model, iterations=150, seed=1):
    """Optimised states (N+1, 4), controls (N, 2), gains (N, 2, 4) and the cost per iteration."""
    N = int(round(T / H))
    u = np.random.default_rng(seed).normal(0, 0.1, (N, 2))  # breaks the symmetry of hanging
    x = rollout(model, START, u)
    J = cost(x, u)
    history, mu = [J], 1e-6
    for _ in range(iterations):
        d, K, dV = backward(model, x, u, mu)
        for alpha in 0.5 ** np.arange(10):
            xn, un = forward(model, x, u, d, K, alpha)
            if xn is None:
                continue
            Jn = cost(xn, un)
            expected = -(alpha * dV[0] + alpha**2 * dV[1])
            if Jn < J and (J - Jn) > 1e-4 * expected:
                break
        else:
            mu = max(mu * 10, 1e-6)
            continue
        improvement = (J - Jn) / J
        x, u, J, mu = xn, un, Jn, max(mu / 10, 1e-9)
        history.append(J)
        if improvement < 1e-5:
            break
    _, K, _ = backward(model, x, u, mu)
    return x, u, K, history


def run(iterations=150):
    """The plan and its run on femdyn.Simulator: dict plan_x, u, K, history, t, q, qd."""
    model = femdyn.load(str(ROOT / "models" / "double_pendulum_planar.json"))
    x, u, K, history = ilqr(model, iterations)
    sim = femdyn.Simulator(model, integrator="rk4", dt=H, q0=START[:2], qd0=START[2:])

    def controller(t, q, qd):
        k = min(int(round(t / H)), len(u) - 1)
        return u[k] + K[k] @ (np.r_[q, qd] - x[k])

    result = sim.run(controller, T)
    return {"plan_x": x, "u": u, "K": K, "history": history, "t": result["t"],
            "q": result["q"], "qd": result["qd"]}


def plot(r, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, bx, cx) = plt.subplots(1, 3, figsize=(12, 3.8))
    ax.plot(r["t"], r["q"][:, 0], label="shoulder")
    ax.plot(r["t"], r["q"][:, 1], label="elbow")
    ax.axhline(np.pi / 2, color="gray", linestyle="--", linewidth=0.8)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("q (rad)")
    ax.set_title("simulated (rk4, held τ + feedback)")
    ax.legend()
    tu = np.arange(len(r["u"])) * H
    bx.step(tu, r["u"][:, 0], where="post", label="τ shoulder")
    bx.step(tu, r["u"][:, 1], where="post", label="τ elbow")
    bx.set_xlabel("t (s)")
    bx.set_ylabel("τ (N m)")
    bx.set_title(f"iLQR controls ({len(r['history']) - 1} iterations)")
    bx.legend()
    for i in range(0, len(r["t"]), 5):
        a, b = r["q"][i]
        p1 = 0.6 * np.array([np.cos(a), np.sin(a)])
        p2 = p1 + 0.4 * np.array([np.cos(a + b), np.sin(a + b)])
        shade = 0.2 + 0.8 * i / (len(r["t"]) - 1)
        cx.plot([0, p1[0], p2[0]], [0, p1[1], p2[1]], color=(0, 0, 0.6, shade), linewidth=1)
    cx.set_aspect("equal")
    cx.set_title("every 0.1 s, hanging to upright")
    cx.set_xlabel("x (m)")
    cx.set_ylabel("y (m)")
    fig.tight_layout()
    pathlib.Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--plot", default=None,
                        help="write the figure to this PNG file (none unless asked)")
    args = parser.parse_args()
    r = run()
    xf = np.r_[r["q"][-1], r["qd"][-1]]
    print(f"iLQR: {len(r['history']) - 1} iterations, cost {r['history'][0]:.4g} -> "
          f"{r['history'][-1]:.4g}; plan's final error {np.abs(r['plan_x'][-1] - GOAL).max():.2e}")
    print(f"simulated final state {np.array2string(xf, precision=5)}, error "
          f"{np.abs(xf - GOAL).max():.2e} (goal {np.array2string(GOAL, precision=5)})")
    if args.plot:
        plot(r, args.plot)
        print("plot:", args.plot)


if __name__ == "__main__":
    main()
