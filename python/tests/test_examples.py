"""The worked example of docs/python.md and the batch benchmark run."""
import subprocess
import sys

import numpy as np
import pytest

from conftest import ROOT, cli_json, subprocess_env


def run(*args):
    env = subprocess_env()
    return subprocess.run([sys.executable, *map(str, args)], cwd=ROOT, env=env,
                          capture_output=True, text=True, check=True).stdout


def test_python_example():
    out = run(ROOT / "examples" / "python_example.py")
    assert "dexterous finger: n = 4" in out
    assert "max |D[qd, qd] - h|" in out and "energy balance error" in out


def test_python_example_on_urdf():
    out = run(ROOT / "examples" / "python_example.py", "models/urdf/arm7.urdf")
    assert "n = 7" in out


def test_benchmark_smoke():
    out = run(ROOT / "tools" / "bench_python.py", "--quick")
    assert out.count("| forward_dynamics |") == 3


def load_example(name):
    import importlib.util
    spec = importlib.util.spec_from_file_location(name, ROOT / "examples" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_lqr_holds_the_finger():
    import numpy as np
    r = load_example("lqr_finger").run(t_end=3.0)
    assert r["eigenvalues"].real.max() < -1.0  # A − BK strictly in the left half-plane
    t, e = r["t"], r["error"]
    assert e[0] > 0.09
    assert e[t >= 2.0].max() < 1e-6  # converged within 2 s
    # and within the envelope the closed-loop eigenvalues allow, e ≤ 100 e0 exp(−σ t / 2), σ the
    # slowest decay rate −max Re λ of A − BK, down to round-off: the decay is oscillatory, and
    # A − BK is not normal, so e first grows (measured: 19 times the envelope's e0 exp(−σt/2)
    # at 0.05 s, the start's velocity carrying the finger on)
    sigma = -r["eigenvalues"].real.max()
    assert np.all(e <= 100 * e[0] * np.exp(-0.5 * sigma * t) + 1e-13)


def test_ilqr_swings_the_double_pendulum_up():
    import numpy as np
    example = load_example("ilqr_swingup")
    r = example.run()
    assert r["history"][-1] < 1e-2 * r["history"][0]
    xf = np.r_[r["q"][-1], r["qd"][-1]]
    assert np.abs(xf - example.GOAL).max() < 1e-2  # upright and at rest on femdyn.Simulator


def test_spin_up_beam_follows_its_hub_and_writes_the_columns(tmp_path):
    # A short run (4 parts, 2 s): the hub follows the prescribed angle, the tip lags behind it
    # (v_tip < 0 while the hub accelerates) and stays near the bar's length.
    m = load_example("spin_up_beam")
    rows, hub_error = m.run(4, 1e-8, t_end=2.0)
    assert hub_error < 1e-6
    assert list(rows[:, 0]) == [0.0, 0.5, 1.0, 1.5, 2.0]
    assert (rows[1:, 1] < 0).all() and abs(rows[-1, 1]) < 0.2
    assert abs(rows[-1, 2]) < 1e-2
    out = run(ROOT / "examples" / "spin_up_beam.py", "--segments", "4", "--t-end", "1", "--csv")
    assert out.splitlines()[0] == "t,v_tip,u_tip"
    assert len(out.splitlines()) == 4  # 0, 0.5, 1


def test_spin_up_linear_model_without_stiffening_diverges_and_femdyn_does_not():
    # The linear model's first mode loses its stiffness (ω_1² − θ̇² < 0 once θ̇ > 3.80 rad/s):
    # its tip grows without bound; femdyn's (docs/flexible/spin_up_beam.csv, 64 parts) stays
    # within 0.41 m. The closed-form modes: ω_1 = 1.8751² √(EI/(ρA L⁴)).
    m = load_example("spin_up_beam")
    roots, _ = m.cantilever_modes(3)
    assert roots == pytest.approx([1.87510407, 4.69409113, 7.85475744], rel=1e-8)
    assert roots[0] ** 2 * (m.EI / (m.RHO_A * m.L ** 4)) ** 0.5 == pytest.approx(3.80, abs=5e-3)
    t = np.arange(0.0, 30.01, 0.5)
    linear = m.linear_model_tip(t)
    assert abs(linear[t == 5.0][0]) < 0.5  # (the two agree while the hub is slow)
    assert np.abs(linear[t >= 20]).min() > 1e3
    table = np.loadtxt(ROOT / "docs" / "flexible" / "spin_up_beam.csv", delimiter=",",
                       skiprows=1)
    assert list(table[:, 0]) == list(t)
    assert np.abs(table[:, 1]).max() < 0.41
    assert abs(linear[t == 5.0][0] - table[t == 5.0, 1][0]) < 0.05

def test_flexible_space_robot_lqr_is_stable_and_damps_the_arms_modes():
    # The LQR of examples/flexible_space_robot.py, on the arm reduced by the base's momentum:
    # no closed-loop eigenvalue in the right half-plane; the modes the in-plane joints reach
    # (below 400 rad/s) damped well beyond the aluminium's 1e-4; the out-of-plane ones, which
    # no joint about z moves, stay (uncontrollable) where check lists them. Then 0.2 s of the
    # slew on the nonlinear model runs through femdyn.Simulator.
    ex = load_example("flexible_space_robot")
    arm = ex.Arm()
    lam = arm.closed_loop
    assert (lam.real <= 1e-9 * np.abs(lam).max()).all()
    slow = [z for z in lam if 0 < z.imag < 400]
    damped = sorted(-z.real / abs(z) for z in slow)
    assert sum(d > 0.04 for d in damped) >= 4
    check = {round(x["omega"], 1) for x in cli_json("check", "models/flexible_space_robot.json",
                                                    "--json")["natural_modes"]["oscillatory"]}
    undamped = [round(z.imag, 1) for z in slow if -z.real / abs(z) < 1e-3]
    assert undamped and all(any(abs(w - c) < 0.2 for c in check) for w in undamped)
    t, d = arm.run(arm.lqr, 0.2)
    assert t[-1] == pytest.approx(0.2) and np.isfinite(d).all() and d.max() < 0.01
