#!/usr/bin/env python3
"""femdyn's q̈, ∂q̈/∂q, ∂q̈/∂v and M⁻¹ at the states of `pin_bench --sanity`, against its output.

    build-pinocchio/pin_bench --robots=tests/robots --sanity > sanity.txt
    PYTHONPATH=build/python python3 tools/pinocchio_bench/check_sanity.py sanity.txt

Joints are matched by name (Pinocchio and femdyn number the rates in different orders). Prints
the largest relative difference of q̈ and of the three Frobenius norms per robot and state, and
exits 1 if any exceeds 1e-8 (the output's ten significant digits allow about 1e-10).
"""
import re
import sys

import numpy as np

import femdyn

STATES = {"A": lambda i: 0.1 * (i + 1), "B": lambda i: 0.1 * ((i % 10) + 1)}


def number(pattern, text):
    return float(re.search(pattern, text).group(1))


def main(path):
    text = open(path, encoding="utf-8").read()
    worst = 0.0
    for section in text.split("\n== ")[1:]:
        robot = section.split(":")[0]
        order = re.search(r"joint order \(idx_v: name\): (.*)", section).group(1).split()
        order = [entry.split(":", 1)[1] for entry in order]
        model = femdyn.load(f"tests/robots/{robot}.urdf")
        perm = [order.index(name) for name in model.coordinates]  # femdyn rate -> Pinocchio's
        n = len(order)
        for state, q_of in STATES.items():
            block = section.split("-- state " + state)[1]
            q = np.array([q_of(i) for i in range(n)])[perm]
            d = model.derivatives(q, 0.2 * np.ones(n), np.zeros(n))
            qdd = re.search(r"qdd \(aba\)\s*= (.*)", block).group(1).split()
            qdd = np.array([float(x) for x in qdd])
            diffs = {"qdd": np.abs(d["qdd"] - qdd[perm]).max() / np.abs(qdd).max()}
            for key, label in (("dqdd_dq", "ddq_dq"), ("dqdd_dv", "ddq_dv"), ("Minv", "Minv")):
                norm = number(r"\|\|" + label + r"\|\|_F\s*= (\S+)", block)
                diffs[key] = abs(np.linalg.norm(d[key]) / norm - 1)
            print(f"{robot} state {state}: " + ", ".join(f"{k} {v:.1e}" for k, v in diffs.items()))
            worst = max(worst, *diffs.values())
    print(f"largest relative difference {worst:.1e}")
    return 0 if worst < 1e-8 else 1


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: check_sanity.py SANITY_OUTPUT")
    sys.exit(main(sys.argv[1]))
