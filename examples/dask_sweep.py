#!/usr/bin/env python3
"""A parameter study on dask.distributed (docs/python.md#sweeps): the finger's error against
run time across proximal link lengths and integrators.

    PYTHONPATH=build/python /usr/bin/python3 examples/dask_sweep.py [--scheduler ADDRESS]
                                                [--out DIR] [--quick] [--check-serial]

Each case builds the paper's finger with one proximal length, integrates its free motion for
0.5 s with one integrator and setting (rk4, euler: dt; dopri, bdf: rtol), and measures the error
of the final state against a tight reference run, with the integrator's statistics. The cases
run on a dask.distributed cluster: by default a LocalCluster of 2 worker processes on
127.0.0.1; with --scheduler tcp://host:8786 an existing cluster (whose workers can import
femdyn) — nothing else changes. The results are gathered into a pandas DataFrame, written to
DIR/finger_sweep.csv and plotted (matplotlib, Agg) to DIR/finger_sweep.png. --check-serial
runs the same cases here, one after another, and exits 1 unless every number but the timings
is equal.
"""
import argparse
import json
import os
import sys

import numpy as np

import femdyn

T_END = 0.5
Q0 = [0.1, 0.5, 0.6, 0.5]
QD0 = [0.5, 1.0, 1.0, 1.0]
SETTINGS = {"rk4": [4e-3, 2e-3, 1e-3, 5e-4], "euler": [1e-3, 5e-4, 2.5e-4],
            "dopri": [1e-4, 1e-6, 1e-8], "bdf": [1e-4, 1e-6, 1e-8]}
LENGTHS = [0.035, 0.045, 0.055]  # proximal phalanx, m (the paper's: 0.045)
TIMINGS = ["wall_time"]  # the only columns that differ between runs


def finger(proximal_length):
    """The finger model with that proximal length (a plugin document, read from its text)."""
    doc = {"model": "dexterous_finger",
           "params": {"lengths": [0.015, proximal_length, 0.030, 0.022]}}
    return femdyn.loads(json.dumps(doc), name=f"finger, proximal {proximal_length} m")


def study_case(proximal_length, integrator, setting):
    """One case: the error of the final state (q, qd) against a reference, and the cost."""
    model = finger(proximal_length)
    ref = femdyn.simulate(model, T_END, Q0, QD0, integrator="dopri", rtol=1e-12, atol=1e-14,
                          t_eval=[T_END])
    step = {"dt": setting} if integrator in ("rk4", "euler") else {"rtol": setting,
                                                                    "atol": setting * 1e-2}
    run = femdyn.simulate(model, T_END, Q0, QD0, integrator=integrator, t_eval=[T_END], **step)
    s = run["stats"]
    error = max(np.abs(run["q"][-1] - ref["q"][-1]).max(),
                np.abs(run["qd"][-1] - ref["qd"][-1]).max())
    return {"error": float(error), "steps": s["steps"], "rhs_evals": s["rhs_evals"],
            "energy_balance_error": s["energy_balance_error"],
            "wall_time": s["integration_time"]}


def cases(quick):
    lengths = LENGTHS[1:2] if quick else LENGTHS
    return [{"proximal_length": L, "integrator": name, "setting": x}
            for L in lengths for name, xs in SETTINGS.items() for x in (xs[:2] if quick else xs)]


def plot(table, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    markers = dict(zip(LENGTHS, "os^"))
    for (name, L), group in table.groupby(["integrator", "proximal_length"]):
        ax.loglog(group["wall_time"], group["error"], marker=markers.get(L, "x"),
                  label=f"{name}, {L * 1000:.0f} mm")
    ax.set_xlabel("integration wall time (s)")
    ax.set_ylabel("max error of the final state")
    ax.set_title(f"finger, free motion over {T_END} s: error against run time")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def parser():
    """The command line; --help shows the docstring's first paragraph (the whole sentence, not
    its first line) and, after the options, its explanation."""
    paragraphs = [" ".join(p.split()) for p in __doc__.split("\n\n")]
    p = argparse.ArgumentParser(description=paragraphs[0], epilog=paragraphs[2])
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="The address of an existing dask scheduler (tcp://host:8786); without "
                        "it, a LocalCluster of 2 worker processes on 127.0.0.1.")
    p.add_argument("--out", metavar="DIR", default=".",
                   help="The directory for finger_sweep.csv and finger_sweep.png (default: the "
                        "current directory).")
    p.add_argument("--quick", action="store_true",
                   help="Fewer cases: one length and two settings per integrator (the tests).")
    p.add_argument("--check-serial", action="store_true",
                   help="Also run the cases serially and exit 1 unless every number but the "
                        "timings is equal.")
    return p


def main():
    a = parser().parse_args()
    from dask.distributed import Client, LocalCluster

    if a.scheduler:
        cluster, client = None, Client(a.scheduler)
    else:  # two worker processes; every socket (the dashboards' too) on the loopback interface
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address="127.0.0.1:0",
                               worker_dashboard_address="127.0.0.1:0")
        client = Client(cluster)
    try:
        table = femdyn.sweep(study_case, cases(a.quick), client=client)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    os.makedirs(a.out, exist_ok=True)
    table.to_csv(os.path.join(a.out, "finger_sweep.csv"), index=False)
    plot(table, os.path.join(a.out, "finger_sweep.png"))
    print(table.drop(columns=TIMINGS).to_string(index=False))
    if a.check_serial:
        serial = femdyn.sweep(study_case, cases(a.quick))
        same = table.drop(columns=TIMINGS).equals(serial.drop(columns=TIMINGS))
        print(f"distributed equals serial: {same}")
        if not same:
            sys.exit(1)


if __name__ == "__main__":
    main()
