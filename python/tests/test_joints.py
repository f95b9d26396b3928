"""A free-floating base and a ball joint from Python: q has n_q entries (a quaternion per joint),
v has n; the trajectory agrees with `femdyn simulate`, the quaternions stay unit, and in zero
gravity the motion conserves the energy."""
import csv
import json

import numpy as np

import femdyn
from conftest import cli_json, numbers

FLOATING = {
    "name": "floating two-link", "gravity": [0, 0, 0],
    "bodies": [
        {"name": "base", "parent": "world", "joint": {"type": "free"},
         "elements": [{"type": "rigid_body", "mass": 10, "com": [0, 0, 0],
                       "inertia": {"ixx": 1, "iyy": 1.2, "izz": 0.8}}]},
        {"name": "arm", "parent": "base",
         "joint": {"type": "spherical", "origin": {"xyz": [0.5, 0, 0]}},
         "elements": [{"type": "rigid_body", "mass": 2, "com": [0.3, 0, 0],
                       "inertia": {"ixx": 0.01, "iyy": 0.05, "izz": 0.05}}]}]}


def test_floating_base_from_python_equals_cli(tmp_path):
    path = tmp_path / "floating.json"
    path.write_text(json.dumps(FLOATING))
    model = femdyn.load(str(path))
    qd0 = np.array([0.1, 0, 0, 0, 0, 1, 0, 2, 0])
    r = femdyn.simulate(model, 2.0, qd0=qd0, integrator="rk4", dt=1e-3)
    q = r["q"]
    assert q.shape[1] == 11 and r["qd"].shape[1] == 9
    assert abs(np.linalg.norm(q[-1, 3:7]) - 1) < 1e-14
    assert abs(np.linalg.norm(q[-1, 7:11]) - 1) < 1e-14
    assert abs(r["total"][-1] - r["total"][0]) < 1e-9 * r["total"][0]
    out = tmp_path / "traj.csv"
    cli_json("simulate", str(path), "--t-end=2", "--integrator=rk4", "--dt=0.001",
             f"--qd0={numbers(qd0)}", f"--out={out}", "--json")
    with open(out) as f:
        rows = list(csv.reader(f))
    assert rows[0][1:5] == ["q_base.x", "q_base.y", "q_base.z", "q_base.qw"]
    last = np.array([float(x) for x in rows[-1][1:12]])
    assert np.allclose(last, q[-1], rtol=0, atol=1e-12)
