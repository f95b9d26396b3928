#!/usr/bin/env python3
"""The spin-up of a flexible beam (Simo & Vu-Quoc 1986; Kane, Ryan & Banerjee 1987): a planar
cantilever, L = 10 m, ρA = 1.2 kg/m, EA = 2.8e7 N, EI = 1.4e4 N m², clamped to a hub whose angle
follows

    θ(t) = (ω_s/T_s) (t²/2 + (T_s/2π)² (cos(2πt/T_s) − 1))   for t ≤ T_s,
    θ(t) = ω_s (t − T_s/2)                                     after,

T_s = 15 s, ω_s = 4 rad/s: above the beam's first bending frequency (3.80 rad/s), so that a
model without geometric stiffening lets the deflection grow without bound. femdyn's flexible bar
(docs/flexible.md) stiffens through its exact kinematics.

The hub's angle is prescribed by computed torque at every evaluation of the dynamics: with
q̈ = q̈₀ + M⁻¹ e_hub τ_hub (q̈₀ the accelerations without it), τ_hub = (θ̈_c − q̈₀_hub)/(M⁻¹)_hub,hub
gives the hub exactly θ̈_c = θ̈(t) + 2ζω (θ̇(t) − θ̇) + ω² (θ(t) − θ), whose feedback only holds
the integrator's drift (ω = 20 rad/s).

Usage: spin_up_beam.py [--segments N] [--rtol R] [--t-end T] [--csv] [--plot FILE.png]
  --csv prints t,v_tip,u_tip every 0.5 s from 0 to 30 s: the tip's transverse and axial
  displacement in the hub's frame (m). 8 parts (the default) at rtol 1e-8 take minutes: the
  controller is Python, called at every evaluation (docs/flexible.md#in-motion).
"""
import argparse
import math
import sys

import numpy as np

import femdyn

L, RHO_A, EA, EI = 10.0, 1.2, 2.8e7, 1.4e4
T_S, OMEGA_S = 15.0, 4.0


def hub_angle(t):
    """θ, θ̇, θ̈ of the prescribed hub at t."""
    if t <= T_S:
        c = T_S / (2 * math.pi)
        theta = OMEGA_S / T_S * (t * t / 2 + c * c * (math.cos(t / c) - 1))
        rate = OMEGA_S / T_S * (t - c * math.sin(t / c))
        accel = OMEGA_S / T_S * (1 - math.cos(t / c))
        return theta, rate, accel
    return OMEGA_S * (t - T_S / 2), OMEGA_S, 0.0


def model(segments):
    b = femdyn.Builder("spin-up beam")
    b.body("hub", "world", type="revolute", joint="hub", axis=[0, 0, 1])
    b.rigid_body("hub", 1.0, [0, 0, 0], np.diag([0.1, 0.1, 0.1]))
    # In the plane: bending about z (EI), stretch (EA); the out-of-plane bending is kept (it
    # stays at rest) and torsion left out. ρI = ρA EI/EA, a homogeneous section's.
    b.flexible_bar("beam", "hub", length=L, segments=segments, torsion=False,
                   section={"EA": EA, "EIy": EI, "EIz": EI, "rhoA": RHO_A})
    return b.build()


def run(segments, rtol, t_end=30.0):
    """Rows (t, v_tip, u_tip) every 0.5 s, and the largest |θ − θ(t)| of the hub at them."""
    m = model(segments)
    omega, zeta = 20.0, 1.0

    def controller(t, q, qd):
        theta, rate, accel = hub_angle(t)
        e = m.equations(q, qd, np.zeros(m.n))
        commanded = accel + 2 * zeta * omega * (rate - qd[0]) + omega ** 2 * (theta - q[0])
        minv_hub = np.linalg.solve(e["M"], np.eye(m.n)[0])[0]
        tau = np.zeros(m.n)
        tau[0] = (commanded - e["qdd"][0]) / minv_hub
        return tau

    sim = femdyn.Simulator(m, integrator="dopri", dt=0.5, rtol=rtol, atol=rtol * 1e-3)
    out = sim.run(controller, t_end, mode="evaluation")
    if not out["stats"]["ok"]:
        sys.exit("spin_up_beam: the run failed: " + out["stats"]["failure"])
    rows, hub_error = [], 0.0
    for t, q in zip(out["t"], out["q"]):
        hub_error = max(hub_error, abs(q[0] - hub_angle(t)[0]))
        p = m.frame_kinematics("beam.tip", q)["p"]
        c, s = math.cos(q[0]), math.sin(q[0])
        x, y = c * p[0] + s * p[1], -s * p[0] + c * p[1]  # in the hub's frame
        rows.append((t, y, x - L))
    return np.array(rows), hub_error


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--segments", type=int, default=8)
    parser.add_argument("--rtol", type=float, default=1e-9)
    parser.add_argument("--t-end", type=float, default=30.0)
    parser.add_argument("--csv", action="store_true")
    parser.add_argument("--plot")
    a = parser.parse_args()
    rows, _ = run(a.segments, a.rtol, a.t_end)
    if a.csv:
        print("t,v_tip,u_tip")
        for t, v, u in rows:
            print(f"{t:.1f},{v:.6f},{u:.6f}")
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 3.5))
        ax.plot(rows[:, 0], rows[:, 1], marker=".")
        ax.set_xlabel("t (s)")
        ax.set_ylabel("tip deflection in the hub's frame (m)")
        ax.set_title(f"spin-up to {OMEGA_S} rad/s in {T_S} s, {a.segments} segments")
        ax.grid(True)
        fig.tight_layout()
        fig.savefig(a.plot, dpi=120)
    if not a.csv and not a.plot:
        print(f"largest |v_tip| {np.abs(rows[:, 1]).max():.4f} m; at 30 s v_tip = "
              f"{rows[-1, 1]:.4f} m, u_tip = {rows[-1, 2]:.5f} m")


if __name__ == "__main__":
    main()
