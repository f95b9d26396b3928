"""simulate equals `femdyn simulate` (statistics and the trajectory file); validate equals
`femdyn validate --json`."""
import csv

import numpy as np
import pytest

import femdyn
from conftest import cli_json, model_path, numbers


@pytest.mark.parametrize("integrator,opts", [("rk4", ["--dt=0.002"]), ("euler", ["--dt=0.001"]),
                                             ("dopri", ["--rtol=1e-8", "--atol=1e-10"]),
                                             ("bdf", [])])
def test_simulate_equals_cli(tmp_path, integrator, opts):
    name = model_path("models/finger.json")
    model = femdyn.load(name)
    q0, qd0, tau = np.array([0.1, 0.5, 0.6, 0.5]), np.array([0.5, 1, 1, 1]), np.full(4, 1e-3)
    out = tmp_path / "traj.csv"
    cli = cli_json("simulate", name, "--t-end=0.05", f"--integrator={integrator}", *opts,
                   f"--q0={numbers(q0)}", f"--qd0={numbers(qd0)}", f"--tau={numbers(tau)}",
                   f"--out={out}", "--json")
    kw = {k[2:].split("=")[0]: float(k.split("=")[1]) for k in opts}
    r = femdyn.simulate(model, 0.05, q0, qd0, integrator=integrator, tau=tau, **kw)
    s = r["stats"]
    for key in ["steps", "rejected", "rhs_evals", "jac_evals", "t_reached", "conservative"]:
        assert s[key] == cli[key], key
    assert s["energy_balance_error"] == pytest.approx(cli["energy_balance_error"], rel=1e-12,
                                                      abs=1e-300)
    rows = list(csv.reader(open(out)))
    data = np.array([[float(x) for x in row] for row in rows[1:]])
    n = model.n
    assert rows[0][1] == "q_abduction"
    assert data.shape[0] == len(r["t"])
    assert np.array_equal(data[:, 0], r["t"])
    assert np.array_equal(data[:, 1:1 + n], r["q"])
    assert np.array_equal(data[:, 1 + n:1 + 2 * n], r["qd"])
    assert np.array_equal(data[:, -1], r["work"])


@pytest.mark.parametrize("integrator", ["rk4", "dopri"])
def test_sampled_tau_equals_cli_tau_csv(tmp_path, integrator):
    name = model_path("models/urdf/arm7.urdf")
    model = femdyn.load(name)
    tau_t = np.linspace(0, 0.1, 7)
    tau = np.outer(np.sin(40 * tau_t), np.linspace(1, 2, model.n))
    table = tmp_path / "tau.csv"
    with open(table, "w") as f:
        f.write(",".join(["t"] + model.coordinates) + "\n")
        for t, row in zip(tau_t, tau):
            f.write(numbers([t, *row]) + "\n")
    out = tmp_path / "traj.csv"
    cli = cli_json("simulate", name, "--t-end=0.1", f"--integrator={integrator}",
                   f"--tau-csv={table}", f"--out={out}", "--json")
    r = femdyn.simulate(model, 0.1, integrator=integrator, tau=tau, tau_t=tau_t)
    assert r["stats"]["steps"] == cli["steps"] and not r["stats"]["conservative"]
    data = np.array([[float(x) for x in row] for row in list(csv.reader(open(out)))[1:]])
    assert np.array_equal(data[:, 1:1 + model.n], r["q"])
    assert np.array_equal(data[:, -1], r["work"])
    with pytest.raises(ValueError, match=r"^tau_t covers t in \[0, 0.1\] s; it must cover "
                                         r"\[0, 0.2\] s$"):
        femdyn.simulate(model, 0.2, integrator=integrator, tau=tau, tau_t=tau_t)
    with pytest.raises(ValueError, match=r"^tau: expected shape \(7, 7\) with tau_t, got "
                                         r"\(7, 6\)$"):
        femdyn.simulate(model, 0.1, tau=tau[:, 1:], tau_t=tau_t)


def test_simulate_outputs():
    model = femdyn.load(model_path("models/pendulum.json"))
    r = femdyn.simulate(model, 1.0, q0=[0.3], integrator="rk4", dt=1e-3, every=10)
    assert r["t"][0] == 0 and r["t"][-1] == 1.0 and len(r["t"]) == 101
    assert r["q"].shape == (101, 1) and r["qd"].shape == (101, 1)
    drift = np.abs(r["total"] - r["total"][0]).max()
    assert drift < 1e-9 and r["stats"]["conservative"]
    te = np.linspace(0, 1, 11)
    d = femdyn.simulate(model, 1.0, q0=[0.3], rtol=1e-10, atol=1e-12, t_eval=te)
    assert np.array_equal(d["t"], te)
    # the small-angle period of a 1 m pendulum is 2 s: at t = 1 s it is near -0.3
    assert d["q"][-1, 0] == pytest.approx(-0.3, abs=0.01)
    assert np.abs(d["q"][-1] - r["q"][-1]).max() < 1e-8


@pytest.mark.skipif(not femdyn.with_simbody, reason="built without Simbody")
@pytest.mark.parametrize("name", ["models/finger.json", "models/branched_tree.json",
                                  "models/urdf/arm7.urdf"])
def test_validate_equals_cli(name):
    model = femdyn.load(model_path(name))
    r = femdyn.validate(model, states=4, t_end=0.02, samples=5)
    cli = cli_json("validate", model_path(name), "--states=4", "--t-end=0.02", "--json")
    assert r["pass"] and r["failure"] == ""
    for q, v in r["quantities"].items():
        assert v["pass"] and v["max_rel"] <= 1e-10
        assert v["max_rel"] == cli["max_rel_error"][q], q
    assert r["trajectory"]["run"] and r["trajectory"]["pass"]


@pytest.mark.skipif(not femdyn.with_simbody, reason="built without Simbody")
def test_validate_not_compared_equals_cli(tmp_path):
    # A massless link with a rotary inertia: Simbody cannot hold it, so neither door compares,
    # both say why in the same words, and neither calls it a pass (the CLI exits 3).
    import json
    import subprocess
    from conftest import BINARY
    path = tmp_path / "rotor.urdf"
    inertial = ('<inertial><origin xyz="{c}"/><mass value="{m}"/><inertia ixx="{i}" iyy="{i}" '
                'izz="{i}" ixy="0" ixz="0" iyz="0"/></inertial>')
    path.write_text(
        '<robot name="r"><link name="base"/><link name="arm">'
        + inertial.format(c="0.1 0 0", m=1, i=0.01) + '</link><link name="rotor">'
        + inertial.format(c="0 0 0", m=0, i=1e-4) + '</link>'
        '<joint name="j" type="revolute"><parent link="base"/><child link="arm"/>'
        '<axis xyz="0 0 1"/></joint><joint name="spin" type="revolute"><parent link="arm"/>'
        '<child link="rotor"/><origin xyz="0.2 0 0"/><axis xyz="0 0 1"/></joint></robot>')
    r = femdyn.validate(femdyn.load(str(path)), states=2, t_end=0)
    out = subprocess.run([str(BINARY), "validate", str(path), "--states=2", "--t-end=0", "--json"],
                         capture_output=True, text=True)
    cli = json.loads(out.stdout)
    assert out.returncode == 3
    assert r["compared"] is False and cli["compared"] is False
    assert r["pass"] is False and cli["pass"] is False
    assert r["failure"] == cli["failure"] and "rotary inertia but no mass" in r["failure"]


@pytest.mark.skipif(not femdyn.with_simbody, reason="built without Simbody")
def test_sundials_does_not_shadow_simbody_cpodes():
    """femdyn's SUNDIALS is linked into the extension statically with its symbols hidden: in the
    interpreter too, Simbody's CPodes (its own SUNDIALS copy) stays usable, beside femdyn's
    SUNDIALS integrators."""
    from femdyn import _femdyn

    assert "CPodes" in _femdyn._simbody_integrators()
    model = femdyn.load(model_path("models/finger.json"))
    assert femdyn.simulate(model, 0.01, qd0=np.ones(4), integrator="bdf")["stats"]["ok"]
    assert femdyn.validate(model, states=2, t_end=0.01, samples=2)["pass"]
