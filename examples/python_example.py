#!/usr/bin/env python3
"""femdyn from Python: the worked example of docs/python.md (run by the tests).

    PYTHONPATH=build/python /usr/bin/python3 examples/python_example.py [MODEL]

Loads the paper's robot finger, prints its equations M q'' + h = Q at one state, checks
h = D[q', q'] and inverse dynamics, evaluates a batch of states on every core, and simulates
the finger's free motion from that state for 0.2 s (the finger
model has no gravity: its energy is conserved).
"""
import sys
import time

import numpy as np

import femdyn

path = sys.argv[1] if len(sys.argv) > 1 else "models/finger.json"
model = femdyn.load(path)  # femdyn.ModelError (a ValueError) if the file is bad
print(f"{model.name}: n = {model.n}, coordinates {model.coordinates}")

# 1. The equations at one state (arguments left out are zero).
q = np.full(model.n, 0.3)
qd = np.full(model.n, 1.0)
tau = np.full(model.n, 0.01)
eq = model.equations(q, qd, tau)
np.set_printoptions(precision=4, suppress=False, linewidth=100)
print("M^s =\n", eq.M, "\nh =", eq.h, "\nQ =", eq.Q, "\nqdd =", eq.qdd)

# 2. The velocity term from the third-order tensor, h_a = sum_bc D_abc qd_b qd_c, and inverse
#    dynamics of qdd giving tau back.
D = model.tensor(q)
print("max |D[qd, qd] - h| =", np.abs(np.einsum("abc,b,c->a", D, qd, qd) - eq.h).max())
print("max |tau(qdd) - tau| =", np.abs(model.inverse_dynamics(q, qd, eq.qdd) - tau).max())

# 3. A batch: k states as (k, n) arrays, on all cores with the GIL released.
rng = np.random.default_rng(1)
k = 20000
Q = rng.uniform(-0.5, 0.5, (k, model.n))
QD = rng.uniform(-2, 2, (k, model.n))
start = time.perf_counter()
qdd = model.forward_dynamics_batch(Q, QD)
print(f"forward dynamics of {k} states: {time.perf_counter() - start:.3f} s, "
      f"max |qdd| = {np.abs(qdd).max():.4g}")
assert np.array_equal(qdd[5], model.forward_dynamics(Q[5], QD[5]))

# 4. A simulation: arrays of t, q, qd and energies, and the integrator's statistics.
run = femdyn.simulate(model, 0.2, q0=q, qd0=qd, integrator="dopri", rtol=1e-8, atol=1e-10,
                      t_eval=np.linspace(0, 0.2, 5))
for t, qt in zip(run["t"], run["q"]):
    print(f"t = {t:.2f} s  q = {np.array2string(qt, precision=4)}")
stats = run["stats"]
print(f"{stats['steps']} steps, energy balance error {stats['energy_balance_error']:.2e} J "
      f"of {run['total'][0]:.4e} J")
