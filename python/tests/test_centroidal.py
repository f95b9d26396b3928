"""The mechanism as a whole from Python: centre of mass, its Jacobian, the centroidal momentum
matrix and the generalized Jacobian of the space robot; the batch forms equal the single calls
row for row, and the CLI gives the same numbers."""
import numpy as np
import pytest

import femdyn
from conftest import cli_json, numbers


def test_centroidal_equals_differences_and_the_cli(root):
    model = femdyn.load(str(root / "models/hand.json"))
    rng = np.random.default_rng(3)
    q = rng.uniform(-0.5, 0.5, model.n)
    v = rng.uniform(-1, 1, model.n)
    c = model.centroidal(q, v)
    assert c["A"].shape == (6, model.n) and c["Jcom"].shape == (3, model.n)
    assert np.allclose(c["momentum"], c["A"] @ v, rtol=0, atol=1e-12)
    assert np.allclose(c["momentum"][:3], c["mass"] * c["com_velocity"], rtol=0, atol=1e-12)
    h = 1e-6
    for j in range(model.n):
        e = np.zeros(model.n)
        e[j] = h
        fd = (model.centroidal(q + e)["com"] - model.centroidal(q - e)["com"]) / (2 * h)
        assert np.allclose(c["Jcom"][:, j], fd, rtol=0, atol=1e-8)
    # Ȧ v: the rate of A v along q + t v.
    fd = (model.centroidal(q + h * v)["A"] @ v - model.centroidal(q - h * v)["A"] @ v) / (2 * h)
    assert np.allclose(c["bias"], fd, rtol=0, atol=1e-6 * (1 + np.abs(fd).max()))
    out = cli_json("kinematics", str(root / "models/hand.json"), f"--q={numbers(q)}",
                   f"--qd={numbers(v)}", "--json")["centroidal"]
    assert np.allclose(np.array(out["A"]), c["A"], rtol=0, atol=1e-12)
    assert np.allclose(np.array(out["bias"]), c["bias"], rtol=0, atol=1e-12)
    assert out["mass"] == pytest.approx(c["mass"], rel=1e-15)


def test_batches_equal_single_calls(root):
    model = femdyn.load(str(root / "models/space_robot.json"))
    rng = np.random.default_rng(4)
    k = 5
    q = np.tile(model.neutral_configuration(), (k, 1))
    q[:, 7:] += rng.uniform(-0.5, 0.5, (k, model.n_q - 7))
    v = rng.uniform(-1, 1, (k, model.n))
    frames = model.frame_kinematics_batch("index_tip", q, v, axes="local")
    cents = model.centroidal_batch(q, v)
    assert frames["J"].shape == (k, 6, model.n) and cents["A"].shape == (k, 6, model.n)
    for i in range(k):
        one = model.frame_kinematics("index_tip", q[i], v[i], axes="local")
        for key in ("p", "R", "J", "velocity", "bias"):
            assert np.array_equal(frames[key][i], one[key]), key
        one = model.centroidal(q[i], v[i])
        for key in ("com", "Jcom", "momentum", "A", "bias", "inertia_com"):
            assert np.array_equal(cents[key][i], one[key]), key


def test_generalized_jacobian_moves_the_tip_with_the_base_floating(root):
    model = femdyn.load(str(root / "models/space_robot.json"))
    rng = np.random.default_rng(5)
    q = model.neutral_configuration()
    q[7:] += rng.uniform(-0.5, 0.5, model.n_q - 7)
    g = model.generalized_jacobian("index_tip", q)
    assert g["J"].shape == (6, model.n - 6) and g["rates"][0] == "joint1"
    assert list(g["rate_index"]) == list(range(6, model.n))
    # Arm rates v_m; the base as momentum conservation from rest moves it: A_b v_b = −A_m v_m.
    v_m = rng.uniform(-1, 1, model.n - 6)
    A = model.centroidal(q)["A"]
    v = np.concatenate([-np.linalg.solve(A[:, :6], A[:, 6:] @ v_m), v_m])
    tip = model.frame_kinematics("index_tip", q, v)
    assert np.allclose(g["J"] @ v_m, tip["velocity"], rtol=0, atol=1e-10)
    assert np.allclose(g["drift"], 0, atol=1e-15)
    with pytest.raises(femdyn.ModelError, match="needs one tree on a free joint"):
        hand = femdyn.load(str(root / "models/hand.json"))
        hand.generalized_jacobian("index_tip", np.zeros(hand.n))
