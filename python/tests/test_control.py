"""femdyn.Simulator, the controller in the loop (docs/control.md), and the two control examples."""
import os
import signal
import subprocess
import sys
import threading

import numpy as np
import pytest

import femdyn
from conftest import ROOT, model_path, subprocess_env

sys.path.insert(0, str(ROOT / "examples"))
import control_computed_torque  # noqa: E402
import control_space_robot  # noqa: E402
import control_task_space  # noqa: E402


@pytest.fixture(scope="module")
def finger():
    return femdyn.load(model_path("models/finger.json"))


Q0 = np.array([0.1, 0.4, 0.3, 0.2])
QD0 = np.array([1.0, -0.5, 0.2, 0.3])
TAU = np.array([0.002, -0.001, 0.0015, 0.0005])


def test_step_holds_tau_as_simulate_does(finger):
    sim = femdyn.Simulator(finger, integrator="rk4", dt=1e-3, q0=Q0, qd0=QD0)
    for _ in range(200):
        sim.step(TAU)
    ref = femdyn.simulate(finger, 0.2, q0=Q0, qd0=QD0, integrator="rk4", dt=1e-3, tau=TAU)
    s = sim.state
    assert s["t"] == pytest.approx(0.2, abs=1e-12) and sim.t == s["t"]
    np.testing.assert_allclose(s["q"], ref["q"][-1], rtol=0, atol=1e-13)
    np.testing.assert_allclose(s["qd"], ref["qd"][-1], rtol=0, atol=1e-12)
    assert s["work"] == pytest.approx(ref["work"][-1], abs=1e-15)
    sim.reset(Q0, t=1.0)
    assert sim.state["t"] == 1.0 and np.all(sim.state["qd"] == 0)
    np.testing.assert_array_equal(sim.state["q"], Q0)


@pytest.mark.parametrize("mode", ["hold", "evaluation"])
def test_run_with_a_constant_controller_is_simulate(finger, mode):
    sim = femdyn.Simulator(finger, integrator="rk4", dt=1e-3, q0=Q0, qd0=QD0)
    r = sim.run(lambda t, q, qd: TAU, 0.1, mode=mode)
    ref = femdyn.simulate(finger, 0.1, q0=Q0, qd0=QD0, integrator="rk4", dt=1e-3, tau=TAU)
    assert r["t"].shape == (101,) and r["q"].shape == (101, 4) and r["tau"].shape == (101, 4)
    np.testing.assert_allclose(r["t"], ref["t"], atol=1e-12)
    np.testing.assert_allclose(r["q"], ref["q"], rtol=0, atol=1e-13)
    np.testing.assert_allclose(r["work"], ref["work"], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(r["tau"], np.tile(TAU, (101, 1)))
    s = r["stats"]
    assert s["ok"] and s["periods"] == 100 and s["steps"] == 100
    # hold: one call a period; evaluation: four a step (rk4) and one a row
    assert s["controller_calls"] == (100 if mode == "hold" else 4 * 100 + 100)


def test_zoh_samples_the_state_at_each_period(finger):
    seen = []

    def pd(t, q, qd):
        seen.append(t)
        return -1e-4 * q - 1e-6 * qd

    sim = femdyn.Simulator(finger, integrator="dopri", dt=0.01, rtol=1e-9, atol=1e-11, q0=Q0)
    r = sim.run(pd, 0.2)
    np.testing.assert_allclose(seen, np.arange(20) * 0.01, atol=1e-12)
    np.testing.assert_allclose(r["tau"][:-1], -1e-4 * r["q"][:-1] - 1e-6 * r["qd"][:-1])
    # E(t) - E(0) = W(t) with the controller's tau
    assert np.max(np.abs(r["total"] - r["total"][0] - r["work"])) < 1e-7 * np.max(np.abs(r["work"]))
    assert np.max(np.abs(r["work"])) > 0


def test_bad_controllers_are_named(finger):
    sim = femdyn.Simulator(finger, dt=1e-3, q0=Q0)
    with pytest.raises(ValueError, match=r"controller at t = 0 s: expected tau of shape \(4,\), "
                                         r"got \(3,\)"):
        sim.run(lambda t, q, qd: np.zeros(3), 0.01)
    with pytest.raises(ValueError, match=r"tau is NaN or Inf \(pip\)"):
        sim.run(lambda t, q, qd: np.array([0, 0, np.nan, 0]), 0.01)
    with pytest.raises(ValueError, match="expected tau, an array of shape"):
        sim.run(lambda t, q, qd: "up", 0.01)
    with pytest.raises(TypeError, match="callable"):
        sim.run(3, 0.01)
    with pytest.raises(ValueError, match="mode"):
        sim.run(lambda t, q, qd: TAU, 0.01, mode="sometimes")

    class SensorLost(Exception):
        pass

    def lost(t, q, qd):
        if t > 0.005:
            raise SensorLost("sensor lost")
        return TAU

    for mode in ("hold", "evaluation"):
        sim.reset(Q0)
        with pytest.raises(SensorLost, match="sensor lost"):
            sim.run(lost, 0.02, mode=mode)
        sim.reset(Q0)
        with pytest.raises(ValueError, match=r"tau is NaN or Inf"):
            sim.run(lambda t, q, qd: TAU * (np.nan if t > 0.005 else 1), 0.02, mode=mode)
    with pytest.raises(ValueError, match=r"tau: expected shape \(4,\)"):
        sim.step(np.zeros(2))
    with pytest.raises(ValueError, match="substeps"):
        femdyn.Simulator(finger, integrator="dopri", substeps=4)
    with pytest.raises(ValueError, match="dt"):
        femdyn.Simulator(finger, dt=0)


@pytest.mark.parametrize("integrator", ["rk4", "dopri", "bdf"])
@pytest.mark.parametrize("mode", ["evaluation", "hold"])
@pytest.mark.parametrize("call", ["reset", "step", "run"])
def test_a_controller_that_calls_its_own_simulator_is_refused(finger, integrator, mode, call):
    """reset, step or run from inside the Simulator's own run (it crashed the interpreter with
    dopri and bdf and hung with rk4): a RuntimeError naming the call, once, and the Simulator
    usable afterwards."""
    sim = femdyn.Simulator(finger, integrator=integrator, dt=1e-3, q0=Q0)

    def controller(t, q, qd):
        {"reset": lambda: sim.reset(Q0), "step": lambda: sim.step(TAU),
         "run": lambda: sim.run(lambda *_: TAU, 1.0)}[call]()
        return TAU

    with pytest.raises(RuntimeError, match=rf"Simulator\.{call}: called while this Simulator's "
                                           r"run\(\) is in progress"):
        sim.run(controller, 0.01, mode=mode)
    sim.reset(Q0)
    sim.step(TAU)
    r = sim.run(lambda t, q, qd: TAU, sim.t + 0.005, mode=mode)
    assert r["stats"]["ok"] and sim.t == pytest.approx(0.006)


@pytest.mark.parametrize("integrator", ["rk4", "dopri", "bdf"])
def test_a_controller_that_raises_leaves_the_simulator_usable(finger, integrator):
    """The controller's exception propagates once (in evaluation mode from inside the
    integrator's step); step, a held run and reset then step work afterwards."""
    sim = femdyn.Simulator(finger, integrator=integrator, dt=1e-3, q0=Q0)
    calls = [0]

    def controller(t, q, qd):
        calls[0] += 1
        if calls[0] > 3:
            raise KeyError("the controller's own failure")
        return TAU

    with pytest.raises(KeyError, match="the controller's own failure"):
        sim.run(controller, 0.01)
    t = sim.t
    sim.step(TAU)
    assert sim.t == pytest.approx(t + 1e-3)
    assert sim.run(lambda *_: TAU, sim.t + 0.003, mode="hold")["stats"]["ok"]
    sim.reset(Q0)
    sim.step(TAU)
    assert sim.t == pytest.approx(1e-3) and np.all(np.isfinite(sim.state["q"]))


def test_a_diverging_run_raises_numerical_error_with_its_cause(finger):
    stiff = lambda t, q, qd: -1e4 * q  # noqa: E731  far beyond rk4's stability at 1 ms
    sim = femdyn.Simulator(finger, dt=1e-3, q0=Q0)
    with pytest.raises(femdyn.NumericalError, match="the solution diverges"):
        sim.run(stiff, 1.0)
    sim.reset(Q0)
    r = sim.run(stiff, 1.0, check=False)
    assert not r["stats"]["ok"] and r["stats"]["diverged"]
    assert r["stats"]["t_reached"] < 1.0 and np.all(np.isfinite(r["q"]))


def test_ctrl_c_stops_a_run(finger):
    sim = femdyn.Simulator(finger, dt=1e-3, substeps=50, q0=Q0)
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            sim.run(lambda t, q, qd: TAU, 100.0)
    finally:
        timer.cancel()


@pytest.mark.parametrize("integrator", ["dopri", "bdf"])
def test_ctrl_c_stops_one_long_step(finger, integrator):
    """One step of a billion seconds on a moving model: Ctrl-C is honoured inside it (the motion
    asks Python's signal check every 20 ms), raising KeyboardInterrupt within a second, and the
    Simulator is usable after."""
    import time
    sim = femdyn.Simulator(finger, integrator=integrator, dt=1e9, q0=Q0, qd0=np.ones(4))
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    start = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt):
            sim.step(TAU)
    finally:
        timer.cancel()
    assert time.monotonic() - start < 1.3
    assert sim.state["t"] < 1e9  # stopped inside the step, at a good state
    sim.reset(Q0)
    assert sim.state["t"] == 0 and np.array_equal(sim.state["q"], Q0)


# ---- the examples converge (short horizons) --------------------------------------------------

def test_computed_torque_tracks_the_fingertip_path():
    r = control_computed_torque.run(t_end=1.0)
    t, e = r["t"], r["error"]
    assert r["run"]["stats"]["ok"]
    assert e[0] > 1e-3  # it starts off the path
    assert np.max(e[t >= 0.5]) < 1e-4  # and follows it after the transient


def test_computed_torque_with_the_wrong_sign_does_not_track():
    r = control_computed_torque.run(t_end=0.5, kp=-control_computed_torque.OMEGA**2, check=False)
    assert r["error"][-1] > 1e-3  # the error grows (until the run diverges)


@pytest.mark.parametrize("mode", ["hold", "evaluation"])
def test_task_space_controller_moves_the_tip_to_the_point(mode):
    r = control_task_space.run(t_end=1.0, mode=mode)
    e = r["error"]
    assert e[0] > 1e-2  # 1 cm or more away at the start
    assert e[-1] < 1e-6  # at the point within a micrometre after 1 s


def test_space_robot_tip_reaches_the_point_with_the_satellite_floating():
    # Resolved rates on the generalized Jacobian J*: the tip converges as e' = -K e while the
    # satellite turns under it and the momentum stays zero (the controller's torques are internal).
    r = control_space_robot.run(t_end=2.0)
    t, e = r["t"], r["error"]
    assert r["run"]["stats"]["ok"]
    assert e[0] > 0.09  # 10 cm away at the start
    assert e[-1] < 1e-4  # at the point within 0.1 mm after 2 s
    assert np.all(np.diff(e[t > 0.2]) < 0)  # closing in all the way
    assert np.degrees(r["angle"][-1]) > 0.5  # the satellite turned
    assert np.abs(r["momentum"]).max() < 1e-8  # about 1e-11: only round-off and rk4's error


def test_space_robot_with_the_wrong_sign_moves_away():
    r = control_space_robot.run(t_end=0.5, k=-4.0)
    assert r["error"][-1] > r["error"][0]


@pytest.mark.parametrize("script", ["control_computed_torque.py", "control_task_space.py",
                                    "control_space_robot.py"])
def test_examples_run_as_scripts_and_plot(script, tmp_path):
    plot = tmp_path / "error.png"
    out = subprocess.run([sys.executable, str(ROOT / "examples" / script), "--t-end", "0.3",
                          "--plot", str(plot)], cwd=tmp_path, env=subprocess_env(),
                         capture_output=True, text=True, check=True).stdout
    assert "t =  0.300 s" in out and plot.stat().st_size > 1000


def test_overhead_benchmark_smoke():
    out = subprocess.run([sys.executable, str(ROOT / "tools" / "bench_control.py"), "--quick"],
                         env=subprocess_env(), capture_output=True, text=True, check=True).stdout
    assert out.count("| Simulator.") == 3 and "| femdyn.simulate" in out


def test_a_run_beyond_the_memory_limit_is_refused_before_it_starts(finger):
    sim = femdyn.Simulator(finger, dt=1e-3, q0=Q0)
    calls = []
    femdyn.set_max_memory(1e-6)  # 1 kB
    try:
        with pytest.raises(ValueError, match=r"Simulator.run: 1002 rows of n = 4 coordinates needs"):
            sim.run(lambda t, q, qd: calls.append(t) or TAU, 1.0)
    finally:
        femdyn.set_max_memory(None)
    assert calls == [] and sim.t == 0


def zoh_radius(A, B, K, T):
    """ρ(Φ + Γ K) of the loop held over T, by scipy's expm of Van Loan's block."""
    import scipy.linalg
    n2, n = A.shape[0], B.shape[1]
    C = np.zeros((n2 + n, n2 + n))
    C[:n2, :n2], C[:n2, n2:] = A * T, B * T
    E = scipy.linalg.expm(C)
    return max(abs(np.linalg.eigvals(E[:n2, :n2] + E[:n2, n2:] @ K)))


def test_a_controller_that_destabilises_the_sampled_loop_is_named_with_its_growth():
    """A pendulum under a PD law held over T = 1 ms: the report's growth per period and the
    period below which the gains hold are those of the sampled loop's theory (x_{k+1} =
    (Φ + Γ K) x_k, computed here by scipy), and the model alone is not blamed."""
    m = femdyn.load(model_path("models/pendulum.json"))
    kp, kd, T = 4e6, 1e3, 1e-3
    A, B = m.linearize(np.zeros(1), np.zeros(1))
    K = np.array([[-kp, -kd]])
    rho = zoh_radius(A, B, K, T)
    assert rho > 1.3  # (the case: unstable at T, though rk4's 20 substeps follow the model)
    sim = femdyn.Simulator(m, integrator="rk4", dt=T, substeps=20, q0=[0.1])
    with pytest.raises((femdyn.NumericalError, ValueError)) as e:
        sim.run(lambda t, q, qd: -kp * q - kd * qd, 2.0)
    text = str(e.value)
    assert "the controller is the likely cause" in text
    assert f"grow ×{rho:.3g} a period" in text
    below = float(text.split("hold below a period of about ")[1].split(" s")[0])
    assert zoh_radius(A, B, K, 0.97 * below) <= 1 + 1e-6 < zoh_radius(A, B, K, 1.03 * below)
    # the same gains sampled at 0.9 of that period run
    sim = femdyn.Simulator(m, integrator="rk4", dt=0.9 * below, substeps=4, q0=[0.1])
    assert sim.run(lambda t, q, qd: -kp * q - kd * qd, 0.05)["stats"]["ok"]


def test_a_controller_too_stiff_for_the_step_is_named_with_rk4s_limit():
    """Called inside f, a gain of 1e8 makes the loop ω = 1e4 rad/s: rk4 at 1 ms is beyond its
    limit 2√2/ω (the imaginary-axis bound of its stability region), the model alone far within."""
    m = femdyn.load(model_path("models/pendulum.json"))
    sim = femdyn.Simulator(m, integrator="rk4", dt=1e-3, q0=[0.1])
    with pytest.raises(femdyn.NumericalError) as e:
        sim.run(lambda t, q, qd: -1e8 * q, 1.0, mode="evaluation")
    text = str(e.value)
    limit = float(text.split("beyond the stability limit of the step 0.001 s (")[1].split(" s")[0])
    assert limit == pytest.approx(2 * np.sqrt(2) / np.sqrt(1e8 + 9.81), rel=2e-3)


def test_a_gentle_controller_and_a_plain_step_divergence_do_not_blame_the_controller():
    m = femdyn.load(model_path("models/pendulum.json"))
    sim = femdyn.Simulator(m, integrator="rk4", dt=1e-3, q0=[0.1])
    assert sim.run(lambda t, q, qd: -100 * q - 20 * qd, 1.0)["stats"]["ok"]
    # rk4 at a step beyond the model's own limit (0.905 s), the controller doing nothing
    sim = femdyn.Simulator(m, integrator="rk4", dt=2.0, q0=[0.1])
    with pytest.raises(femdyn.NumericalError) as e:
        sim.run(lambda t, q, qd: np.zeros(1), 1e4)
    assert "controller is the likely cause" not in str(e.value)


def test_a_driven_joints_torque_is_in_the_rows():
    # A hub driven through a spin-up (θ̈* = (ω_s/T_s)(1 − cos 2πt/T_s)) carrying a sprung arm,
    # no controller: the rows' τ is what the dynamics applies, the drive's torque on the hub.
    # Forward dynamics under the recorded τ gives the hub the prescribed θ̈*, and ∫ τ·q̇ dt is the
    # work W the run integrated.
    doc = {"name": "driven hub", "gravity": [0, 0, 0], "bodies": [
        {"name": "hub", "parent": "world",
         "joint": {"name": "hub", "type": "revolute", "axis": [0, 0, 1],
                   "prescribed": {"spin_up": {"rate": 2.0, "time": 1.0}}},
         "elements": [{"type": "rigid_body", "mass": 1.0,
                       "inertia": {"ixx": 0.1, "iyy": 0.1, "izz": 0.1}}]},
        {"name": "arm", "parent": "hub",
         "joint": {"name": "elbow", "type": "revolute", "axis": [0, 0, 1],
                   "origin": {"xyz": [0.5, 0, 0]}, "spring": {"stiffness": 20}},
         "elements": [{"type": "lumped_point", "node": [0.4, 0, 0], "mass": 0.7}]}]}
    import json
    m = femdyn.loads(json.dumps(doc), name="driven hub")
    out = femdyn.Simulator(m, integrator="rk4", dt=1e-3).run(lambda t, q, v: np.zeros(m.n), 1.5)
    t, tau, q, qd = out["t"], out["tau"], out["q"], out["qd"]
    assert np.abs(tau[:, 0]).max() > 0.1 and np.all(tau[:, 1] == 0)
    for k in range(0, len(t), 100):
        qdd = m.equations(q[k], qd[k], tau[k])["qdd"]
        want = 2.0 * (1 - np.cos(2 * np.pi * t[k])) if t[k] <= 1 else 0.0
        assert qdd[0] == pytest.approx(want, abs=1e-6), t[k]
    power = np.einsum("ij,ij->i", tau, qd)
    work = np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(t))
    assert work == pytest.approx(out["work"][-1], rel=1e-5)
