#!/usr/bin/env python3
"""Overhead of a Python controller in the loop (docs/control.md#the-control-loop): on the finger,
rk4 at dt = 1 ms for --t-end s, the same motion under a constant tau run

  1. by femdyn.simulate (the C++ loop, no controller: the baseline),
  2. by Simulator.step(tau) called from a Python loop,
  3. by Simulator.run with a Python controller returning a fixed numpy tau, held (one call a
     period),
  4. by Simulator.run with that controller called at every evaluation of f (four a step);

the median CPU time of --repeat runs each, all in one process, the four interleaved. Prints a Markdown table: time per period,
and the overhead over the baseline per period and per controller call.

    PYTHONPATH=build/python /usr/bin/python3 tools/bench_control.py [--t-end 2] [--repeat 7] [--quick]
"""
import argparse
import os
import statistics
import time

import numpy as np

import femdyn

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
TAU = np.array([0.002, -0.001, 0.0015, 0.0005])
Q0 = np.array([0.1, 0.4, 0.3, 0.2])
DT = 1e-3


def median_times(functions, repeat):
    """The median CPU time of each function (this process's, so that other work on a shared
    machine does not count), the runs interleaved (one of each per round), so that a change in
    the machine's load falls on all of them alike."""
    times = [[] for _ in functions]
    for _ in range(repeat):
        for f, t in zip(functions, times):
            start = time.process_time()
            f()
            t.append(time.process_time() - start)
    return [statistics.median(t) for t in times]


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--t-end", type=float, default=2.0, help="simulated time per run (s)")
    p.add_argument("--repeat", type=int, default=7)
    p.add_argument("--quick", action="store_true", help="a smoke run (tests)")
    a = p.parse_args()
    if a.quick:
        a.t_end, a.repeat = 0.05, 1
    model = femdyn.load(os.path.join(ROOT, "models", "finger.json"))
    periods = round(a.t_end / DT)
    sim = femdyn.Simulator(model, integrator="rk4", dt=DT)

    def baseline():  # rows kept to a few: the loop itself is measured
        femdyn.simulate(model, a.t_end, q0=Q0, integrator="rk4", dt=DT, tau=TAU, every=periods)

    def stepped():
        sim.reset(Q0)
        for _ in range(periods):
            sim.step(TAU)

    def held():
        sim.reset(Q0)
        sim.run(lambda t, q, qd: TAU, a.t_end)

    def evaluated():
        sim.reset(Q0)
        sim.run(lambda t, q, qd: TAU, a.t_end, mode="evaluation")

    runs = [("femdyn.simulate, constant tau (C++ loop, no controller)", baseline, 0),
            ("Simulator.step(tau) from a Python loop", stepped, 1),
            ("Simulator.run, controller held (mode='hold')", held, 1),
            ("Simulator.run, controller in f (mode='evaluation')", evaluated, 5)]
    medians = median_times([f for _, f, _ in runs], a.repeat)
    times = {name: m / periods for (name, _, _), m in zip(runs, medians)}
    base = times[runs[0][0]]
    print(f"finger (n = 4), rk4, dt = {DT * 1e3:g} ms, {periods} periods a run, median of "
          f"{a.repeat} runs; {os.cpu_count()} CPUs, load {os.getloadavg()[0]:.1f}\n")
    print("| loop | µs per period | overhead µs per period | Python calls per period | "
          "overhead µs per call |")
    print("|---|---|---|---|---|")
    for name, _, calls in runs:
        t = times[name] * 1e6
        over = (times[name] - base) * 1e6
        per_call = f"{over / calls:.2f}" if calls else "–"
        print(f"| {name} | {t:.2f} | {over:.2f} | {calls} | {per_call} |")


if __name__ == "__main__":
    main()
