"""Bad input gets the documented messages and exceptions and never crashes the interpreter
(docs/python.md, "Errors")."""
import json

import numpy as np
import pytest

import femdyn
from conftest import model_path


@pytest.fixture(scope="module")
def finger():
    return femdyn.load(model_path("models/finger.json"))


def test_exception_classes():
    assert issubclass(femdyn.ModelError, ValueError)
    assert issubclass(femdyn.NumericalError, ArithmeticError)


@pytest.mark.parametrize("call,message", [
    (lambda m: m.equations([1, 2, 3]), "q: expected shape (4,), got (3,)"),
    (lambda m: m.equations(np.zeros(4), np.zeros(5)), "qd: expected shape (4,), got (5,)"),
    (lambda m: m.equations(np.zeros(4), None, np.zeros((4, 1))),
     "tau: expected shape (4,), got (4, 1)"),
    (lambda m: m.forward_dynamics(np.zeros((2, 4))), "q: expected shape (4,), got (2, 4)"),
    (lambda m: m.inverse_dynamics(np.zeros(4), np.zeros(4), np.zeros(2)),
     "qdd: expected shape (4,), got (2,)"),
    (lambda m: m.mass_matrix(np.zeros(())), "q: expected shape (4,), got ()"),
    (lambda m: m.tensor(np.zeros(3)), "q: expected shape (4,), got (3,)"),
    (lambda m: m.energy(np.zeros(4), np.zeros(3)), "qd: expected shape (4,), got (3,)"),
    (lambda m: m.equations_batch(np.zeros(4)), "q: expected shape (k, 4), got (4,)"),
    (lambda m: m.equations_batch(np.zeros((3, 4)), np.zeros((2, 4))),
     "qd: expected shape (3, 4), got (2, 4)"),
    (lambda m: m.forward_dynamics_batch(np.zeros((3, 4)), None, np.zeros((3, 5))),
     "tau: expected shape (3, 4), got (3, 5)"),
    (lambda m: m.inverse_dynamics_batch(np.zeros((3, 4)), None, np.zeros(3)),
     "qdd: expected shape (3, 4), got (3,)"),
    (lambda m: m.equations_batch(np.zeros((3, 4)), threads=-1),
     "threads: expected an integer in [0, 256], got -1"),
    (lambda m: m.equations([0, 0, np.nan, 0]), "q: entry 2 ('pip') is NaN or Inf"),
    (lambda m: m.forward_dynamics(np.zeros(4), [0, np.inf, 0, 0]),
     "qd: entry 1 ('mcp') is NaN or Inf"),
    (lambda m: m.equations_batch(np.array([[0, 0, 0, 0], [0, 0, 0, -np.inf]])),
     "q: row 1, entry 3 ('dip') is NaN or Inf"),
    (lambda m: femdyn.simulate(m, 0.1, q0=np.zeros(3)), "q0: expected shape (4,), got (3,)"),
    (lambda m: femdyn.simulate(m, 0.1, integrator="rk5"),
     "integrator: 'rk5' is not one of rk4, euler, dopri, bdf"),
    (lambda m: femdyn.simulate(m, 0.1, dt=1e-3),
     "dt sets the step of rk4 and euler; dopri is adaptive: use rtol and atol"),
    (lambda m: femdyn.simulate(m, 0.1, integrator="rk4", rtol=1e-6),
     "rtol/atol apply to dopri and bdf; rk4 has a fixed step: use dt"),
    (lambda m: femdyn.simulate(m, -1), "t_end expects a time in (0, 1e9] s"),
    (lambda m: femdyn.simulate(m, 1, t_eval=[0.5, 0.2]),
     "t_eval: expected nondecreasing times in [0, t_end]; entry 1 is not"),
    (lambda m: femdyn.load(model_path("models/finger.json"), gravity=[0, 0]),
     "gravity: expected shape (3,), got (2,)"),
])
def test_value_errors(finger, call, message):
    with pytest.raises(ValueError) as e:
        call(finger)
    assert str(e.value) == message
    assert not isinstance(e.value, femdyn.ModelError)


def test_bad_integrator_option(finger):
    with pytest.raises(ValueError, match="^dt"):
        femdyn.simulate(finger, 0.1, integrator="rk4", dt=-1)


def test_types_are_type_errors(finger):
    with pytest.raises(TypeError):
        finger.equations("abc")
    with pytest.raises(ValueError, match=r"^q: expected shape \(4,\), got \(\)$"):
        finger.equations(None)  # a 0-d array to numpy: q has no default
    with pytest.raises(TypeError):
        femdyn.load(42)


def test_model_errors_name_the_file_and_place(tmp_path):
    with pytest.raises(femdyn.ModelError, match="nope.json: cannot open file"):
        femdyn.load(str(tmp_path / "nope.json"))
    bad = tmp_path / "bad.json"
    bad.write_text("{ not json")
    with pytest.raises(femdyn.ModelError, match="bad.json"):
        femdyn.load(str(bad))
    doc = json.loads(open(model_path("models/pendulum.json")).read())
    doc["bodies"][0]["joint"]["type"] = "gearbox"
    bad.write_text(json.dumps(doc))
    with pytest.raises(femdyn.ModelError, match=r"bad.json: /bodies/0/joint"):
        femdyn.load(str(bad))
    with pytest.raises(femdyn.ModelError, match="is a directory"):
        femdyn.load(str(tmp_path))


def test_a_million_bodies_are_refused_by_count_before_parsing(tmp_path):
    # load() reads through the same JSON reader as the command line: one linear pass counts the
    # top-level "bodies" before anything is built (issue 22; the time is not asserted here).
    big = tmp_path / "million.json"
    big.write_text('{"bodies": [' + ",".join(['{"a":1}'] * 1_000_000) + "]}")
    with pytest.raises(femdyn.ModelError,
                       match=r"million.json: /bodies: 1000000 bodies: more than femdyn's "
                             r"limit of 200000$"):
        femdyn.load(str(big))


LIMIT = ("is out of range (|x| ≤ 1e100: beyond it the equations' products overflow double "
         "precision)")


def test_states_are_held_to_the_cli_limit(finger):
    """q, q̇ and q̈ are physical inputs like the CLI's --q and --qd: beyond 1e100 a ValueError
    before any work (issue 22: Python took q = 1e300), with the argument, row and entry named."""
    with pytest.raises(ValueError) as e:
        finger.equations(np.zeros(4), np.full(4, 1e200))
    assert str(e.value) == f"qd: entry 0 ('abduction') 1e+200 {LIMIT}"
    with pytest.raises(ValueError) as e:
        finger.equations(np.array([0, 1e300, 0, 0]))
    assert str(e.value) == f"q: entry 1 ('mcp') 1e+300 {LIMIT}"
    with pytest.raises(ValueError) as e:
        finger.forward_dynamics_batch(np.zeros((3, 4)), np.array([[0.0] * 4, [1e200] * 4,
                                                                 [0.0] * 4]))
    assert str(e.value) == f"qd: row 1, entry 0 ('abduction') 1e+200 {LIMIT}"
    with pytest.raises(ValueError, match=r"^qdd: row 0, entry 2 \('pip'\) -1e\+101 "):
        finger.inverse_dynamics_batch(np.zeros((1, 4)), None, [[0, 0, -1e101, 0]])
    with pytest.raises(ValueError, match=r"^q0: entry 0 \('abduction'\) 1e\+300 "):
        femdyn.simulate(finger, 0.1, q0=[1e300, 0, 0, 0])
    assert np.isfinite(finger.equations(np.zeros(4), np.full(4, 1e100)).h).all()


def test_failed_simulation(finger):
    with pytest.raises(femdyn.NumericalError):
        femdyn.simulate(finger, 1.0, integrator="euler", dt=0.5, qd0=np.full(4, 1e100))
    r = femdyn.simulate(finger, 1.0, integrator="euler", dt=0.5, qd0=np.full(4, 1e100),
                        check=False)
    assert not r["stats"]["ok"] and r["stats"]["failure"]
    assert len(r["t"]) >= 1 and np.isfinite(r["q"]).all()


@pytest.mark.parametrize("call,message", [
    (lambda m: m.equations(np.zeros(4), None, [0, 0, 1e200, 0]),
     f"tau: entry 2 ('pip') 1e+200 {LIMIT}"),
    (lambda m: m.forward_dynamics(np.zeros(4), None, [-1e101, 0, 0, 0]),
     f"tau: entry 0 ('abduction') -1e+101 {LIMIT}"),
    (lambda m: m.equations_batch(np.zeros((2, 4)), None, [[0, 0, 0, 0], [0, 1e300, 0, 0]]),
     f"tau: row 1, entry 1 ('mcp') 1e+300 {LIMIT}"),
    (lambda m: m.forward_dynamics_batch(np.zeros((2, 4)), None, [[0, 0, 0, 1e200], [0] * 4]),
     f"tau: row 0, entry 3 ('dip') 1e+200 {LIMIT}"),
    (lambda m: femdyn.simulate(m, 0.1, tau=[0, 0, 0, 1e200]),
     f"tau: entry 3 ('dip') 1e+200 {LIMIT}"),
    (lambda m: femdyn.simulate(m, 0.1, tau_t=[0, 1], tau=[[0] * 4, [0, 2e100, 0, 0]]),
     f"tau: row 1, entry 1 ('mcp') 2e+100 {LIMIT}"),
    (lambda m: femdyn.simulate(m, 0.1, tau_t=[0, 1e200], tau=[[0] * 4, [0] * 4]),
     f"tau_t: entry 1 1e+200 {LIMIT}"),
    (lambda m: femdyn.simulate(m, 0.1, tau_t=[0, 1], tau=[[0] * 4, [0, np.nan, 0, 0]]),
     "tau: row 1, entry 1 ('mcp') is NaN or Inf"),
])
def test_tau_is_held_to_the_physical_limit(finger, call, message):
    """τ is a physical input like the model's numbers and the CLI's --tau and --tau-csv: finite
    and |x| ≤ 1e100 (docs/robustness.md), with the argument, row, entry and value named."""
    with pytest.raises(ValueError) as e:
        call(finger)
    assert str(e.value) == message


def test_tau_at_the_limit_is_accepted(finger):
    """1e100 itself is within the limit, for τ as for the states."""
    tau = np.array([1e100, 0, 0, 0])
    assert np.isfinite(finger.equations(np.zeros(4), None, tau).Q).all()
    assert finger.forward_dynamics_batch(np.zeros((1, 4)), None, tau[None, :]).shape == (1, 4)


@pytest.mark.skipif(not femdyn.with_simbody, reason="built without Simbody")
def test_validate_refuses_work_beyond_its_budget_as_the_cli_does(tmp_path):
    """A 10,000-body chain is estimated before any state and refused at once with a ValueError
    whose message is the line `femdyn validate` prints (the estimates differ a little from run to
    run: the form is compared). The time is a generous guard, not a speed claim."""
    import re
    import subprocess
    import time

    from conftest import BINARY

    path = tmp_path / "chain10000.json"
    path.write_text(json.dumps({"model": "random_tree",
                                "params": {"seed": 3, "bodies": 10000, "branching": 0}}))
    chain = femdyn.load(str(path))
    start = time.monotonic()
    with pytest.raises(ValueError) as e:
        femdyn.validate(chain, budget=30)
    assert time.monotonic() - start < 60
    message = str(e.value)
    cli = subprocess.run([str(BINARY), "validate", str(path), "--budget", "30"],
                         capture_output=True, text=True)
    assert cli.returncode == 1 and cli.stdout == ""
    line = cli.stderr.strip()
    assert "\n" not in line and line.startswith("femdyn validate: ")
    numbers = re.compile(r"\d+(\.\d+)?(e[+-]?\d+)?( (s|min|h|days|kB|MB|GB))?")
    assert numbers.sub("#", message) == numbers.sub("#", line[len("femdyn validate: "):])
    assert message.startswith(f"{path}: validating n = 10000 coordinates would take ")
    assert "beyond the budget of 30 s: use --t-end 0 (t_end=0: no trajectory" in message
    assert "(budget=)" in message
    with pytest.raises(ValueError, match=r"^budget: expected a positive number of seconds"):
        femdyn.validate(chain, budget=0)
    with pytest.raises(ValueError, match=r"^max_memory: expected a positive number of GB"):
        femdyn.validate(chain, max_memory=-1.0)


@pytest.mark.skipif(not femdyn.with_simbody, reason="built without Simbody")
def test_validate_reports_its_work(finger):
    r = femdyn.validate(finger, states=2, t_end=0.01, samples=2, max_memory=1.0)
    assert r["pass"]
    w = r["work"]
    assert w["budget_s"] == 120 and w["memory_limit_bytes"] == 1e9
    assert w["mass_comparison"] == "entries"
    assert 0 < w["estimated_s"] and 0 < w["wall_time_s"]


@pytest.mark.skipif(not femdyn.with_simbody, reason="built without Simbody")
def test_validate_caps_t_end_as_the_cli_does(finger):
    """The trajectory limit is the CLI's --t-end limit (validation::kMaxTrajectoryTime), which
    `femdyn validate --t-end` reports in its own error; both refuse just above it."""
    import subprocess

    from conftest import BINARY

    cli = subprocess.run([str(BINARY), "validate", model_path("models/finger.json"),
                          "--t-end", "1000"], capture_output=True, text=True)
    assert cli.returncode == 2
    limit = cli.stderr.strip().rsplit("at most ", 1)[1].split(" s")[0]
    assert float(limit) == 100
    with pytest.raises(ValueError) as e:
        femdyn.validate(finger, states=1, t_end=float(limit) + 0.5)
    assert str(e.value).startswith(f"t_end: 100.5 is not a time in [0, {limit}] s")
    assert "femdyn validate --t-end" in str(e.value)
    for bad in (-1, np.inf, np.nan):
        with pytest.raises(ValueError, match=r"^t_end: .* is not a time in \[0, 100\] s"):
            femdyn.validate(finger, states=1, t_end=bad)


def test_divergence_is_a_failure_with_its_cause(tmp_path):
    """The issue's spring (omega = 10 rad/s) at rk4 dt = 1.5 s: never ok, the cause named."""
    spring = tmp_path / "spring10.json"
    spring.write_text(json.dumps({
        "name": "spring", "gravity": [0, 0, 0],
        "bodies": [{"name": "arm", "parent": "world",
                    "joint": {"name": "theta", "type": "revolute", "axis": [0, 1, 0],
                              "spring": {"stiffness": 100}},
                    "elements": [{"type": "lumped_point", "node": [1, 0, 0], "mass": 1.0}]}]}))
    m = femdyn.load(str(spring))
    with pytest.raises(femdyn.NumericalError, match="the solution diverges.*stability limit"):
        femdyn.simulate(m, 20.0, q0=[0.1], integrator="rk4", dt=1.5)
    r = femdyn.simulate(m, 20.0, q0=[0.1], integrator="rk4", dt=1.5, check=False)
    assert not r["stats"]["ok"] and r["stats"]["diverged"]
    assert np.isfinite(r["q"]).all() and r["stats"]["t_reached"] < 20
    # The same spring at a resolving step is ok, with its balance relative to the 0.5 J it holds.
    r = femdyn.simulate(m, 2.0, q0=[0.1], integrator="rk4", dt=0.01)
    assert r["stats"]["ok"] and not r["stats"]["diverged"]
    assert r["stats"]["energy_scale"] == pytest.approx(0.5)
    # RK4 shrinks |R(i h w)|^2 = 1 - (h w)^6/72 a step: 200 steps at h w = 0.1 lose that much.
    assert r["stats"]["energy_balance_relative"] == pytest.approx(200 * 0.1**6 / 72, rel=0.05)


def test_unbounded_work_is_refused_up_front(finger):
    with pytest.raises(ValueError, match="below the resolution of the time"):
        femdyn.simulate(finger, 1.0, integrator="rk4", dt=1e-300)
    with pytest.raises(ValueError, match=r"1e\+09 steps.*max_steps"):
        femdyn.simulate(finger, 1e6, integrator="euler", dt=1e-3)
    r = femdyn.simulate(finger, 0.01, integrator="rk4", dt=1e-6, max_steps=20000, every=1000)
    assert r["stats"]["ok"] and r["stats"]["steps"] == 10000
    with pytest.raises(ValueError, match="max_steps"):
        femdyn.simulate(finger, 0.01, integrator="rk4", dt=1e-3, max_steps=0)


def test_limit_crossings_are_reported(finger):
    # The finger's joints have limits; started beyond the flexion range's end at speed.
    r = femdyn.simulate(finger, 0.5, q0=[0, 0, 0, 0], qd0=[0, 20, 20, 20])
    crossings = r["stats"]["limit_crossings"]
    assert crossings, "the finger flexed at 20 rad/s leaves its limits"
    names = [c["joint"] for c in crossings]
    assert len(names) == len(set(names))  # once per joint
    for c in crossings:
        assert not (c["lower"] <= c["value"] <= c["upper"])
