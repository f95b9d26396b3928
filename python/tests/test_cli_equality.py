"""The module's numbers equal `femdyn equations --json --tensor` on every kind of model."""
import numpy as np
import pytest

import femdyn
from conftest import MODELS, cli_json, model_path, numbers, state


def close(a, b, rel=1e-14):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    assert a.shape == b.shape
    scale = max(1.0, float(np.max(np.abs(b)))) if b.size else 1.0
    assert float(np.max(np.abs(a - b), initial=0)) <= rel * scale


@pytest.mark.parametrize("name", MODELS)
def test_equations_equal_cli(name):
    model = femdyn.load(model_path(name))
    q, qd, tau = state(model.n, seed=7)
    cli = cli_json("equations", model_path(name), f"--q={numbers(q)}", f"--qd={numbers(qd)}",
                   f"--tau={numbers(tau)}", "--json", "--tensor")
    assert cli["coordinates"] == model.coordinates
    eq = model.equations(q, qd, tau)
    close(eq.M, cli["M"])
    close(eq.h, cli["h"])
    close(eq.Q, cli["Q"])
    close(eq.qdd, cli["qdd"])
    close(model.tensor(q), cli["D"])
    # the CLI prints round-trip precision and runs the same code: the numbers are the same
    assert np.array_equal(eq.M, np.array(cli["M"])) and np.array_equal(eq.qdd, cli["qdd"])


def test_gravity_override_equals_cli():
    name = model_path("models/urdf/arm7.urdf")
    model = femdyn.load(name, gravity=[0.5, -1.0, -3.0])
    assert np.array_equal(model.gravity, [0.5, -1.0, -3.0])
    q, qd, tau = state(model.n, seed=3)
    cli = cli_json("equations", name, "--gravity=0.5,-1,-3", f"--q={numbers(q)}",
                   f"--qd={numbers(qd)}", f"--tau={numbers(tau)}", "--json")
    eq = model.equations(q, qd, tau)
    close(eq.Q, cli["Q"])
    close(eq.qdd, cli["qdd"])


def test_omitted_arguments_are_zero():
    model = femdyn.load(model_path("models/finger.json"))
    q = np.full(model.n, 0.2)
    cli = cli_json("equations", model_path("models/finger.json"), f"--q={numbers(q)}", "--json")
    eq = model.equations(q)
    close(eq.h, cli["h"])
    close(eq.qdd, cli["qdd"])
    assert np.all(eq.h == 0)


def test_info_matches_cli():
    name = model_path("models/finger.json")
    model = femdyn.load(name)
    cli = cli_json("info", name, "--json")
    assert model.info() == cli
    table = model.correlation_table()
    assert [e["row"] for e in table] == cli["correlation_table"]
    assert all(len(e["row"]) == 6 * len(e["nodes"]) for e in table)
