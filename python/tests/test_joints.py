"""A free-floating base and a ball joint from Python: q has n_q entries (a quaternion per joint),
v has n; the trajectory agrees with `femdyn simulate`, the quaternions stay unit, and in zero
gravity the motion conserves the energy."""
import csv
import json

import numpy as np
import pytest

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


def test_batches_take_configurations_of_n_q_entries(tmp_path):
    # Rows of q have n_q entries; each row equals the single-state call, quaternions are
    # normalised as there, and a row's bad quaternion is named by its row.
    path = tmp_path / "floating.json"
    path.write_text(json.dumps(FLOATING))
    model = femdyn.load(str(path))
    rng = np.random.default_rng(3)
    k = 5
    q = rng.uniform(-1, 1, (k, 11))
    for cols in (slice(3, 7), slice(7, 11)):
        q[:, cols] /= np.linalg.norm(q[:, cols], axis=1, keepdims=True)
    qd, tau = rng.uniform(-1, 1, (k, 9)), rng.uniform(-1, 1, (k, 9))
    qdd = model.forward_dynamics_batch(q, qd, tau)
    eq = model.equations_batch(q, qd, tau)
    assert qdd.shape == (k, 9) and eq["M"].shape == (k, 9, 9)
    for i in range(k):
        one = model.forward_dynamics(q[i], qd[i], tau[i])
        assert np.array_equal(qdd[i], one)
        assert np.array_equal(eq["qdd"][i], one)
    back = model.inverse_dynamics_batch(q, qd, qdd)
    assert np.allclose(back, tau, rtol=0, atol=1e-12)
    bad = q.copy()
    bad[2, 3:7] *= 1.1
    with pytest.raises(ValueError, match=r"^q: row 2, "):
        model.forward_dynamics_batch(bad)
    with pytest.raises(ValueError, match=r"expected shape \(k, 11\), got \(5, 9\)"):
        model.forward_dynamics_batch(q[:, :9])


COUPLED_FLOATING = {
    "name": "floating coupled chain", "gravity": [0, 0, 0],
    "bodies": FLOATING["bodies"] + [
        {"name": "l1", "parent": "arm",
         "joint": {"type": "revolute", "axis": [0, 1, 0], "origin": {"xyz": [0.6, 0, 0]}},
         "elements": [{"type": "rigid_body", "mass": 1, "com": [0.2, 0, 0],
                       "inertia": {"ixx": 0.01, "iyy": 0.02, "izz": 0.02}}]},
        {"name": "l2", "parent": "l1",
         "joint": {"type": "revolute", "axis": [0, 1, 0], "origin": {"xyz": [0.4, 0, 0]}},
         "elements": [{"type": "rigid_body", "mass": 0.5, "com": [0.1, 0, 0],
                       "inertia": {"ixx": 0.005, "iyy": 0.01, "izz": 0.01}}]}],
    "couplings": [{"joint": "l2", "follows": "l1", "ratio": 0.5, "offset": 0.2}]}


@pytest.mark.parametrize("law", [False, True])
def test_couplings_beside_quaternions_from_python(tmp_path, law):
    # q: base (7), arm (4), l1 (1); l2 follows l1 linearly or by a polynomial law.
    spec = json.loads(json.dumps(COUPLED_FLOATING))
    if law:
        c = spec["couplings"][0]
        del c["ratio"], c["offset"]
        c["polynomial"] = [[0.2, 0], [0.5, 1], [0.1, 2]]
    path = tmp_path / "coupled.json"
    path.write_text(json.dumps(spec))
    model = femdyn.load(str(path))
    assert model.n == 6 + 3 + 1
    qd0 = np.array([0.1, 0, 0.2, 0, 0.3, 1, 0, 2, 0, 3])
    r = femdyn.simulate(model, 1.0, qd0=qd0, integrator="rk4", dt=1e-3)
    q = r["q"]
    assert q.shape[1] == 12
    for cols in (slice(3, 7), slice(7, 11)):
        assert abs(np.linalg.norm(q[-1, cols]) - 1) < 1e-14
    assert abs(r["total"][-1] - r["total"][0]) < 1e-8 * r["total"][0]
    # A batch row equals the single call at the same (q, v).
    rng = np.random.default_rng(5)
    qs = q[::250]
    vs = rng.uniform(-1, 1, (len(qs), model.n))
    taus = rng.uniform(-1, 1, (len(qs), model.n))
    batch = model.forward_dynamics_batch(qs, vs, taus)
    for k in range(len(qs)):
        assert np.allclose(batch[k], model.forward_dynamics(qs[k], vs[k], taus[k]),
                           rtol=1e-13, atol=1e-13)


def test_model_names_q_and_v(tmp_path):
    path = tmp_path / "coupled.json"
    path.write_text(json.dumps(COUPLED_FLOATING))
    model = femdyn.load(str(path))
    assert (model.n, model.n_q) == (10, 12)
    assert model.configuration[:4] == ["base.x", "base.y", "base.z", "base.qw"]
    assert model.configuration[-1] == "l1"
    assert model.coordinates[:2] == ["base.vx", "base.vy"] and "l2" not in model.coordinates
    q = model.neutral_configuration()
    assert q.shape == (12,) and q[3] == 1 and q[7] == 1 and np.count_nonzero(q) == 2


def test_load_urdf_with_a_floating_base():
    # HyQ's root link on a free joint, as the CLI's --floating-base; welded by default.
    import os
    path = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "robots", "hyq.urdf")
    welded, floating = femdyn.load(path), femdyn.load(path, floating_base=True)
    assert (welded.n, welded.n_q) == (12, 12)
    assert (floating.n, floating.n_q) == (18, 19)
    assert floating.configuration[3].endswith(".qw")
    q = floating.neutral_configuration()
    qdd = floating.forward_dynamics(q, np.zeros(18), np.zeros(18))
    # At rest in free fall every body accelerates with g: the joints keep still.
    assert np.abs(qdd[6:]).max() < 1e-9
    assert np.allclose(qdd[:3], floating.gravity, atol=1e-9)


def test_load_urdf_balance_inertia_equals_the_cli(tmp_path):
    # A link drawn too flat (0.001 + 0.001 < 0.01) is refused; balance_inertia loads it with the
    # nearest physical tensor (0.005, 0.005, 0.01) and warns, as --balance-inertia does.
    path = tmp_path / "flat.urdf"
    path.write_text(
        '<robot name="r"><link name="base"/><link name="disc"><inertial>'
        '<origin xyz="0.1 0 0"/><mass value="1"/>'
        '<inertia ixx="0.001" iyy="0.001" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>'
        '<joint name="j" type="revolute"><parent link="base"/><child link="disc"/>'
        '<axis xyz="0 0 1"/></joint></robot>')
    with pytest.raises(femdyn.ModelError, match="link 'disc': inertia violates the triangle"):
        femdyn.load(str(path))
    with pytest.warns(UserWarning, match="0.001, 0.001, 0.01 -> 0.005, 0.005, 0.01"):
        model = femdyn.load(str(path), balance_inertia=True)
    M = model.mass_matrix(np.zeros(1))
    assert M[0, 0] == pytest.approx(0.01 + 0.1**2, rel=1e-14)
    cli = cli_json("equations", str(path), "--balance-inertia", "--q", "0", "--qd", "0", "--json")
    assert np.array(cli["M"]) == pytest.approx(M, rel=1e-15)


def test_frame_kinematics_from_python_equal_the_cli(tmp_path):
    # A named frame on the floating coupled chain: J (6, n), velocity = J v, and the CLI's
    # `femdyn kinematics --json` gives the same numbers in every set of axes.
    spec = json.loads(json.dumps(COUPLED_FLOATING))
    spec["frames"] = [{"name": "tool", "body": "l2", "xyz": [0.2, 0, 0.05], "rpy": [0.1, 0.2, 0.3]}]
    path = tmp_path / "framed.json"
    path.write_text(json.dumps(spec))
    model = femdyn.load(str(path))
    assert model.frames[-1] == "tool" and "base" in model.frames
    rng = np.random.default_rng(8)
    q = model.neutral_configuration()
    q[:3] = rng.uniform(-1, 1, 3)
    q[11] = 0.4
    v = rng.uniform(-1, 1, model.n)
    for axes in ("local_world_aligned", "local", "world"):
        k = model.frame_kinematics("tool", q, v, axes=axes)
        assert k["J"].shape == (6, model.n)
        assert np.allclose(k["velocity"], k["J"] @ v, rtol=0, atol=1e-12)
        out = cli_json("kinematics", str(path), "--frame=tool", f"--axes={axes}",
                       f"--q={numbers(q)}", f"--qd={numbers(v)}", "--json")
        frame = out["frames"][0]
        assert frame["name"] == "tool" and frame["body"] == "l2"
        assert np.allclose(np.array(frame["J"]), k["J"], rtol=0, atol=1e-12)
        assert np.allclose(np.array(frame["bias"]), k["bias"], rtol=0, atol=1e-12)
    with pytest.raises(ValueError, match="no frame 'nope'"):
        model.frame_kinematics("nope", q)
