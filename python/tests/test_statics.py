"""Statics through every door (sim/statics.hpp): femdyn statics, Model.statics on a loaded file
and on a Builder's model give the same q to the bit; the sprung arm's closed form; no
equilibrium is femdyn.NumericalError naming the load factor reached."""
import json
import math

import numpy as np
import pytest

import femdyn
from conftest import cli_json

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
