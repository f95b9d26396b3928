"""Flexible bars through the Python doors (docs/flexible.md): the Builder's bar is the file's to
the bit, its coordinates are named as documented, a refused bar names the key, and the tables
of docs/flexible.md are what tools/flexible_modes.py computes now."""
import json
import sys

import numpy as np
import pytest

import femdyn
from conftest import ROOT, cli_json

SECTION = {"E": 7e10, "G": 2.6e10, "density": 2700, "area": 1e-4, "Iy": 2e-9, "Iz": 3e-9,
           "J": 4e-9}
BAR = {"length": 0.8, "segments": 3, "origin": {"xyz": [0.1, 0, 0], "rpy": [0, 0.2, 0]},
       "section": SECTION, "damping": {"stiffness_proportional": 1e-4}}


def built(gravity=(0, 0, -9.81)):
    b = femdyn.Builder("hub and bar", gravity=list(gravity))
    b.body("hub", "world", type="revolute", joint="hub", axis=[0, 0, 1])
    b.rigid_body("hub", 2.0, [0, 0, 0], np.diag([0.1, 0.1, 0.2]))
    b.flexible_bar("arm", "hub", **BAR)
    b.lumped_point("arm.tip", [0, 0, 0], 0.05)
    return b.build()


def from_file(tmp_path):
    doc = {"name": "hub and bar", "gravity": [0, 0, -9.81], "bodies": [
        {"name": "hub", "parent": "world",
         "joint": {"name": "hub", "type": "revolute", "axis": [0, 0, 1]},
         "elements": [{"type": "rigid_body", "mass": 2.0, "com": [0, 0, 0],
                       "inertia": [[0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.2]]}]},
        {"name": "payload", "parent": "arm.tip", "joint": {"type": "fixed"},
         "elements": [{"type": "lumped_point", "node": [0, 0, 0], "mass": 0.05}]}],
        "flexible_bars": [dict(name="arm", parent="hub", **BAR)]}
    path = tmp_path / "hub_bar.json"
    path.write_text(json.dumps(doc))
    return femdyn.load(str(path))


def test_builder_bar_is_the_files(tmp_path):
    a, b = built(), from_file(tmp_path)
    assert a.coordinates == b.coordinates
    assert a.coordinates[:5] == ["hub", "arm.1.ry", "arm.1.rz", "arm.1.rx", "arm.1.ux"]
    assert len(a.coordinates) == 1 + 4 * 3
    assert list(a.actuated) == [0]  # no actuator drives a strain: only the hub's τ is an input
    assert a.linearize(np.zeros(a.n_q), np.zeros(a.n), np.zeros(a.n))[1].shape == (2 * a.n, 1)
    rng = np.random.default_rng(4)
    for _ in range(3):
        q, qd = rng.uniform(-0.05, 0.05, a.n), rng.uniform(-1, 1, a.n)
        tau = np.zeros(a.n)
        ea, eb = a.equations(q, qd, tau), b.equations(q, qd, tau)
        for key in ("M", "h", "Q", "qdd"):
            # (the payload: a lumped point on arm.tip, or on a fixed child of it: one body)
            assert np.allclose(ea[key], eb[key], rtol=1e-13, atol=1e-13 * np.abs(eb[key]).max()), key


def test_builder_bar_has_the_files_centreline(tmp_path):
    # info's "bars" (what view draws the bar along): the same stations, clamp to tip, through
    # either door; the radius √((ρIy + ρIz)/ρA) = √((Iy + Iz)/A) of the section.
    a, b = built().info()["bars"], from_file(tmp_path).info()["bars"]
    assert a == b
    assert [bar["name"] for bar in a] == ["arm"]
    assert a[0]["stations"] == ["arm.0", "arm.1", "arm.2", "arm.3", "arm.tip"]
    assert a[0]["parts"] == 3
    assert a[0]["radius"] == pytest.approx(np.sqrt((2e-9 + 3e-9) / 1e-4), rel=1e-14)


def test_modal_damping_dissipates_and_keeps_the_energy_balance(tmp_path):
    # A bar let go bent with 5 % modal damping: the run counts the damping's power −q̇ᵀ D q̇ in
    # its work, so E − W stays E(0) while nearly all of E(0) is dissipated.
    doc = {"name": "damped bar", "gravity": [0, 0, 0], "bodies": [], "flexible_bars": [
        {"name": "arm", "parent": "world", "length": 0.8, "segments": 4, "section": SECTION,
         "damping": {"modal": 0.05}}]}
    path = tmp_path / "damped.json"
    path.write_text(json.dumps(doc))
    m = femdyn.load(str(path))
    q0 = np.array([0.01 if c.endswith(".rz") else 0.0 for c in m.coordinates])
    r = femdyn.simulate(m, 0.5, integrator="dopri", rtol=1e-10, atol=1e-12, q0=q0)
    assert not r["stats"]["conservative"]
    assert r["total"][-1] < 1e-3 * r["total"][0]
    assert r["work"][-1] == pytest.approx(r["total"][-1] - r["total"][0], rel=1e-9)
    assert r["stats"]["energy_balance_relative"] < 1e-9


def test_spring_forces_are_minus_k_q():
    # Q of each elastic rate with the bar straight but that rate at 1e-3, gravity off: −k θ,
    # k = EI/Δ, GJ/Δ, EA/Δ (docs/flexible.md).
    m = built(gravity=(0, 0, 0))
    delta = 0.8 / 3
    k = {"ry": 7e10 * 2e-9 / delta, "rz": 7e10 * 3e-9 / delta, "rx": 2.6e10 * 4e-9 / delta,
         "ux": 7e10 * 1e-4 / delta}
    for i, name in enumerate(m.coordinates[1:], start=1):
        q = np.zeros(m.n)
        q[i] = 1e-3
        Q = m.equations(q, np.zeros(m.n), np.zeros(m.n))["Q"]
        assert Q[i] == pytest.approx(-k[name.split(".")[-1]] * 1e-3, rel=1e-12), name


def test_bad_bar_names_the_key():
    b = femdyn.Builder("bad")
    with pytest.raises(femdyn.ModelError, match=r"/flexible_bars/0/segments: expected an integer"):
        b.flexible_bar("arm", "world", length=1, segments=0, section=SECTION)
    with pytest.raises(femdyn.ModelError, match=r"/flexible_bars/1/section/G: "):
        b.flexible_bar("arm", "world", length=1, segments=2,
                       section={k: v for k, v in SECTION.items() if k != "G"})


def test_docs_tables_are_current():
    sys.path.insert(0, str(ROOT / "tools"))
    import flexible_modes
    doc = (ROOT / "docs" / "flexible.md").read_text()
    for key, make in flexible_modes.TABLES.items():
        table = getattr(flexible_modes, make)()
        assert table in doc, f"docs/flexible.md: the {key} table is stale " \
                             "(tools/flexible_modes.py --update)"


@pytest.mark.parametrize("damping", [None, {"modal": 0.02, "mass_proportional": 1.0}])
def test_free_floating_bar_keeps_momentum_and_energy(damping):
    # A satellite on a free joint carrying a bar that bends and twists, spun and released in
    # zero gravity: linear and angular momentum (about the centre of mass, in the world) stay
    # as they were, to the integrator's tolerance, with the bar's modal and mass-proportional
    # damping too (forces between its pieces); energy without damping, and with it E − W.
    b = femdyn.Builder("floating bar")
    b.body("sat", "world", type="free", joint="base")
    b.rigid_body("sat", 50.0, [0, 0, 0], np.diag([4.0, 5.0, 6.0]))
    b.flexible_bar("arm", "sat", length=2.0, segments=4, axial=False,
                   origin={"xyz": [0.5, 0, 0], "rpy": [0.1, 0.2, 0.3]},
                   section={"E": 7e10, "G": 2.6e10, "density": 2700, "area": 3e-4,
                            "Iy": 1.2e-7, "Iz": 1.5e-7, "J": 2.4e-7},
                   **({"damping": damping} if damping else {}))
    m = b.build()
    rng = np.random.default_rng(8)
    q0 = np.zeros(m.n_q)
    q0[3] = 1.0  # the identity rotation (w, x, y, z)
    q0[7:] = rng.uniform(-0.02, 0.02, m.n_q - 7)
    qd0 = rng.uniform(-0.5, 0.5, m.n)
    run = femdyn.simulate(m, 0.2, q0=q0, qd0=qd0, integrator="dopri", rtol=1e-11, atol=1e-13)
    assert run["stats"]["ok"]
    first = m.centroidal(run["q"][0], run["qd"][0])["momentum"]
    last = m.centroidal(run["q"][-1], run["qd"][-1])["momentum"]
    scale = np.abs(first).max()
    assert np.abs(last - first).max() < 1e-9 * scale
    e0, e1 = m.energy(run["q"][0], run["qd"][0])["total"], m.energy(run["q"][-1], run["qd"][-1])["total"]
    w = run["work"][-1]
    assert abs(e1 - e0 - w) < 1e-8 * abs(e0)
    assert (w == 0) == (damping is None) and w <= 0


def test_bdf_max_order_is_one_door_and_refused_elsewhere():
    """simulate(max_order=2) equals femdyn simulate --max-order 2 and steps over the bar's
    undamped modes; max_order is refused off bdf and outside 1..5, at every door."""
    m = femdyn.load(str(ROOT / "models" / "spin_up_beam.json"))
    low = femdyn.simulate(m, 2.0, integrator="bdf", rtol=1e-7, atol=1e-9, max_order=2)
    high = femdyn.simulate(m, 2.0, integrator="bdf", rtol=1e-7, atol=1e-9)
    assert low["stats"]["steps"] * 10 < high["stats"]["steps"]
    assert np.abs(low["q"][-1] - high["q"][-1]).max() < 1e-5
    cli = cli_json("simulate", "models/spin_up_beam.json", "--t-end", "2", "--integrator", "bdf",
                   "--rtol", "1e-7", "--atol", "1e-9", "--max-order", "2", "--json")
    assert cli["steps"] == low["stats"]["steps"]
    for bad in [dict(integrator="dopri", max_order=2), dict(integrator="bdf", max_order=0),
                dict(integrator="bdf", max_order=6), dict(integrator="bdf", max_order=2.5)]:
        with pytest.raises(ValueError, match="max_order"):
            femdyn.simulate(m, 0.1, **bad)
    with pytest.raises(ValueError, match="max_order"):
        femdyn.Simulator(m, integrator="rk4", max_order=2)
    with pytest.raises(ValueError, match="max_order"):
        femdyn.Simulator(m, integrator="bdf", max_order=9)
    sim = femdyn.Simulator(m, integrator="bdf", dt=0.5, rtol=1e-7, atol=1e-9, max_order=2)
    sim.step(np.zeros(m.n))
    assert sim.state["t"] == pytest.approx(0.5)


def test_flexible_space_robot_keeps_momentum_and_rings_at_checks_frequencies():
    """models/flexible_space_robot.json: a spinning satellite whose arm's joints push (internal
    torques) keeps its momentum; let go bent, its arm rings
    at the frequencies `femdyn check` lists (the spectrum's peaks, within the resolution)."""
    path = str(ROOT / "models" / "flexible_space_robot.json")
    m = femdyn.load(path)
    names = m.coordinates
    shoulder, elbow = names.index("shoulder"), names.index("elbow")
    q0 = m.neutral_configuration
    q0 = np.array(q0() if callable(q0) else q0)
    qd0 = np.zeros(m.n)
    qd0[3:6] = [0.01, -0.02, 0.05]  # the satellite turning
    tau = np.zeros((3, m.n))
    tau[0, shoulder], tau[0, elbow] = 40.0, -25.0  # pushing, eased off by 0.05 s
    run = femdyn.simulate(m, 0.1, q0=q0, qd0=qd0, tau=tau, tau_t=[0.0, 0.05, 0.1],
                          integrator="dopri", rtol=1e-11, atol=1e-13)
    first = m.centroidal(run["q"][0], run["qd"][0])["momentum"]
    last = m.centroidal(run["q"][-1], run["qd"][-1])["momentum"]
    assert np.abs(last - first).max() < 1e-9 * np.abs(first).max()
    # The ring: the arm let go bent in its plane (at rest, no momentum); 2 s, the upper arm's
    # bending at its middle. (Check lists the modes at this posture: a manoeuvre that moved the
    # joints would move the frequencies with them.)
    bent = q0.copy()
    bent[m.configuration.index("upper.4.rz")] = 2e-3
    bent[m.configuration.index("fore.4.rz")] = -2e-3
    dt, t_end = 0.002, 2.0
    ring = femdyn.simulate(m, t_end, q0=bent, integrator="dopri", rtol=1e-7, atol=1e-10,
                           t_eval=np.linspace(0.0, t_end, 1001))
    after = ring["t"] >= 0.0
    x = ring["q"][after, m.configuration.index("upper.4.rz")]
    x = (x - x.mean()) * np.hanning(len(x))
    spectrum = np.abs(np.fft.rfft(x))
    hz = np.fft.rfftfreq(len(x), dt)
    peaks = [i for i in range(1, len(spectrum) - 1)
             if spectrum[i] > spectrum[i - 1] and spectrum[i] >= spectrum[i + 1]
             and spectrum[i] > 0.05 * spectrum.max()]
    check = cli_json("check", path, "--json")
    listed = np.array([mode["hz"] for mode in check["natural_modes"]["oscillatory"]])
    # 6 + 2 rigid-body modes (the satellite, the free shoulder and elbow), none unstable, and the
    # stiffest mode over the random states is the highest natural one (random states keep the
    # bars at small strains: Joint sample_range).
    assert check["natural_modes"]["rigid"] == 8 and check["natural_modes"]["unstable"] == 0
    assert len(listed) == m.n - 8
    highest = check["natural_modes"]["oscillatory"][-1]["omega"]
    assert abs(check["stiffest_mode"]["omega"] / highest - 1) < 0.02
    resolution = 1.0 / (len(x) * dt)
    assert len(peaks) >= 2
    for i in peaks:
        assert np.abs(listed - hz[i]).min() < 2 * resolution, (hz[i], listed[:12])


def test_check_counts_rigid_body_modes_damped_or_not(tmp_path):
    """n − rank K: a free joint is a rigid-body mode with or without a damper on it; a sprung one
    oscillates."""
    for damping, rigid in [(0.0, 2), (0.3, 2)]:
        doc = {"name": "two free, one sprung", "gravity": [0, 0, 0], "bodies": [
            {"name": "a", "parent": "world",
             "joint": {"type": "revolute", "axis": [0, 0, 1], "damping": damping},
             "elements": [{"type": "lumped_point", "node": [0.5, 0, 0], "mass": 1}]},
            {"name": "b", "parent": "a",
             "joint": {"type": "revolute", "axis": [0, 0, 1], "origin": {"xyz": [0.5, 0, 0]},
                       "damping": damping},
             "elements": [{"type": "lumped_point", "node": [0.5, 0, 0], "mass": 1}]},
            {"name": "c", "parent": "b",
             "joint": {"type": "revolute", "axis": [0, 0, 1], "origin": {"xyz": [0.5, 0, 0]},
                       "spring": {"stiffness": 40}},
             "elements": [{"type": "lumped_point", "node": [0.5, 0, 0], "mass": 1}]}]}
        path = tmp_path / "m.json"
        path.write_text(json.dumps(doc))
        modes = cli_json("check", str(path), "--json")["natural_modes"]
        assert modes["rigid"] == rigid and len(modes["oscillatory"]) == 1
        assert modes["unstable"] == 0
