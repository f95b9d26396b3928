"""One truth (docs/robustness.md#one-truth): the same model and state give the same answer from
every call, or a clear refusal."""
import numpy as np
import pytest

import femdyn
from conftest import ROOT, cli_json, model_path, numbers


def rel(a, b):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return float(np.max(np.abs(a - b)) / max(1e-300, float(np.max(np.abs(b)))))


@pytest.mark.parametrize("name", ["models/space_robot.json", "models/urdf/arm7.urdf"])
def test_mass_matrix_and_bias_take_the_configuration(name):
    """mass_matrix(q) and bias(q, qd) take q (n_q, quaternions) as every other call does, and give
    equations()'s M and h."""
    m = femdyn.load(model_path(name), floating_base=name.endswith(".urdf"))
    rng = np.random.default_rng(43)
    q = m.neutral_configuration()
    q[:3] = rng.uniform(-1, 1, 3)
    if m.n_q != m.n:  # a quaternion: a random unit one
        w = rng.normal(size=4)
        q[3:7] = w / np.linalg.norm(w)
    q[m.n_q - m.n + 6:] += rng.uniform(-0.5, 0.5, m.n - 6)
    qd = rng.uniform(-1, 1, m.n)
    eq = m.equations(q, qd)
    assert np.array_equal(m.mass_matrix(q), eq.M)
    assert np.array_equal(m.bias(q, qd), eq.h)
    with pytest.raises(ValueError, match=rf"q: expected shape \({m.n_q},\)"):
        m.mass_matrix(q[:m.n])
    with pytest.raises(ValueError, match=rf"q: expected shape \({m.n_q},\)"):
        m.bias(q[:m.n], qd)


def test_builder_refuses_an_axis_on_a_ball_or_free_joint():
    for kind in ("spherical", "free"):
        b = femdyn.Builder("x")
        with pytest.raises(ValueError, match="takes no axis"):
            b.body("l", type=kind, axis=[0, 0, 1])


def closed_chain():
    """A planar 2-link chain whose tip is held on the world by a ball (in the plane): a four-bar
    with the ground as its fourth bar, driven at both joints."""
    b = femdyn.Builder("held")
    b.body("l1", type="revolute", axis=[0, 0, 1])
    b.rigid_body("l1", 1.0, [0.5, 0, 0], np.diag([0.01, 0.1, 0.1]))
    b.body("l2", "l1", type="revolute", axis=[0, 0, 1], xyz=[1, 0, 0])
    b.rigid_body("l2", 1.0, [0.5, 0, 0], np.diag([0.01, 0.1, 0.1]))
    b.body("l3", "l2", type="revolute", axis=[0, 0, 1], xyz=[1, 0, 0])
    b.rigid_body("l3", 1.0, [0.5, 0, 0], np.diag([0.01, 0.1, 0.1]))
    b.constraint("ball", name="tip", a={"body": "l3", "xyz": [1, 0, 0]},
                 b={"body": "world", "xyz": [2.2, 0.9, 0]}, normal=[0, 0, 1])
    return b.build()


def test_every_door_gives_the_closed_mechanism_its_own_qdd():
    m = closed_chain()
    s = m.assemble(np.array([0.9, -0.8, -0.6]), np.array([0.7, 0.0, 0.0]))
    q, qd, tau = s["q"], s["qd"], np.array([0.2, -0.1, 0.3])
    ref = m.constrained_dynamics(q, qd, tau)
    assert np.array_equal(m.forward_dynamics(q, qd, tau), ref["qdd"])
    assert np.array_equal(m.equations(q, qd, tau).qdd, ref["qdd"])
    batch = m.forward_dynamics_batch(np.stack([q, q]), np.stack([qd, qd]), np.stack([tau, tau]))
    assert np.array_equal(batch[0], ref["qdd"]) and np.array_equal(batch[1], ref["qdd"])
    eqb = m.equations_batch(np.stack([q]), np.stack([qd]), np.stack([tau]))
    assert np.array_equal(eqb["qdd"][0], ref["qdd"])
    # The tip stays held: Φ_q q̈ + Φ̇_q q̇ = 0.
    k = m.constraint_kinematics(q, qd)
    assert np.abs(k["J"] @ ref["qdd"] + k["bias"]).max() < 1e-10
    # Off the loops: refused, naming the constraint.
    with pytest.raises(femdyn.NumericalError, match="does not close the loops.*tip"):
        m.forward_dynamics(q + 0.1, qd, tau)
    assert m.equations(q + 0.1, qd, tau).qdd is None
    # Inverse dynamics: τ is not unique on a closed mechanism; the tree's on request.
    with pytest.raises(femdyn.ModelError, match="closed loops"):
        m.inverse_dynamics(q, qd, ref["qdd"])
    with pytest.raises(femdyn.ModelError, match="closed loops"):
        m.inverse_dynamics_batch(np.stack([q]), np.stack([qd]), np.stack([ref["qdd"]]))
    back = m.inverse_dynamics(q, qd, ref["qdd"], tree=True)
    assert rel(back, tau + ref["constraint_forces"]) < 1e-10


def test_the_cli_and_the_module_agree_on_a_closed_mechanism(tmp_path):
    path = model_path("models/five_bar.json")
    m = femdyn.load(path)
    cli = cli_json("equations", path, "--json")  # the neutral configuration, assembled
    q, qd = np.array(cli["q"]), np.array(cli["qd"])
    assert np.abs(m.constraint_kinematics(q)["phi"]).max() < 1e-10
    eq = m.equations(q, qd)
    assert np.array_equal(eq.M, np.array(cli["M"])) and np.array_equal(eq.qdd, cli["qdd"])
    r = m.constrained_dynamics(q, qd)
    assert np.array_equal(r["lambda"], cli["lambda"])
    again = cli_json("equations", path, f"--q={numbers(q)}", f"--qd={numbers(qd)}", "--json")
    assert np.array_equal(again["qdd"], cli["qdd"])


@pytest.mark.parametrize("name", ["models/five_bar.json", "models/space_robot.json",
                                  "models/finger.json", "models/iftomm_a04_bricard.json"])
def test_linearize_is_one_answer_at_every_door(name):
    """femdyn linearize --json, Model.linearize and linearize_batch give the same A and B bit for
    bit, at the state as given (off a closed loop: the stabilised equations there), and the CLI
    without --q at the state it prints (the neutral configuration, assembled onto the loops)."""
    path = model_path(name)
    m = femdyn.load(path)
    cli = cli_json("linearize", path, "--json")
    q, qd = np.array(cli["q"]), np.array(cli["qd"])
    A, B = m.linearize(q, qd)
    assert np.array_equal(A, cli["A"]) and np.array_equal(B, np.array(cli["B"]).reshape(B.shape))
    rng = np.random.default_rng(43)
    q = q.copy()
    q[-1] += 0.01  # (off the loops of a closed mechanism; a quaternion's last entry stays close)
    if m.n_q != m.n:
        q[3:7] /= np.linalg.norm(q[3:7])
    qd, tau = rng.uniform(-0.3, 0.3, m.n), rng.uniform(-0.1, 0.1, m.n)
    if len(m.actuated) < m.n:
        tau[[i for i in range(m.n) if i not in m.actuated]] = 0
    cli = cli_json("linearize", path, f"--q={numbers(q)}", f"--qd={numbers(qd)}",
                   f"--tau={numbers(tau)}", "--json")
    assert np.array_equal(cli["q"], q)
    A, B = m.linearize(q, qd, tau)
    Ab, Bb = m.linearize_batch(np.stack([q, q]), np.stack([qd, qd]), np.stack([tau, tau]))
    assert np.array_equal(A, cli["A"]) and np.array_equal(B, np.array(cli["B"]).reshape(B.shape))
    assert np.array_equal(Ab[1], A) and np.array_equal(Bb[0], B)


def test_simulator_run_reports_what_simulate_reports():
    """Simulator.run's stats carry simulate's run summary: the energy balance, limit crossings,
    velocity excesses and effort saturations (one RecordedRun for both, sim/recorded_run.hpp)."""
    arm = femdyn.load(model_path("models/urdf/arm7.urdf"))
    push = np.zeros(arm.n)
    push[1] = 400.0  # far beyond the joint's effort limit (100 N m): saturated at it
    sim = femdyn.Simulator(arm, integrator="rk4", dt=1e-3)
    r = sim.run(lambda t, q, qd: push, 0.5)
    s = r["stats"]
    ref = femdyn.simulate(arm, 0.5, integrator="rk4", dt=1e-3, tau=push)["stats"]
    for key in ("energy_balance_relative", "energy_initial", "limit_crossings",
                "velocity_excesses", "saturations", "saturated_evaluations", "saturated_steps",
                "unapplied_effort_limits"):
        assert key in s, key
    # The same motion: a held constant τ is simulate's constant τ.
    assert [e["joint"] for e in s["velocity_excesses"]] == \
        [e["joint"] for e in ref["velocity_excesses"]]
    assert s["velocity_excesses"] and s["velocity_excesses"][0]["limit"] == 1.7
    assert s["saturations"][0]["evaluations"] == ref["saturations"][0]["evaluations"]
    assert [c["joint"] for c in s["limit_crossings"]] == [c["joint"] for c in ref["limit_crossings"]]
    # The energy balance over the same rows (a row a period, a step a period): the same figure.
    assert s["energy_balance_relative"] == pytest.approx(ref["energy_balance_relative"], rel=1e-6)
    # A second run counts its own saturations only.
    s2 = sim.run(lambda t, q, qd: np.zeros(arm.n), 0.6)["stats"]
    assert s2["saturated_evaluations"] == 0 and s2["saturations"] == []


def test_simulator_run_on_closed_loops_reports_the_residuals():
    m = closed_chain()
    s = m.assemble(np.array([0.9, -0.8, -0.6]))
    sim = femdyn.Simulator(m, integrator="rk4", dt=1e-3, q0=s["q"])
    st = sim.run(lambda t, q, qd: np.zeros(m.n), 0.2)["stats"]
    assert st["ok"] and st["loops"]["max_position_residual"] < 1e-6 and st["loops"]["max_velocity_residual"] < 1e-6


def test_a_diverging_controller_is_named_and_a_huge_tau_refused():
    """A run that a controller drives to divergence names the controller's largest output (the
    suspect); a τ beyond ±1e100, the bound of --tau and of every physical input, is refused."""
    finger = femdyn.load(model_path("models/finger.json"))
    q0 = np.array([0.1, 0.4, 0.3, 0.2])
    sim = femdyn.Simulator(finger, dt=1e-3, q0=q0)
    with pytest.raises(femdyn.NumericalError,
                       match=r"diverges.*controller's largest output in this run: tau of '\w+'"):
        sim.run(lambda t, q, qd: -1e4 * q, 1.0)
    sim.reset(q0)
    with pytest.raises(ValueError, match=r"tau of 'abduction' 1e\+200 is out of range"):
        sim.run(lambda t, q, qd: np.array([1e200, 0, 0, 0]), 0.1)
    with pytest.raises(ValueError, match=r"tau: entry 2 \('pip'\) 1e\+101 is out of range"):
        sim.step(np.array([0, 0, 1e101, 0]))


# femdyn simulate and femdyn.simulate are one request (sim/simulation_request.hpp): the same
# runs give the same report, field for field, and break the same rules with the same words.
SIMULATIONS = [
    ("models/pendulum.json", ["--q0=0.4"], {"q0": [0.4]}),
    ("models/finger.json", ["--integrator=rk4", "--dt=2e-3", "--tau=0.1,0,-0.05,0", "--every=7"],
     {"integrator": "rk4", "dt": 2e-3, "tau": [0.1, 0, -0.05, 0], "every": 7}),
    ("models/five_bar.json", ["--baumgarte=35", "--q0=2.2,-1.15,1.05,1.2", "--rtol=1e-8"],
     {"baumgarte": 35, "q0": [2.2, -1.15, 1.05, 1.2], "rtol": 1e-8}),
    ("models/space_robot.json", ["--integrator=bdf"], {"integrator": "bdf"}),
]
TIMES = {"wall_time", "integration_time", "real_time_factor"}


@pytest.mark.parametrize("name,args,kwargs", SIMULATIONS)
def test_simulate_reports_equal_the_cli(name, args, kwargs):
    model = femdyn.load(model_path(name))
    cli = cli_json("simulate", model_path(name), "--t-end=0.3", "--json", *args)
    stats = femdyn.simulate(model, 0.3, **kwargs)["stats"]
    assert set(stats) == set(cli)
    for key in set(cli) - TIMES:
        assert stats[key] == cli[key], key
    assert stats["ok"] and stats["rows"] > 2
    if name == "models/five_bar.json":  # the start was off the loops, and assembled
        assert stats["loops"]["assembly_iterations"] > 0 and stats["loops"]["baumgarte"] == 35


@pytest.mark.parametrize("name", ["models/five_bar.json", "models/finger_fourbar.json",
                                  "models/space_robot.json", "models/finger_paper.json"])
def test_every_door_names_the_same_routes(name):
    """Model.routes, info --json, equations --json and a run's report name the same algorithms;
    the closed loops' constrained q̈ is named where the model has loops."""
    m = femdyn.load(model_path(name))
    routes = m.routes
    assert {"mass", "force", "forward_dynamics"} <= set(routes)
    assert ("loops" in routes) == bool(m.constraints)
    assert cli_json("info", model_path(name), "--json")["routes"] == routes
    assert cli_json("equations", model_path(name), "--json")["routes"] == routes
    assert femdyn.simulate(m, 0.01)["stats"]["routes"] == routes


def cli_error(*args):
    from conftest import BINARY, ROOT
    import subprocess
    out = subprocess.run([str(BINARY), *map(str, args)], cwd=ROOT, capture_output=True, text=True)
    assert out.returncode != 0
    return out.stderr.strip().removeprefix("femdyn simulate: ")


# (CLI arguments, Python arguments): each breaks one rule of the request.
BROKEN = [
    (["--t-end=-1"], {"t_end": -1}),
    (["--integrator=rk5"], {"integrator": "rk5"}),
    (["--dt=1e-3"], {"dt": 1e-3}),
    (["--integrator=rk4", "--rtol=1e-6"], {"integrator": "rk4", "rtol": 1e-6}),
    (["--integrator=rk4", "--dt=-1"], {"integrator": "rk4", "dt": -1}),
    (["--rtol=2"], {"rtol": 2}),
    (["--baumgarte=3"], {"baumgarte": 3}),
    (["--max-steps=0.5"], {"max_steps": 0.5}),
    (["--every=0"], {"every": 0}),
]


@pytest.mark.parametrize("cli_args,kwargs", BROKEN)
def test_simulate_refuses_as_the_cli(cli_args, kwargs):
    path = model_path("models/finger.json")
    model = femdyn.load(path)
    args = {"t_end": 0.1, **kwargs}
    with pytest.raises(ValueError) as e:
        femdyn.simulate(model, **args)
    cli = cli_error("simulate", path, *(["--t-end=0.1"] if "t_end" not in kwargs else []),
                    *cli_args)
    spelled = str(e.value)
    for name in ("t_end", "max_steps", "integrator", "baumgarte", "every", "rtol", "atol", "dt"):
        spelled = spelled.replace(name, "--" + name.replace("_", "-"))
    assert cli.endswith(spelled), (cli, str(e.value))


def test_check_promises_the_error_over_the_run_asked_for(tmp_path):
    """femdyn check --t-end T measures its recommended rk4 step over T: `femdyn simulate` at that
    step then errs by what check promised (against dopri at 1e-10, at the same 21 times). The
    five-bar's 3-period trial (1.8 s) promises 2e-3 at 3 s and the run errs by 1.2: without
    --t-end, check says which horizon its number holds over."""
    from conftest import BINARY, ROOT
    import subprocess
    path = model_path("models/five_bar.json")
    out = tmp_path / "t.csv"

    def trajectory(*args):
        subprocess.run([str(BINARY), "simulate", path, "--t-end=3", "--sample-dt=0.15",
                        f"--out={out}", "--force", *args], cwd=ROOT, check=True,
                       capture_output=True)
        return np.loadtxt(out, delimiter=",", skiprows=1)[:, 1:9]

    reference = trajectory("--rtol=1e-10", "--atol=1e-10")
    advice = cli_json("check", path, "--json", "--t-end=3")["recommended"]
    assert advice["integrator"] == "rk4" and advice["trial"]["horizon"] == 3
    x = trajectory("--integrator=rk4", f"--dt={advice['rk4_dt']!r}")
    error = np.max(np.abs(x - reference)) / max(1, np.max(np.abs(reference)))
    assert error <= 1.01 * advice["trial"]["error"]
    text = subprocess.run([str(BINARY), "check", path], cwd=ROOT, capture_output=True,
                          text=True).stdout
    assert "the promise holds over that horizon" in text


def test_loads_is_load_of_the_same_text(tmp_path):
    # femdyn.loads(text) and femdyn.load(path) of the same document are one model: the same
    # coordinates and info, the same equations to the bit at random states, gravity overridden
    # alike; a bad document names the `name` given and the JSON path.
    text = (ROOT / "models" / "flexible_space_robot.json").read_text()
    path = tmp_path / "robot.json"
    path.write_text(text)
    for gravity in (None, [0.0, -9.81, 0.0]):
        a, b = femdyn.load(str(path), gravity=gravity), femdyn.loads(text, gravity=gravity)
        assert a.coordinates == b.coordinates and a.info() == b.info()
        rng = np.random.default_rng(2)
        for _ in range(3):
            q = a.neutral_configuration()
            q[7:] += rng.uniform(-0.05, 0.05, a.n_q - 7)
            qd, tau = rng.uniform(-1, 1, a.n), np.zeros(a.n)
            ea, eb = a.equations(q, qd, tau), b.equations(q, qd, tau)
            for key in ("M", "h", "Q", "qdd"):
                assert np.array_equal(ea[key], eb[key]), key
    with pytest.raises(femdyn.ModelError, match=r"^mine: /bodies: expected an array"):
        femdyn.loads('{"name": "x", "bodies": 3}', name="mine")
