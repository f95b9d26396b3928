"""Closed loops from Python (docs/loops.md): a four-bar built with femdyn.Builder equals its JSON
file, its constrained q̈ satisfies the constraint at acceleration level and its λ the equations,
assembly lands on the loop, a run keeps the loop closed and conserves energy, and Andrews'
mechanism reproduces the Test Set's reference at t = 0.03 through femdyn.simulate. Every model
file validates against docs/model.schema.json."""
import json
import math
import re

import numpy as np
import pytest

import femdyn
from conftest import ROOT, model_path

# A planar four-bar (ground 0.4 m, crank 0.1 m, coupler 0.35 m, rocker 0.3 m) under gravity:
# crank and coupler a chain from the origin, the rocker from (0.4, 0); the coupler's end pinned
# to the rocker's by a ball in the x-y plane. The initial angles are a guess near the loop.
FOURBAR = {
    "name": "four-bar", "gravity": [0, -9.81, 0],
    "bodies": [
        {"name": "crank", "parent": "world",
         "joint": {"name": "a", "type": "revolute", "axis": [0, 0, 1], "initial": 1.2},
         "elements": [{"type": "rigid_body", "mass": 0.2, "com": [0.05, 0, 0],
                       "inertia": {"ixx": 1e-4, "iyy": 2e-4, "izz": 2e-4}}]},
        {"name": "coupler", "parent": "crank",
         "joint": {"name": "b", "type": "revolute", "axis": [0, 0, 1], "initial": -0.9,
                   "origin": {"xyz": [0.1, 0, 0]}},
         "elements": [{"type": "rigid_body", "mass": 0.5, "com": [0.175, 0, 0],
                       "inertia": {"ixx": 1e-4, "iyy": 5e-3, "izz": 5e-3}}]},
        {"name": "rocker", "parent": "world",
         "joint": {"name": "c", "type": "revolute", "axis": [0, 0, 1], "initial": 1.9,
                   "origin": {"xyz": [0.4, 0, 0]}},
         "elements": [{"type": "rigid_body", "mass": 0.4, "com": [0.15, 0, 0],
                       "inertia": {"ixx": 1e-4, "iyy": 3e-3, "izz": 3e-3}}]}],
    "constraints": [{"name": "pin", "type": "ball", "a": {"body": "coupler", "xyz": [0.35, 0, 0]},
                     "b": {"body": "rocker", "xyz": [0.3, 0, 0]}, "normal": [0, 0, 1]}],
    "springs": [{"name": "s", "a": {"body": "rocker", "xyz": [0.15, 0, 0]},
                 "b": {"body": "world", "xyz": [0.6, 0.3, 0]}, "stiffness": 20,
                 "rest_length": 0.1}]}


def built():
    b = femdyn.Builder("four-bar", gravity=[0, -9.81, 0])
    b.body("crank", type="revolute", joint="a", initial=1.2)
    b.rigid_body("crank", 0.2, [0.05, 0, 0], np.diag([1e-4, 2e-4, 2e-4]))
    b.body("coupler", parent="crank", type="revolute", joint="b", xyz=[0.1, 0, 0], initial=-0.9)
    b.rigid_body("coupler", 0.5, [0.175, 0, 0], np.diag([1e-4, 5e-3, 5e-3]))
    b.body("rocker", type="revolute", joint="c", xyz=[0.4, 0, 0], initial=1.9)
    b.rigid_body("rocker", 0.4, [0.15, 0, 0], np.diag([1e-4, 3e-3, 3e-3]))
    b.constraint("ball", name="pin", a={"body": "coupler", "xyz": [0.35, 0, 0]},
                 b={"body": "rocker", "xyz": [0.3, 0, 0]}, normal=[0, 0, 1])
    b.spring(name="s", a={"body": "rocker", "xyz": [0.15, 0, 0]},
             b={"body": "world", "xyz": [0.6, 0.3, 0]}, stiffness=20, rest_length=0.1)
    return b.build()


@pytest.fixture(scope="module")
def fourbar(tmp_path_factory):
    path = tmp_path_factory.mktemp("loops") / "fourbar.json"
    path.write_text(json.dumps(FOURBAR))
    return femdyn.load(str(path))


def test_builder_equals_file(fourbar):
    m = built()
    assert m.constraints == fourbar.constraints == [{"name": "pin", "type": "ball", "rows": 2}]
    rng = np.random.default_rng(1)
    q, qd = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3)
    a, b = m.constrained_dynamics(q, qd), fourbar.constrained_dynamics(q, qd)
    assert np.array_equal(a["qdd"], b["qdd"]) and np.array_equal(a["lambda"], b["lambda"])


def test_assembly_and_constrained_dynamics(fourbar):
    s = fourbar.assemble(fourbar.neutral_configuration(), np.array([3.0, 0, 0]), hold=["a"])
    assert s["residual"] < 1e-12 and s["rank"] == 2 and s["redundant"] == 0
    assert s["q"][0] == 1.2  # held
    q, qd = s["q"], s["qd"]
    k = fourbar.constraint_kinematics(q, qd)
    assert np.abs(k["J"] @ qd).max() < 1e-12  # the velocity projected onto the loop
    tau = np.array([0.3, -0.1, 0.2])
    r = fourbar.constrained_dynamics(q, qd, tau)
    # Φ_q q̈ + Φ̇_q v = 0, and M q̈ + h = Q(τ) + Φ_qᵀ λ (inverse dynamics gives τ + Φ_qᵀ λ back).
    assert np.abs(k["J"] @ r["qdd"] + k["bias"]).max() < 1e-9 * np.abs(k["J"] @ r["qdd"]).max()
    back = fourbar.inverse_dynamics(q, qd, r["qdd"], tree=True)
    assert np.allclose(back, tau + k["J"].T @ r["lambda"], rtol=0, atol=1e-10)
    assert np.allclose(r["constraint_forces"], k["J"].T @ r["lambda"], rtol=0, atol=1e-14)


def test_derivatives_of_the_constrained_dynamics(fourbar):
    s = fourbar.assemble(fourbar.neutral_configuration(), np.array([3.0, 0, 0]), hold=["a"])
    q, qd = s["q"], s["qd"]
    tau = np.array([0.3, -0.1, 0.2])
    for rate in (0.0, 20.0):
        d = fourbar.derivatives(q, qd, tau, baumgarte=rate)
        r = fourbar.constrained_dynamics(q, qd, tau, baumgarte=rate)
        assert np.allclose(d["qdd"], r["qdd"], rtol=0, atol=1e-12)
        h = 1e-6  # ∂q̈/∂v against central differences
        fd = np.column_stack([
            (fourbar.constrained_dynamics(q, qd + h * e, tau, baumgarte=rate)["qdd"]
             - fourbar.constrained_dynamics(q, qd - h * e, tau, baumgarte=rate)["qdd"]) / (2 * h)
            for e in np.eye(fourbar.n)])
        assert np.abs(d["dqdd_dv"] - fd).max() < 1e-6 * max(1.0, np.abs(fd).max())
        k = fourbar.constraint_kinematics(q, qd)
        assert np.abs(k["J"] @ d["Minv"]).max() < 1e-10  # the projected inverse
    A, B = fourbar.linearize(q, qd, tau)  # the simulator's rate, 20 1/s
    assert A.shape == (6, 6) and B.shape == (6, 3)
    # The batch forms: each row bit for bit the single call, at the rate given.
    Q, QD, TAU = np.stack([q, q]), np.stack([qd, 0.5 * qd]), np.stack([tau, -tau])
    for rate in (None, 0.0, 7.5):
        kw = {} if rate is None else {"baumgarte": rate}
        batch = fourbar.derivatives_batch(Q, QD, TAU, **kw)
        Ab, Bb = fourbar.linearize_batch(Q, QD, TAU, **kw)
        for i in range(2):
            one = fourbar.derivatives(Q[i], QD[i], TAU[i], **kw)
            for key in ("qdd", "dqdd_dq", "dqdd_dv", "Minv"):
                assert np.array_equal(batch[key][i], one[key])
            Ai, Bi = fourbar.linearize(Q[i], QD[i], TAU[i], **kw)
            assert np.array_equal(Ab[i], Ai) and np.array_equal(Bb[i], Bi)
    assert not np.array_equal(fourbar.derivatives_batch(Q, QD, TAU, baumgarte=0.0)["dqdd_dq"],
                              fourbar.derivatives_batch(Q, QD, TAU, baumgarte=7.5)["dqdd_dq"])
    with pytest.raises(ValueError, match="no constraints"):
        femdyn.load(model_path("models/pendulum.json")).derivatives([0], baumgarte=1.0)
    with pytest.raises(ValueError, match="no constraints"):
        femdyn.load(model_path("models/pendulum.json")).derivatives_batch([[0]], baumgarte=1.0)
    with pytest.raises(ValueError, match="rate >= 0"):
        fourbar.linearize_batch(Q, QD, TAU, baumgarte=-1.0)


def test_run_keeps_the_loop_and_the_energy(fourbar):
    run = femdyn.simulate(fourbar, t_end=1.0, integrator="dopri", rtol=1e-10, atol=1e-12,
                          t_eval=np.linspace(0, 1, 21))
    stats = run["stats"]
    assert stats["ok"]
    for q in run["q"]:
        assert np.abs(fourbar.constraint_kinematics(q)["phi"]).max() < 1e-10
    assert stats["loops"]["max_position_residual"] < 1e-10 and stats["loops"]["max_velocity_residual"] < 1e-9
    # Conservative (gravity, a spring): the energy drift stays at the tolerance's level.
    assert stats["energy_balance_relative"] < 1e-8


def test_loops_that_cannot_close_and_bad_arguments(fourbar):
    far = built_far()
    with pytest.raises(femdyn.NumericalError, match="cannot close"):
        far.assemble(far.neutral_configuration())
    with pytest.raises(Exception, match="cannot close"):  # a run cannot start there
        femdyn.simulate(far, t_end=0.1)
    with pytest.raises(ValueError, match="hold: unknown coordinate 'z'"):
        fourbar.assemble(fourbar.neutral_configuration(), hold=["z"])
    b = femdyn.Builder("x")
    b.body("l", type="revolute")
    b.rigid_body("l", 1.0, [0.5, 0, 0], np.diag([0.01, 0.1, 0.1]))
    b.constraint("hinge", a="l", b="world")
    with pytest.raises(femdyn.ModelError, match="constraints/0/type: unknown constraint type"):
        b.build()
    with pytest.raises(ValueError, match="no constraints"):
        femdyn.load(model_path("models/pendulum.json")).constrained_dynamics([0])


def built_far():
    b = femdyn.Builder("far")
    b.body("l", type="revolute")
    b.rigid_body("l", 1.0, [0.5, 0, 0], np.diag([0.01, 0.1, 0.1]))
    b.constraint("ball", a={"body": "l", "xyz": [1, 0, 0]},
                 b={"body": "world", "xyz": [3, 0, 0]}, normal=[0, 0, 1])
    return b.build()


def test_andrews_reference_through_simulate():
    m = femdyn.load(model_path("models/andrews.json"))
    run = femdyn.simulate(m, t_end=0.03, integrator="dopri", rtol=1e-12, atol=1e-12,
                          t_eval=[0, 0.03])
    assert run["stats"]["ok"]
    q = dict(zip(m.coordinates, run["q"][-1]))
    # Test Set for IVP Solvers, andrews: the reference at t = 0.03 (PSIDE, tolerances 1e-14).
    reference = {"beta": 15.81077119629904, "theta": -15.75637105984298,
                 "gamma": 0.04082224013073101, "phi": -0.5347301163226948,
                 "delta": 0.5244099658805304, "omega": 0.5347301163226948,
                 "epsilon": 1.048080741042263}
    for name, value in reference.items():
        assert abs(q[name] - value) < 1e-9 * (1 + abs(value)), name


def test_every_model_file_follows_the_schema():
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads((ROOT / "docs" / "model.schema.json").read_text())
    for path in sorted((ROOT / "models").glob("*.json")):
        jsonschema.validate(json.loads(path.read_text()), schema)
    jsonschema.validate(FOURBAR, schema)
    bad = json.loads(json.dumps(FOURBAR))
    bad["constraints"][0]["length"] = 1.0  # a ball has no length
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, schema)


@pytest.mark.parametrize("integrator, bound", [("rk4", "2.79e-10 s"), ("euler", "8.28e-11 s"),
                                               ("dopri", "max_steps"), ("bdf", "max_steps")])
def test_a_baumgarte_rate_the_method_cannot_follow_is_refused_as_on_the_command_line(integrator,
                                                                                     bound):
    """The same request rule as `femdyn simulate --baumgarte`: one ValueError naming the bound."""
    m = femdyn.load(model_path("models/five_bar.json"))
    with pytest.raises(ValueError, match=r"^baumgarte 1e\+10: .*" + re.escape(bound)):
        femdyn.simulate(m, t_end=1.0, integrator=integrator, baumgarte=1e10)


def test_the_simulator_refuses_the_same_baumgarte_rate_as_simulate():
    """One truth: the Simulator's fixed step answers as femdyn.simulate for the same loop model
    (the default rate 20 1/s under rk4 needs a step ≤ 0.139 s), and a short step runs."""
    m = femdyn.load(model_path("models/five_bar.json"))
    with pytest.raises(ValueError) as run_error:
        femdyn.simulate(m, t_end=1.0, integrator="rk4", dt=0.5)
    with pytest.raises(ValueError) as sim_error:
        femdyn.Simulator(m, integrator="rk4", dt=0.5)
    assert str(sim_error.value) == str(run_error.value)
    assert "the Baumgarte rate 20 1/s" in str(sim_error.value)
    sim = femdyn.Simulator(m, integrator="rk4", dt=0.01)
    sim.step(np.zeros(m.n))
