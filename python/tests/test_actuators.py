"""Actuators, friction and limits from Python (docs/control.md): Builder.body's armature, gear,
friction, effort and velocity limits and stop are the JSON fields, and femdyn.simulate reports
saturations, velocity excesses and limit crossings."""
import json
import math

import numpy as np
import pytest

import femdyn


def arm(**joint):
    """1 kg at 1 m about z: 1 kg·m² about the joint, no gravity."""
    b = femdyn.Builder("arm", gravity=[0, 0, 0])
    b.body("link", "world", type="revolute", joint="j", axis=[0, 0, 1], **joint)
    b.lumped_point("link", [1, 0, 0], 1.0)
    return b.build()


def test_builder_armature_equals_the_json_field(tmp_path):
    built = arm(armature=0.01, gear=10, friction=0.3, friction_velocity=0.05)
    doc = {"name": "arm", "gravity": [0, 0, 0], "bodies": [
        {"name": "link", "parent": "world",
         "joint": {"name": "j", "type": "revolute", "axis": [0, 0, 1], "armature": 0.01,
                   "gear": 10, "friction": 0.3, "friction_velocity": 0.05},
         "elements": [{"type": "lumped_point", "node": [1, 0, 0], "mass": 1.0}]}]}
    path = tmp_path / "arm.json"
    path.write_text(json.dumps(doc))
    loaded = femdyn.load(str(path))
    # M^s = 1 + I_a G² = 2 in both; the friction −0.3 tanh(θ̇ / 0.05) in q̈.
    assert built.mass_matrix([0.0])[0, 0] == pytest.approx(2.0, rel=1e-14)
    assert loaded.mass_matrix([0.0])[0, 0] == pytest.approx(2.0, rel=1e-14)
    for m in (built, loaded):
        qdd = m.forward_dynamics([0.0], [0.02])
        assert qdd[0] == pytest.approx(-0.3 * math.tanh(0.02 / 0.05) / 2.0, rel=1e-12)


def test_simulate_reports_saturation_and_velocity_limits():
    m = arm(effort_limit=2.0, velocity_limit=1.01, limits=(-1.0, 0.5))
    r = femdyn.simulate(m, 1.0, [0.0], [0.0], integrator="rk4", dt=0.01, tau=[5.0])
    s = r["stats"]
    # Saturated at 2: θ = t², θ̇ = 2t (rk4 is exact on it).
    assert r["q"][-1, 0] == pytest.approx(1.0, rel=1e-12)
    assert s["saturated_evaluations"] == s["rhs_evals"] >= 400
    assert s["saturated_steps"] == 100
    assert s["saturations"] == [
        {"coordinate": "j", "limit": 2.0, "evaluations": s["saturated_evaluations"]}]
    # θ̇ = 2t passes 1.01 at t = 0.505 (the step at 0.51 finds it); θ = t² passes 0.5 at 0.707.
    (v,) = s["velocity_excesses"]
    assert v["joint"] == "j" and v["limit"] == 1.01
    assert v["value"] == pytest.approx(1.02, abs=1e-9)
    assert v["t"] == pytest.approx(0.51, abs=1e-9)
    (c,) = s["limit_crossings"]
    assert c["joint"] == "j" and c["t"] == pytest.approx(0.71, abs=1e-9)
    assert abs(r["total"][-1] - r["total"][0] - r["work"][-1]) < 1e-9


def test_a_stop_holds_the_joint_near_its_limit():
    # Pushed at 1 N·m into a stop at 0.5 of k = 1e4, from the limit: it settles 1e-4 past it.
    m = arm(limits=(-1.0, 0.5), stop={"stiffness": 1e4, "dissipation": 5.0}, damping=50.0)
    r = femdyn.simulate(m, 3.0, [0.5], [0.0], tau=[1.0], rtol=1e-10, atol=1e-12)
    assert r["q"][-1, 0] == pytest.approx(0.5 + 1e-4, abs=1e-7)
    assert abs(r["total"][-1] - r["total"][0] - r["work"][-1]) < 1e-8


@pytest.mark.parametrize("argument,value,message", [
    ("armature", -1.0, "armature: must be finite and not negative"),
    ("gear", 0.0, "gear: must be finite and not zero"),
    ("friction", -0.1, "friction: must be finite and not negative"),
    ("effort_limit", 0.0, "effort_limit: must be positive"),
    ("stop", {"stiffness": 1.0}, "stop: a stop needs finite limits"),
])
def test_builder_bad_actuator_arguments(argument, value, message):
    with pytest.raises(femdyn.ModelError, match=rf"^arm \(builder\): /bodies/0/joint/{message}"):
        arm(**{argument: value})


def test_actuator_arguments_need_a_moving_joint():
    b = femdyn.Builder("arm")
    with pytest.raises(ValueError, match="a fixed joint has no motion"):
        b.body("link", "world", type="fixed", armature=0.1)
    with pytest.raises(ValueError, match="given without a joint type"):
        b.body("link", "world", friction=0.1)
    with pytest.raises(ValueError, match="stop: unknown key 'damping'"):
        b.body("link", "world", type="revolute", limits=(-1, 1), stop={"damping": 1.0})


def test_a_controllers_torque_is_saturated_and_recorded_as_applied():
    # A controller asking 5 N·m of a joint limited to 2: the run records the 2 it got, and the
    # motion is θ = t² (rk4 exact), as with a prescribed τ.
    m = arm(effort_limit=2.0)
    sim = femdyn.Simulator(m, integrator="rk4", dt=0.01, q0=[0.0], qd0=[0.0])
    r = sim.run(lambda t, q, qd: np.array([5.0]), 1.0)
    assert np.all(r["tau"] == 2.0)
    assert r["stats"]["saturated_evaluations"] == r["stats"]["rhs_evals"] >= 400
    assert r["q"][-1, 0] == pytest.approx(1.0, rel=1e-12)  # (m, n_q) even for n_q = 1


def test_a_ball_joint_rotor_is_the_same_from_the_builder_and_from_json(tmp_path):
    """armature on a spherical joint: I_a on each of its three rates, the same model whether the
    Builder or a JSON file says it (one compile check behind both); a free joint's adds
    I_a ω × v; a universal joint's is refused."""
    inertia = np.diag([0.01, 0.02, 0.03])
    b = femdyn.Builder("ball")
    b.body("l", type="spherical", armature=0.1)
    b.rigid_body("l", 1.0, [0.3, 0, 0], inertia)
    built = b.build()
    doc = {"name": "ball", "bodies": [{"name": "l", "parent": "world",
           "joint": {"name": "l", "type": "spherical", "armature": 0.1},
           "elements": [{"type": "rigid_body", "mass": 1.0, "com": [0.3, 0, 0],
                         "inertia": inertia.tolist()}]}]}
    path = tmp_path / "ball.json"
    path.write_text(json.dumps(doc))
    loaded = femdyn.load(str(path))
    q = np.array([0.9, 0.1, -0.3, 0.2])
    q /= np.linalg.norm(q)
    qd = np.array([0.4, -1.0, 0.7])
    a, c = built.equations(q, qd), loaded.equations(q, qd)
    assert np.array_equal(a.M, c.M) and np.array_equal(a.h, c.h)
    # M^s about the pivot plus I_a on each rate: diag(0.01, 0.02 + 0.09, 0.03 + 0.09) + 0.1
    plain = femdyn.Builder("plain")
    plain.body("l", type="spherical")
    plain.rigid_body("l", 1.0, [0.3, 0, 0], inertia)
    assert np.allclose(a.M - plain.build().equations(q, qd).M, 0.1 * np.eye(3), atol=1e-15)
    # A free joint's rotor: I_a on its six rates, and I_a ω × v in h on its linear rates (its
    # rates are in the body's axes), the same from the Builder and from JSON.
    free = femdyn.Builder("free")
    free.body("l", type="free", armature=0.1)
    free.rigid_body("l", 1.0, [0.3, 0, 0], inertia)
    bare = femdyn.Builder("bare")
    bare.body("l", type="free")
    bare.rigid_body("l", 1.0, [0.3, 0, 0], inertia)
    qf = np.array([0.1, -0.2, 0.3, *q])
    vf = np.array([0.5, -0.4, 0.9, *qd])
    a, c = free.build().equations(qf, vf), bare.build().equations(qf, vf)
    assert np.allclose(a.M - c.M, 0.1 * np.eye(6), atol=1e-15)
    expected = np.zeros(6)
    expected[:3] = 0.1 * np.cross(vf[3:], vf[:3])
    assert np.allclose(a.h - c.h, expected, rtol=0, atol=1e-14)
    with pytest.raises(femdyn.ModelError, match="a universal joint takes no armature"):
        u = femdyn.Builder("u")
        u.body("l", type="universal", axis=[1, 0, 0], axis2=[0, 1, 0], armature=0.1)
        u.rigid_body("l", 1.0, [0.3, 0, 0], inertia)
        u.build()
