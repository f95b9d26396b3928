#!/usr/bin/env python3
"""Batch speed-up of the Python module (docs/python.md#batches): the k states of a batch
evaluated by a loop of single calls, by one batch call on 1 thread, and on 2 (or --threads)
threads; median of --repeat runs. Prints a Markdown table.

    PYTHONPATH=build/python python3 tools/bench_python.py [--k 20000] [--repeat 5] [--quick]
"""
import argparse
import os
import statistics
import time

import numpy as np

import femdyn

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
MODELS = ["models/finger.json", "models/urdf/arm7.urdf", "models/hand.json"]


def median_time(f, repeat):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        f()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--k", type=int, default=20000, help="states per batch")
    p.add_argument("--repeat", type=int, default=5)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--quick", action="store_true", help="a smoke run (tests)")
    a = p.parse_args()
    if a.quick:
        a.k, a.repeat = 200, 1
    print(f"k = {a.k} states, median of {a.repeat}; {os.cpu_count()} CPUs\n")
    print("| model | n | call | single calls (µs/state) | batch, 1 thread | "
          f"batch, {a.threads} threads | speed-up {a.threads} vs 1 thread |")
    print("|---|---|---|---|---|---|---|")
    rng = np.random.default_rng(1)
    for name in MODELS:
        model = femdyn.load(os.path.join(ROOT, name))
        n = model.n
        q = rng.uniform(-0.5, 0.5, (a.k, n))
        qd = rng.uniform(-2, 2, (a.k, n))
        tau = rng.uniform(-1, 1, (a.k, n))
        calls = {
            "forward_dynamics": (lambda i: model.forward_dynamics(q[i], qd[i], tau[i]),
                                 lambda t: model.forward_dynamics_batch(q, qd, tau, threads=t)),
            "equations": (lambda i: model.equations(q[i], qd[i], tau[i]),
                          lambda t: model.equations_batch(q, qd, tau, threads=t)),
        }
        for call, (single, batch) in calls.items():
            loop = median_time(lambda: [single(i) for i in range(a.k)], a.repeat)
            one = median_time(lambda: batch(1), a.repeat)
            many = median_time(lambda: batch(a.threads), a.repeat)
            us = 1e6 / a.k
            print(f"| {os.path.basename(name)} | {n} | {call} | {loop * us:.2f} | "
                  f"{one * us:.2f} | {many * us:.2f} | {one / many:.2f}x |")


if __name__ == "__main__":
    main()
