#!/usr/bin/env python3
"""The flexible bar's speed against beam size and against rigid chains (docs/flexible.md, "Speed").

usage: tools/flexible_bench.py FEMDYN [--parts 10,30,100,300,1000] [--repeats 3] [--markdown]
                               [--check]

For each n it writes a steel cantilever of n parts (4n coordinates: each joint's ry, rz, rx, ux),
a rigid spatial chain of 4n revolute joints (the same number of coordinates and of bodies as
femdyn builds for the bar) and one of n + 1 bodies (the bar's pieces), and times q̈ of each with
`femdyn bench MODEL --quick --json` (median ns per call, femdyn's forward_dynamics; Simbody's on
the bar beside it), the models alternating, `--repeats` rounds, the median of the rounds kept.

--check exits 1 unless, in this run:
  - q̈ of the bar is O(n) up to 300 parts: from each size to the next, the time per coordinate
    grows by less than 1.5x (caches set the limit beyond);
  - at 100 parts the bar is within 2x of the rigid chain with its number of coordinates.
The chain of n + 1 bodies is reported, not judged: it has a quarter of the coordinates.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

STEEL = {"E": 2.1e11, "G": 8.1e10, "density": 7850, "area": 1e-4, "Iy": 8.333e-10,
         "Iz": 8.333e-10, "J": 1.406e-9}


def cantilever(n):
    return {"name": f"cantilever of {n} parts", "gravity": [0, 0, -9.81], "bodies": [],
            "flexible_bars": [{"name": "bar", "parent": "world", "length": 1.0, "segments": n,
                               "section": STEEL}]}


def chain(bodies):
    """A rigid spatial chain of the bar's steel: revolute joints about y, z, x in turn, 1 m long
    in all, each body a piece of the bar (its mass and rotary inertia, as io/flexible_bar.cpp)."""
    step, axes, out = 1.0 / bodies, ([0, 1, 0], [0, 0, 1], [1, 0, 0]), []
    rho_a, rho_i = STEEL["density"] * STEEL["area"], STEEL["density"] * STEEL["Iy"]
    m = rho_a * step
    for k in range(bodies):
        out.append({"name": f"b{k}", "parent": f"b{k - 1}" if k else "world",
                    "joint": {"type": "revolute", "axis": axes[k % 3],
                              "origin": {"xyz": [step if k else 0, 0, 0]}},
                    "elements": [{"type": "rigid_body", "mass": m, "com": [step / 2, 0, 0],
                                  "inertia": {"ixx": 2 * rho_i * step,
                                              "iyy": rho_i * step + m * step ** 2 / 12,
                                              "izz": rho_i * step + m * step ** 2 / 12}}]})
    return {"name": f"rigid chain of {bodies}", "gravity": [0, 0, -9.81], "bodies": out}


def qdd_ns(femdyn, path):
    out = subprocess.run([femdyn, "bench", path, "--quick", "--json"], capture_output=True,
                         text=True, check=True).stdout
    times = {(r["engine"], r["quantity"]): r["median_ns"] for r in json.loads(out)["results"]}
    return times[("femdyn", "qdd")], times.get(("simbody", "qdd"))


def measure(femdyn, parts, repeats, folder):
    models = {}
    for n in parts:
        for kind, doc in (("bar", cantilever(n)), ("chain", chain(4 * n)),
                          ("pieces", chain(n + 1))):
            path = os.path.join(folder, f"{kind}{n}.json")
            with open(path, "w") as f:
                json.dump(doc, f)
            models[(kind, n)] = path
    rounds = {key: [] for key in models}
    simbody = {}
    for _ in range(repeats):  # the models alternating, round after round
        for key, path in models.items():
            ns, sb = qdd_ns(femdyn, path)
            rounds[key].append(ns)
            if key[0] == "bar" and sb:
                simbody.setdefault(key[1], []).append(sb)
    med = {key: statistics.median(v) for key, v in rounds.items()}
    return med, {n: statistics.median(v) for n, v in simbody.items()}


def table(parts, med, simbody):
    rows = ["| parts n | coordinates | flexible bar | rigid chain, same coordinates | ratio | "
            "rigid chain of n + 1 bodies | ratio | Simbody, the bar |",
            "|---|---|---|---|---|---|---|---|"]
    us = lambda ns: f"{ns / 1e3:.3g} μs"  # noqa: E731
    for n in parts:
        bar, chain_, pieces = med[("bar", n)], med[("chain", n)], med[("pieces", n)]
        rows.append(f"| {n} | {4 * n} | {us(bar)} | {us(chain_)} | {bar / chain_:.2f} | "
                    f"{us(pieces)} | {bar / pieces:.2f} | "
                    f"{us(simbody[n]) if n in simbody else '—'} |")
    return "\n".join(rows)


def check(parts, med):
    failures = []
    small = [n for n in parts if n <= 300]
    for a, b in zip(small, small[1:]):
        growth = (med[("bar", b)] / b) / (med[("bar", a)] / a)
        if growth >= 1.5:
            failures.append(f"q̈ per coordinate grows {growth:.2f}x from {a} to {b} parts")
    if 100 in parts and med[("bar", 100)] / med[("chain", 100)] > 2:
        failures.append(f"at 100 parts the bar is {med[('bar', 100)] / med[('chain', 100)]:.2f}x "
                        "the rigid chain with its coordinates")
    return failures


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("femdyn")
    p.add_argument("--parts", default="10,30,100,300,1000")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--markdown", action="store_true")
    p.add_argument("--check", action="store_true")
    a = p.parse_args()
    parts = [int(x) for x in a.parts.split(",")]
    with tempfile.TemporaryDirectory() as folder:
        med, simbody = measure(a.femdyn, parts, a.repeats, folder)
    print(table(parts, med, simbody))
    if a.check:
        failures = check(parts, med)
        for f in failures:
            print(f"FAIL: {f}", file=sys.stderr)
        return 1 if failures else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
