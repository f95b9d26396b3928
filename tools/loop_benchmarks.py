#!/usr/bin/env python3
"""Runs the IFToMM closed-loop benchmark models through the femdyn CLI over the benchmarks'
horizons and prints a markdown table: model, reference quantity, its source, femdyn's result,
the error, the run time. The references are in tests/data/ (tests/data/README.md names each
source): tools/loop_references.py's independent solutions; for A02 also the benchmark library's
own reference file (ADAMS); for A05's motion from the benchmark's start, values read off the
library's reference plot.

Usage: loop_benchmarks.py [--femdyn build/femdyn] [--out TABLE.md]
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")


def read_csv(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    return rows[0], [[float(x) for x in r] for r in rows[1:]]


def simulate(femdyn, model, t_end, rtol, sample_dt, qd0=None, q0=None):
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "traj.csv")
        cmd = [femdyn, "simulate", os.path.join(ROOT, "models", model), "--t-end", str(t_end),
               "--integrator", "dopri", "--rtol", str(rtol), "--atol", str(rtol), "--out", out,
               "--sample-dt", str(sample_dt), "--json"]
        if qd0:
            cmd += ["--qd0", ",".join(repr(x) for x in qd0)]
        if q0:
            cmd += ["--q0", ",".join(repr(x) for x in q0)]
        run = subprocess.run(cmd, capture_output=True, text=True)
        try:  # a run stopped by a numerical fault still prints its summary and its rows so far
            summary = json.loads(run.stdout)
        except json.JSONDecodeError:
            sys.exit(f"{' '.join(cmd)} failed:\n{run.stdout}{run.stderr}")
        if not os.path.exists(out):
            sys.exit(f"{' '.join(cmd)} wrote no rows:\n{run.stdout}{run.stderr}")
        header, rows = read_csv(out)
    return summary, header, rows


def a02(femdyn, rtol):
    n = 40
    qd0 = [-1.0 if k % 2 == 0 else 1.0 for k in range(2 * n + 1)]  # make_nfourbar.py --qd0
    s, header, rows = simulate(femdyn, "iftomm_a02_nfourbar.json", 20.0, rtol, 0.05, qd0)
    _, ref = read_csv(os.path.join(ROOT, "tests", "data", "iftomm_a02_reference.csv"))
    _, library = read_csv(os.path.join(ROOT, "tests", "data", "iftomm_a02_library.csv"))
    iq, iv = header.index("q_crank0"), header.index("qd_crank0")
    err_x = err_v = err_lib = 0.0
    for r, lib, f in zip(ref, library, rows):
        if abs(r[0] - f[0]) > 1e-9:
            break  # the last row of a stopped run
        a, w = f[iq], f[iv]
        x, y = -math.sin(a), math.cos(a)  # B0, crank0's angle from +y
        err_x = max(err_x, abs(x - r[1]), abs(y - r[2]))
        err_v = max(err_v, abs(-math.cos(a) * w - r[3]), abs(-math.sin(a) * w - r[4]))
        err_lib = max(err_lib, abs(x - lib[1]), abs(y - lib[2]))
    return s, [("B0 position x, y over 20 s (401 times), max abs error [m]", err_x, SOURCES["a02"]),
               ("B0 velocity over 20 s, max abs error [m/s]", err_v, SOURCES["a02"]),
               ("B0 position x, y over 20 s (401 times), max abs error [m]", err_lib,
                SOURCES["a02_library"])]


def a04(femdyn, rtol):
    s, header, rows = simulate(femdyn, "iftomm_a04_bricard.json", 10.0, rtol, 0.05)
    names, ref = read_csv(os.path.join(ROOT, "tests", "data", "iftomm_a04_reference.csv"))
    cols = [header.index("q_" + c) for c in "OABCD"]
    err = 0.0
    for r, f in zip(ref, rows):
        if abs(r[0] - f[0]) > 1e-9:
            break  # the last row of a stopped run
        err = max(err, max(abs(f[c] - r[1 + i]) for i, c in enumerate(cols)))
    return s, [("5 joint angles over 10 s (201 times), max abs error [rad]", err, SOURCES["a04"])]


SOURCES = {
    "a02": "closed-form 1-DOF parallelogram pendulum, tools/loop_references.py "
           "(scipy DOP853, rtol 1e-12)",
    "a02_library": "the benchmark library's reference solution (ADAMS, 2005), "
                   "tests/data/iftomm_a02_library.csv",
    "a04": "minimal-coordinate 1-DOF model, tools/loop_references.py (scipy DOP853, rtol "
           "1e-11)",
    "a05": "amended-potential stationary point, tools/loop_references.py a05",
    "a05_plot": "the library's reference s(t), read off its plot, "
                "tests/data/iftomm_a05_plot_readings.csv",
}

# tools/loop_references.py a05: the relative equilibrium at 2π rad/s
A05_S, A05_PHI = 0.692164702647930, -0.210885681283557


def a05(femdyn, rtol):
    omega = 2 * math.pi
    s, header, rows = simulate(femdyn, "iftomm_a05_flyball.json", 10.0, rtol, 0.05,
                               [omega, 0.0, 0.0, 0.0], [0.0, A05_S, A05_PHI, -A05_PHI])
    i_s, i_r = header.index("q_s"), header.index("q_rod_right")
    err = max(max(abs(r[i_s] - A05_S), abs(r[i_r] - A05_PHI)) for r in rows)
    results = [("relative equilibrium at 2π rad/s held over 10 s: max abs change of s [m] and "
                "the rod angle [rad]", err, SOURCES["a05"])]
    # the benchmark's own start (s = 0.5 m, rods 30° below the horizontal, 2π rad/s), against
    # the values read off the library's reference plot
    b, header, rows = simulate(femdyn, "iftomm_a05_flyball.json", 10.0, rtol, 0.05,
                               [omega, 0.0, 0.0, 0.0])
    i_s = header.index("q_s")
    _, readings = read_csv(os.path.join(ROOT, "tests", "data", "iftomm_a05_plot_readings.csv"))
    at = {round(r[0], 6): r[i_s] for r in rows}
    err_plot = max(abs(at[round(t, 6)] - s_read) for t, s_read in readings)
    lo, hi = min(r[i_s] for r in rows), max(r[i_s] for r in rows)
    return s, results, b, (f"s over the first 3 s at 15 times (read to ±0.003 m), max abs error "
                           f"[m]; femdyn's s(10 s) = {rows[-1][i_s]:.6f} m, range {lo:.4f} to "
                           f"{hi:.4f} (the plot: 0.50 to 0.745, s(10 s) ≈ 0.62)"), err_plot


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--femdyn", default=os.path.join(ROOT, "build", "femdyn"))
    p.add_argument("--out")
    a = p.parse_args()
    lines = [
        "| model | reference quantity | source | femdyn (dopri, rtol = atol) | error | energy "
        "drift (relative) | loops: equations, rank, redundant | run time [s] |",
        "|---|---|---|---|---|---|---|---|",
    ]
    def loops(s):
        if "loops" not in s:
            return "none (a tree with springs)"
        lp = s["loops"]
        return f"{lp['equations']}, {lp['rank']}, {lp['redundant']}"

    for label, fn in (("A02 N four-bar (N = 40)", a02), ("A04 Bricard", a04),
                      ("A05 flyball governor", a05)):
        for rtol in (1e-6, 1e-8, 1e-10):
            s, results, *extra = fn(a.femdyn, rtol)
            run = f"rtol {rtol:g}: {s['steps']} steps"
            error = "{:.2e}"
            if not s["ok"]:
                run += f"; STOPPED {s.get('failure', '')}"
                # compared up to the stop; none if it stopped before the first sample time
                error = "- (stopped before 0.05 s)" if s["t_reached"] < 0.05 else \
                    "{:.2e} (up to the stop)"
            for what, err, source in results:
                lines.append(
                    f"| {label} | {what} | {source} | {run} | {error.format(err)} | "
                    f"{s['energy_balance_relative']:.1e} | {loops(s)} | {s['wall_time']:.2f} |")
            if extra:
                b, what, err = extra
                lines.append(
                    f"| {label} | benchmark start (s = 0.5 m, rods 30° down, 2π rad/s), 10 s: "
                    f"{what} | {SOURCES['a05_plot']} | rtol {rtol:g}: {b['steps']} steps | "
                    f"{err:.2e} | {b['energy_balance_relative']:.1e} | {loops(b)} | "
                    f"{b['wall_time']:.2f} |")
    head = [
        "# IFToMM closed-loop benchmarks in femdyn",
        "",
        "Generated by tools/loop_benchmarks.py (femdyn simulate, dopri, rtol = atol as listed, "
        "Baumgarte 20/s; the run time is the CLI's wall time on this machine). References: "
        "independent minimal-coordinate solutions (tools/loop_references.py), the benchmark "
        "library's A02 file, and A05's curve read off the library's plot (tests/data/README.md). "
        "Energy drift: "
        "the CLI's energy balance relative to the energy scale (A05: with the dampers' work).",
        "",
    ]
    text = "\n".join(head + lines) + "\n"
    if a.out:
        with open(a.out, "w") as f:
            f.write(text)
    print(text, end="")


if __name__ == "__main__":
    main()
