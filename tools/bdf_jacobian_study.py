#!/usr/bin/env python3
"""Work-precision of the BDF integrator with the analytic Jacobian against forward differences.

    tools/bdf_jacobian_study.py FEMDYN_BINARY [--markdown]

Two stiff models: the dexterous finger and the dexterous hand (22 DOF) with stiff, strongly
damped joint springs (stiffness 20 N m/rad, damping 0.05 N m s/rad on every finger joint: the
overdamped modes reach ~1e5 1/s on gram-scale links), from a bent, moving start over 0.5 s. Each
run is `femdyn simulate --integrator bdf --jacobian analytic|differences --rtol r --atol r/100`
sampled every 0.025 s; its error is the largest |q − q_ref|, |q̇ − q̇_ref| over the samples
against a BDF run at rtol 1e-12 with the analytic Jacobian (checked against one with differences:
the two references agree to the figure printed). Wall time is the integration's, one run each.
"""
import csv
import json
import os
import subprocess
import sys
import tempfile

FINGER = {"stiffness": [20, 20, 20, 20], "damping": [0.05, 0.05, 0.05, 0.05]}
MODELS = {
    "finger (stiff)": {"model": "dexterous_finger", "params": FINGER},
    "hand (stiff)": {"model": "dexterous_hand", "gravity": [0, 0, -9.81],
                     "params": {"finger": FINGER}},
}
T, SAMPLE = 0.5, 0.025


def run(binary, model, jacobian, rtol, out):
    n = model_n(binary, model)
    q0 = ",".join(["0.3"] * n)
    qd0 = ",".join(["1"] * n)
    cmd = [binary, "simulate", model, "--t-end", str(T), "--integrator", "bdf", "--jacobian",
           jacobian, "--rtol", repr(rtol), "--atol", repr(rtol / 100), "--q0", q0, "--qd0", qd0,
           "--sample-dt", str(SAMPLE), "--out", out, "--force", "--json"]
    summary = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
    with open(out) as f:
        rows = list(csv.DictReader(f))
    cols = [k for k in rows[0] if k.startswith("q_") or k.startswith("qd_")]
    return summary, [[float(r[c]) for c in cols] for r in rows]


_N = {}


def model_n(binary, model):
    if model not in _N:
        out = subprocess.run([binary, "linearize", model, "--json"], check=True,
                             capture_output=True, text=True).stdout
        _N[model] = json.loads(out)["n"]
    return _N[model]


def error(x, ref):
    return max(abs(a - b) for r, s in zip(x, ref) for a, b in zip(r, s))


def main():
    binary = sys.argv[1]
    markdown = "--markdown" in sys.argv
    tmp = tempfile.mkdtemp()
    lines = ["| model | rtol | Jacobian | steps | rhs evals | Jacobians | wall (ms) | error |",
             "|---|---|---|---|---|---|---|---|"]
    for name, spec in MODELS.items():
        model = os.path.join(tmp, name.split()[0] + ".json")
        with open(model, "w") as f:
            json.dump(spec, f)
        out = os.path.join(tmp, "run.csv")
        _, ref = run(binary, model, "analytic", 1e-12, out)
        _, ref_d = run(binary, model, "differences", 1e-12, out)
        print(f"{name}: references agree to {error(ref, ref_d):.1e}", file=sys.stderr)
        for rtol in (1e-4, 1e-6, 1e-8):
            for jac in ("analytic", "differences"):
                s, x = run(binary, model, jac, rtol, out)
                lines.append(f"| {name} | {rtol:.0e} | {jac} | {s['steps']} | {s['rhs_evals']} | "
                             f"{s['jac_evals']} | {1e3 * s['integration_time']:.1f} | "
                             f"{error(x, ref):.1e} |")
    print("\n".join(lines) if markdown else "\n".join(lines))


if __name__ == "__main__":
    main()
