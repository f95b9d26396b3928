#!/usr/bin/env python3
"""Independent reference solutions for the IFToMM benchmark models (models/iftomm_*.json),
computed here in minimal coordinates, without femdyn. Needs numpy and scipy (Debian:
python3-numpy, python3-scipy). Writes tests/data/iftomm_a02_reference.csv and
tests/data/iftomm_a04_reference.csv and prints what it derived.

Usage: loop_references.py [a02|a04|a05|all]

A02, the N four-bar mechanism (N = 40), tools/make_nfourbar.py. Every loop is a parallelogram
(pivots 1 m apart, cranks and couplers 1 m), so all N+1 cranks keep one absolute angle theta
(from +x; pi/2 at the start) and the N couplers translate without turning. With m = 1 kg,
l = 1 m, slender rods:
  T = 1/2 thetȧ² m l² ((N+1)/3 + N)          (cranks about their pivots; couplers translate at
                                             the speed l thetȧ of a crank's tip)
  V = m g l sin(theta) ((N+1)/2 + N)          (crank CoMs at l/2 sin theta, couplers at l sin theta)
so J thetä = -K cos(theta), J = m l² ((N+1)/3 + N), K = m g l ((N+1)/2 + N): a pendulum.
B0 (top of crank 0) = l (cos theta, sin theta); it starts at (0, 1) moving at 1 m/s in +x, so
thetȧ(0) = -1 rad/s. The energy carries the cranks over the top: they turn full circles and
go through the flat position (theta = 0 or pi, every bar along x) twice a turn.

A04, Bricard's mechanism, and A05, the flyball governor's steady state: the comments above
a04() and a05() below.
"""
import csv
import math
import os
import sys

import numpy as np
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
G = 9.81


def a02(n=40, t_end=20.0, dt=0.05):
    m, l = 1.0, 1.0
    J = m * l * l * ((n + 1) / 3 + n)
    K = m * G * l * ((n + 1) / 2 + n)

    def rhs(t, y):
        return [y[1], -K / J * math.cos(y[0])]

    times = np.linspace(0.0, t_end, int(round(t_end / dt)) + 1)
    sol = solve_ivp(rhs, (0.0, t_end), [math.pi / 2, -1.0], method="DOP853", rtol=1e-12,
                    atol=1e-12, t_eval=times)
    assert sol.success
    # Energy per J as a check of the integration: 1/2 thetȧ² + K/J sin(theta).
    e = 0.5 * sol.y[1] ** 2 + K / J * np.sin(sol.y[0])
    path = os.path.join(ROOT, "tests", "data", "iftomm_a02_reference.csv")
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t", "x_B0", "y_B0", "vx_B0", "vy_B0"])
        for t, th, om in zip(sol.t, sol.y[0], sol.y[1]):
            w.writerow([f"{t:.2f}", f"{l * math.cos(th):.12e}", f"{l * math.sin(th):.12e}",
                        f"{-l * math.sin(th) * om:.12e}", f"{l * math.cos(th) * om:.12e}"])
    turns = (math.pi / 2 - sol.y[0][-1]) / (2 * math.pi)
    print(f"A02 (N = {n}): J = {J:.6f} kg m^2, K = {K:.6f} N m; over {t_end} s the cranks turn "
          f"{turns:.4f} times; energy/J drift {np.ptp(e):.2e}; wrote {os.path.relpath(path, ROOT)}")


# A04, Bricard's mechanism (models/iftomm_a04_bricard.json). Five bars of 1 m and 1 kg (bricks
# 1 x 0.1 x 0.1 m, the cross-section of MBS-BOS's model) and the ground close a loop of six
# revolute joints, each axis perpendicular to its two bars. At the start (all joint angles 0):
#   joint  O (0,0,0) axis y | A (1,0,0) axis z | B (1,-1,0) axis x | C (1,-1,1) axis y |
#          D (0,-1,1) axis z | E (0,0,1) axis x (the closing joint, on the ground)
#   bars   OA along x, AB along -y, BC along +z, CD along -x, DE along +y.
# q = the five joint angles O..D, relative, as femdyn's chain. The closure (E on bar DE stays
# at (0,0,1), bar DE's x-axis stays along x) is 5 equations of rank 4: one DOF. Minimal
# coordinate: theta = q_O; the other four follow from the closure (Gauss-Newton, least
# squares), the rates from the Jacobian's null vector n (n_O = 1). Then
#   T = 1/2 m(theta) thetȧ²,  m = sum_k (m v_k·v_k + w_k·I_k w_k) at q̇ = n,  V = sum_k m g y_k
# and m thetä + 1/2 m'(theta) thetȧ² + V'(theta) = 0, with V' = sum_k m g (v_k)_y and m' by a
# central difference (h = 1e-5). From rest under gravity 9.81 in -y.
A04_P = [(0, 0, 0), (1, 0, 0), (1, -1, 0), (1, -1, 1), (0, -1, 1)]  # joints O, A, B, C, D
A04_AXES = [(0, 1, 0), (0, 0, 1), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
A04_COM = [(0.5, 0, 0), (1, -0.5, 0), (1, -1, 0.5), (0.5, -1, 1), (0, -0.5, 1)]
A04_ALONG = [0, 1, 2, 0, 1]  # each bar's long axis (x, y, z) at the start
A04_E = (0, 0, 1)
BAR_AXIAL = 1.0 * (0.1**2 + 0.1**2) / 12  # brick 1 x 0.1 x 0.1 m, 1 kg, about its CoM
BAR_TRANSVERSE = 1.0 * (1.0**2 + 0.1**2) / 12


def rotation(axis, angle):
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


class Bricard:
    def __init__(self):
        self.p = [np.array(x, float) for x in A04_P]
        self.a = [np.array(x, float) for x in A04_AXES]
        self.c = [np.array(x, float) for x in A04_COM]
        self.inertia = []
        for k in A04_ALONG:
            d = np.full(3, BAR_TRANSVERSE)
            d[k] = BAR_AXIAL
            self.inertia.append(np.diag(d))
        self.e = np.array(A04_E, float)
        self.q = np.zeros(5)  # the last closure solution, the next one's start

    def frames(self, q):
        """World (R_k, t_k) of each bar (x_world = R x_start + t), each joint's world axis and
        point (product of exponentials about the joints' axes at the start)."""
        R, t = np.eye(3), np.zeros(3)
        out, axes, points = [], [], []
        for j in range(5):
            axes.append(R @ self.a[j])
            points.append(R @ self.p[j] + t)
            Rj = rotation(self.a[j], q[j])
            t = R @ (self.p[j] - Rj @ self.p[j]) + t
            R = R @ Rj
            out.append((R, t))
        return out, axes, points

    def closure(self, q):
        f, axes, points = self.frames(q)
        R, t = f[4]
        end, x = R @ self.e + t, R @ np.array([1.0, 0, 0])
        phi = np.r_[end - self.e, x[1], x[2]]
        J = np.zeros((5, 5))
        for j in range(5):
            J[:3, j] = np.cross(axes[j], end - points[j])
            J[3:, j] = np.cross(axes[j], x)[1:]
        return phi, J

    def solve(self, theta):
        # far from the last solution: walk there in steps of at most 0.02 rad (continuation)
        steps = int(abs(theta - self.q[0]) / 0.02)
        for k in range(1, steps + 1):
            self.solve_near(self.q[0] + (theta - self.q[0]) / (steps + 1 - k))
        return self.solve_near(theta)

    def solve_near(self, theta):
        q = self.q.copy()
        q[0] = theta
        for _ in range(50):
            phi, J = self.closure(q)
            if np.max(np.abs(phi)) < 1e-14:
                break
            q[1:] -= np.linalg.lstsq(J[:, 1:], phi, rcond=None)[0]
        else:
            raise RuntimeError(f"closure did not converge at theta = {theta}")
        self.q = q
        return q

    def rates(self, q):
        _, J = self.closure(q)
        n = np.linalg.svd(J)[2][-1]
        return n / n[0]

    def mass_and_force(self, theta):
        q = self.solve(theta)
        n = self.rates(q)
        f, axes, points = self.frames(q)
        mass, dV = 0.0, 0.0
        for k in range(5):
            R, t = f[k]
            c = R @ self.c[k] + t
            w = sum(axes[j] * n[j] for j in range(k + 1))
            v = sum(np.cross(axes[j], c - points[j]) * n[j] for j in range(k + 1))
            mass += v @ v + w @ (R @ self.inertia[k] @ R.T) @ w
            dV += G * v[1]
        return mass, dV, q, n

    def potential(self, q):
        f, _, _ = self.frames(q)
        return sum(G * (R @ c + t)[1] for (R, t), c in zip(f, self.c))

    def point_c(self, q):  # joint C, the top of bar BC
        R, t = self.frames(q)[0][2]
        return R @ self.p[3] + t


def a04(t_end=10.0, dt=0.05):
    b = Bricard()
    h = 1e-5

    def rhs(t, y):
        theta, rate = y
        q0 = b.q.copy()
        mp = b.mass_and_force(theta + h)[0]
        b.q = q0
        mm = b.mass_and_force(theta - h)[0]
        b.q = q0
        mass, dV, _, _ = b.mass_and_force(theta)
        return [rate, -(0.5 * (mp - mm) / (2 * h) * rate * rate + dV) / mass]

    times = np.linspace(0.0, t_end, int(round(t_end / dt)) + 1)
    sol = solve_ivp(rhs, (0.0, t_end), [0.0, 0.0], method="DOP853", rtol=1e-11, atol=1e-12,
                    t_eval=times, dense_output=True)
    assert sol.success
    path = os.path.join(ROOT, "tests", "data", "iftomm_a04_reference.csv")
    b.q = np.zeros(5)
    energy = []
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t", "q_O", "q_A", "q_B", "q_C", "q_D", "x_C", "y_C", "z_C"])
        for t, theta, rate in zip(sol.t, sol.y[0], sol.y[1]):
            mass, _, q, _ = b.mass_and_force(theta)
            energy.append(0.5 * mass * rate * rate + b.potential(q))
            c = b.point_c(q)
            w.writerow([f"{t:.2f}"] + [f"{x:.12e}" for x in q] + [f"{x:.12e}" for x in c])
    # The swing's duration from rest at theta = 0 to rest at the far end (theta = pi, where V
    # is V(0) again), by quadrature of dt = sqrt(m / (2 (V(0) - V))) dtheta, theta = pi/2 (1 -
    # cos s) taking away the ends' inverse square roots.
    b.q = np.zeros(5)
    v0 = b.potential(b.solve(0.0))

    def dt_ds(s):
        theta = math.pi / 2 * (1 - math.cos(s))
        mass, _, q, _ = b.mass_and_force(theta)
        return math.sqrt(mass / (2 * abs(v0 - b.potential(q)))) * math.pi / 2 * math.sin(s)

    b.q = np.zeros(5)
    swing = quad(dt_ds, 0.0, math.pi, epsabs=1e-12, epsrel=1e-12, limit=200)[0]
    print(f"A04: the swing from theta = 0 to theta = pi takes {swing:.10f} s (quadrature)")
    # the first return to rest: the period of the swing (thetȧ = 0 again, theta back to 0)
    events = []
    for i in range(1, len(sol.t)):
        if sol.y[1][i - 1] > 0 >= sol.y[1][i] or sol.y[1][i - 1] < 0 <= sol.y[1][i]:
            events.append(sol.t[i])
    print(f"A04: theta range [{sol.y[0].min():.6f}, {sol.y[0].max():.6f}] rad, energy "
          f"{energy[0]:.9f} J, drift {np.ptp(energy):.2e} J; thetȧ changes sign near t = "
          f"{', '.join(f'{t:.2f}' for t in events[:6])}; wrote {os.path.relpath(path, ROOT)}")


# A05, the stiff flyball governor (models/iftomm_a05_flyball.json, tools/make_flyball.py): its
# relative equilibrium at a shaft rate omega. In the frame turning with the shaft, with the
# rods symmetric (joint angles phi and -phi, gamma = 30° + phi each rod's angle below the
# horizontal) and the slider at height s, the equilibria are the stationary points of the
# amended potential
#   V(s, gamma) = m_s g s + 2 [m_r g z_r + 1/2 K (l - l0)² - 1/2 omega² I_zz,r]
#   z_r = 1 - c sin(gamma), l = |(1/2 cos(gamma), 1 - 1/2 sin(gamma) - s)| (slider point
#   (0.05, 0, s) to the rod's middle), I_zz,r = m_r (0.05 + c cos(gamma))² + sin²(gamma) I_xx
#   + cos²(gamma) I_zz (a rod with its tip mass: m_r, its CoM c from the hinge, I about the CoM)
# (the shaft and the slider, on the axis, add constants). Solved by Newton on the gradient.
def a05(omega=2 * math.pi):
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import make_flyball as fb

    m_r, c, (ixx, _, izz) = fb.rod_with_tip()
    m_s, k, l0, g0 = fb.SLIDER_MASS, fb.K, fb.REST, fb.DROP

    def grad(x):
        s, gam = x
        dx, dz = 0.5 * math.cos(gam), 1 - 0.5 * math.sin(gam) - s
        l = math.hypot(dx, dz)
        dl_ds = -dz / l
        dl_dg = (dx * -0.5 * math.sin(gam) + dz * -0.5 * math.cos(gam)) / l
        dI = 2 * m_r * (0.05 + c * math.cos(gam)) * -c * math.sin(gam) \
            + 2 * math.sin(gam) * math.cos(gam) * (ixx - izz)
        return np.array([m_s * G + 2 * k * (l - l0) * dl_ds,
                         2 * (-m_r * G * c * math.cos(gam) + k * (l - l0) * dl_dg
                              - 0.5 * omega**2 * dI)])

    def slider_at(gam):  # the slider's balance for a rod angle (Newton in s, from l = l0)
        s = 1 - math.sin(gam)
        for _ in range(50):
            h = 1e-7
            d = (grad([s + h, gam])[0] - grad([s - h, gam])[0]) / (2 * h)
            s -= grad([s, gam])[0] / d
        return s

    # the rods' balance along the slider's: bracketed between 3° and 57° below the horizontal
    gam = brentq(lambda g: grad([slider_at(g), g])[1], math.radians(3), math.radians(57),
                 xtol=1e-15)
    x = np.array([slider_at(gam), gam])
    for _ in range(100):
        h = 1e-7
        H = np.column_stack([(grad(x + h * e) - grad(x - h * e)) / (2 * h) for e in np.eye(2)])
        step = np.linalg.solve(H, grad(x))
        x = x - step
        if np.max(np.abs(step)) < 1e-15:
            break
    s, gam = x
    l = math.hypot(0.5 * math.cos(gam), 1 - 0.5 * math.sin(gam) - s)
    print(f"A05 at omega = {omega:.10f} rad/s: s = {s:.15f} m, rod joint angle phi = "
          f"{gam - g0:.15f} rad (gamma = {math.degrees(gam):.9f} deg below the horizontal), "
          f"spring length {l:.12f} m (force {k * (l - l0):.6f} N), |grad V| = "
          f"{np.max(np.abs(grad(x))):.1e}, Hessian eigenvalues {np.linalg.eigvalsh(H)}")
    return s, gam - g0


if __name__ == "__main__":
    which = sys.argv[1] if len(sys.argv) > 1 else "all"
    if which in ("a02", "all"):
        a02()
    if which in ("a04", "all"):
        a04()
    if which in ("a05", "all"):
        a05()
