"""Statics through every door (sim/statics.hpp): femdyn statics, Model.statics on a loaded file
and on a Builder's model give the same q to the bit; the sprung arm's closed form; no
equilibrium is femdyn.NumericalError naming the load factor reached."""
import json
import math

import numpy as np
import pytest

import femdyn
from conftest import cli_json, model_path

CANTILEVER = {"name": "cantilever", "bodies": [], "flexible_bars": [{
    "name": "beam", "parent": "world", "length": 2, "segments": 8, "torsion": False,
    "section": {"E": 2.07e11, "density": 7800, "area": 0.01, "Iy": 8.333333333333333e-6,
                "Iz": 8.333333333333333e-6}}]}
FORCE = -3 * 2.07e11 * 8.333333333333333e-6 / 4  # 3EI/L², transverse: a large deflection


def test_every_door_gives_the_same_rest(tmp_path):
    path = tmp_path / "cantilever.json"
    path.write_text(json.dumps(CANTILEVER))
    cli = cli_json("statics", str(path), "--load", f"beam.tip:0,{FORCE!r},0", "--json")
    loaded = femdyn.load(str(path)).statics(loads=[{"body": "beam.tip", "force": [0, FORCE, 0]}])
    b = femdyn.Builder("cantilever")
    bar = dict(CANTILEVER["flexible_bars"][0])
    b.flexible_bar(bar.pop("name"), bar.pop("parent"), **bar)
    built = b.build().statics(loads=[{"body": "beam.tip", "force": [0, FORCE, 0]}])
    assert np.array_equal(np.array(cli["q"]), loaded["q"])
    assert np.array_equal(loaded["q"], built["q"])
    tip = loaded["bodies"]["beam.tip"]
    # Gerstmayr & Irschik's converged tip (x, y) = (2 − 0.5085, −1.2072) m; 8 parts: 6.4e-3
    assert np.hypot(tip[0] - (2 - 0.508537304326), tip[1] + 1.207239854550) < 7e-3
    assert cli["bodies"]["beam.tip"] == pytest.approx(list(tip), abs=0)


def test_sprung_arm_closed_form(tmp_path):
    # 1 kg at 1 m, a spring k on its joint, gravity 9.81: k θ = m g l cos θ.
    k, g = 20.0, 9.81
    b = femdyn.Builder("arm", gravity=[0, 0, -g])
    b.body("arm", "world", type="revolute", joint="theta", axis=[0, 1, 0], stiffness=k)
    b.lumped_point("arm", [1, 0, 0], 1.0)
    theta = b.build().statics()["q"][0]
    assert k * theta == pytest.approx(g * math.cos(theta), rel=1e-12)


def test_no_equilibrium_is_a_numerical_error():
    b = femdyn.Builder("arm", gravity=[0, 0, -9.81])
    b.body("arm", "world", type="revolute", joint="theta", axis=[0, 1, 0])
    b.lumped_point("arm", [1, 0, 0], 1.0)
    with pytest.raises(femdyn.NumericalError, match=r"^no equilibrium found beyond load factor"):
        b.build().statics(tau=[20.0])
    with pytest.raises(ValueError, match=r"loads\[0\]: unknown key 'forse'"):
        b.build().statics(loads=[{"body": "arm", "forse": [0, 0, 1]}])


def test_check_lists_the_natural_modes_about_the_equilibrium(tmp_path):
    # The sprung arm (1 kg at 1 m, spring k, gravity g) rests at k θ = g cos θ; about it
    # ω² = k + g sin θ. And a cantilever's lowest modes are beam theory's (8 parts: 3.6e-3).
    k, g = 20.0, 9.81
    arm = {"name": "arm", "gravity": [0, 0, -g], "bodies": [{
        "name": "arm", "parent": "world",
        "joint": {"name": "theta", "type": "revolute", "axis": [0, 1, 0],
                  "spring": {"stiffness": k}},
        "elements": [{"type": "lumped_point", "node": [1, 0, 0], "mass": 1.0}]}]}
    path = tmp_path / "arm.json"
    path.write_text(json.dumps(arm))
    modes = cli_json("check", str(path), "--json")["natural_modes"]
    theta = femdyn.load(str(path)).statics()["q"][0]
    assert len(modes["oscillatory"]) == 1 and modes["unstable"] == 0
    assert modes["oscillatory"][0]["omega"] == pytest.approx(math.sqrt(k + g * math.sin(theta)),
                                                             rel=1e-9)
    path = tmp_path / "cantilever.json"
    path.write_text(json.dumps(dict(CANTILEVER, gravity=[0, 0, 0])))
    modes = cli_json("check", str(path), "--json")["natural_modes"]["oscillatory"]
    first = 1.8751040687119611 ** 2 * math.sqrt(2.07e11 * 8.333333333333333e-6 / (7800 * 0.01 * 16))
    assert modes[0]["omega"] == pytest.approx(first, rel=5e-3)
    assert modes[0]["omega"] != pytest.approx(first, rel=1e-3)  # (8 parts: not yet converged)
    assert modes[0]["coordinate"].startswith("beam.")


DRIVEN = {"name": "driven", "gravity": [0, -3, -9.81], "bodies": [
    {"name": "hub", "parent": "world",
     "joint": {"name": "hub", "type": "revolute", "axis": [0, 0, 1],
               "prescribed": {"polynomial": [0, 0.5, -0.3, 0.1]}},
     "elements": [{"type": "rigid_body", "mass": 2, "com": [0.1, 0, 0],
                   "inertia": {"ixx": 0.02, "iyy": 0.03, "izz": 0.04}}]},
    {"name": "arm", "parent": "hub",
     "joint": {"name": "swing", "type": "revolute", "axis": [0, 1, 0],
               "origin": {"xyz": [0.3, 0, 0]}},
     "elements": [{"type": "lumped_point", "node": [0.4, 0, 0], "mass": 1}]}]}


def test_a_driven_joint_through_the_python_doors(tmp_path):
    # femdyn.simulate holds the hub on q(t) = 0.5 t − 0.3 t² + 0.1 t³; statics refuses (a rest
    # has no time); validate compares pointwise and says why the trajectory is left out.
    path = tmp_path / "driven.json"
    path.write_text(json.dumps(DRIVEN))
    m = femdyn.load(str(path))
    run = femdyn.simulate(m, 1.0, q0=[0, 0.2], qd0=[0.5, 0], integrator="dopri", rtol=1e-10,
                          atol=1e-12)
    t = np.asarray(run["t"])
    assert np.abs(run["q"][:, 0] - (0.5 * t - 0.3 * t ** 2 + 0.1 * t ** 3)).max() < 1e-8
    hub = next(j for j in m.info()["joints"] if j["name"] == "hub")
    assert hub["prescribed"] == "q(t) = 0 + 0.5 t - 0.3 t^2 + 0.1 t^3"
    with pytest.raises(femdyn.ModelError, match="statics: joint 'hub' is prescribed in time"):
        m.statics()
    if femdyn.with_simbody:
        r = femdyn.validate(m, states=4, t_end=0.1)
        assert "prescribes joint 'hub'" in r["trajectory"]["skipped"]


def test_statics_on_closed_loops_is_the_commands():
    # The five-bar under gravity: the Python door and `femdyn statics --json` give the same rest
    # and constraint forces, and there the constrained dynamics has the mechanism at rest.
    path = model_path("models/five_bar.json")
    m = femdyn.load(path)
    r = m.statics()
    cli = cli_json("statics", path, "--json")
    assert np.allclose(r["q"], cli["q"], rtol=0, atol=1e-13)
    assert np.allclose(r["multipliers"], [x["mu"] for x in cli["multipliers"]], rtol=0, atol=1e-13)
    assert r["constraint_residual"] < 1e-12
    z = np.zeros(m.n)
    assert np.abs(m.equations(r["q"], z, z)["qdd"]).max() < 1e-9
