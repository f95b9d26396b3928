"""Model.view: the page of `femdyn view` from Python (docs/view.md). The page in a browser is
tests/view_browser.py's; here: what the page holds, that it equals the command's, and errors."""
import html
import json
import re
import subprocess

import numpy as np
import pytest

import femdyn
from conftest import BINARY, model_path

pytestmark = pytest.mark.skipif(not hasattr(femdyn.Model, "view"),
                                reason="femdyn built without the 3-D view (web/node_modules)")


def scene_of(path):
    page = open(path, encoding="utf-8").read()
    m = re.search(r'<script type="application/json" id="femdyn-scene">(.*?)</script>', page, re.S)
    assert m, "no scene in the page"
    return json.loads(m.group(1))


def info(name):
    out = subprocess.run([str(BINARY), "info", model_path(name), "--json"], check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out)


def test_posture_page_holds_the_model_and_equals_the_command(tmp_path):
    name = "models/finger.json"
    model = femdyn.load(model_path(name))
    q = np.array([0.1, 0.4, 0.5, 0.3])
    path = model.view(q=q, path=tmp_path / "finger.html")
    scene = scene_of(path)
    facts = info(name)
    assert scene["counts"]["bodies"] == len(facts["joints"])
    assert scene["counts"]["elements"] == len(facts["elements"])
    assert scene["motion"]["q"] == [list(q)]
    cli = tmp_path / "cli.html"
    subprocess.run([str(BINARY), "view", model_path(name), "--q", ",".join(map(str, q)),
                    "--out", str(cli)], check=True, capture_output=True)
    assert scene_of(cli) == scene


def test_trajectory_from_simulate_and_from_its_csv_agree(tmp_path):
    name = model_path("models/hand.json")
    model = femdyn.load(name)
    run = femdyn.simulate(model, 0.1, every=10)
    from_dict = scene_of(model.view(traj=run, path=tmp_path / "a.html"))
    csv = tmp_path / "traj.csv"
    subprocess.run([str(BINARY), "simulate", name, "--t-end", "0.1", "--every", "10", "--out",
                    str(csv)], check=True, capture_output=True)
    from_csv = scene_of(model.view(traj=str(csv), path=tmp_path / "b.html"))
    assert from_dict["motion"]["t"] == pytest.approx(from_csv["motion"]["t"])
    assert len(from_dict["motion"]["poses"]) == len(run["t"]) > 2
    assert np.allclose(from_dict["motion"]["poses"], from_csv["motion"]["poses"], atol=1e-5)
    assert from_dict["motion"]["energy"]["source"] == "trajectory"


def test_trajectory_from_the_simulator_holds_its_energy_balance(tmp_path):
    # Simulator.run's rows have no energies: the page computes them from q and qd, and with a
    # controller doing work the balance E − W stays where it started (to rk4's error).
    model = femdyn.load(model_path("models/finger.json"))
    sim = femdyn.Simulator(model, integrator="rk4", dt=1e-3)
    out = sim.run(lambda t, q, v: 0.002 - 1e-4 * v, 0.2)
    energy = scene_of(model.view(traj=out, path=tmp_path / "sim.html"))["motion"]["energy"]
    balance = np.array(energy["kinetic"]) + energy["potential"] - energy["work"]
    assert len(balance) == len(out["t"]) > 100
    assert np.abs(np.array(energy["work"])).max() > 1e-4  # the controller did work
    assert np.abs(balance - balance[0]).max() < 1e-6 * np.abs(np.array(energy["work"])).max()


def test_urdf_visuals_reach_the_page(tmp_path):
    name = model_path("models/urdf/arm7.urdf")
    scene = scene_of(femdyn.load(name).view(path=tmp_path / "arm.html"))
    assert scene["counts"]["visuals"] == open(name).read().count("<visual>") > 0
    assert {v["shape"] for v in scene["visuals"]} == {"box", "cylinder", "sphere"}


def test_default_path_is_a_new_file(tmp_path):
    model = femdyn.load(model_path("models/pendulum.json"))
    first, second = model.view(), model.view()
    assert first != second
    assert scene_of(first)["model"] == model.name


def test_errors(tmp_path):
    model = femdyn.load(model_path("models/finger.json"))
    page = tmp_path / "page.html"
    page.write_text("mine")
    with pytest.raises(FileExistsError, match="force=True"):
        model.view(path=page)
    assert page.read_text() == "mine"
    model.view(path=page, force=True)
    assert scene_of(page)["model"] == model.name
    with pytest.raises(ValueError, match="traj and q"):
        model.view(traj="x.csv", q=np.zeros(4), path=tmp_path / "x.html")
    with pytest.raises(ValueError, match=r"q: expected shape \(4,\)"):
        model.view(q=np.zeros(3), path=tmp_path / "x.html")
    with pytest.raises(femdyn.ModelError, match="missing.csv: cannot open"):
        model.view(traj=str(tmp_path / "missing.csv"), path=tmp_path / "x.html")
    bad = tmp_path / "bad.csv"
    bad.write_text("t,q_other\n0,1\n")
    with pytest.raises(femdyn.ModelError, match="bad.csv: no column 'q_"):
        model.view(traj=str(bad), path=tmp_path / "x.html")
    with pytest.raises(femdyn.ModelError, match="is NaN or Inf"):
        run = femdyn.simulate(model, 0.01)
        run["q"][-1, 1] = np.nan
        model.view(traj=run, path=tmp_path / "x.html")
    assert not (tmp_path / "x.html").exists()


def test_inline_in_a_notebook(tmp_path, monkeypatch):
    """In a Jupyter kernel the page is displayed as an iframe holding the whole page."""
    import sys
    import types

    from femdyn import _view
    shown = []
    display_module = types.ModuleType("IPython.display")
    display_module.HTML = lambda text: ("HTML", text)
    display_module.display = shown.append
    monkeypatch.setitem(sys.modules, "IPython", types.ModuleType("IPython"))
    monkeypatch.setitem(sys.modules, "IPython.display", display_module)
    monkeypatch.setattr(_view, "_in_notebook", lambda: True)
    path = femdyn.load(model_path("models/pendulum.json")).view(path=tmp_path / "p.html")
    assert len(shown) == 1 and shown[0][0] == "HTML"
    frame = shown[0][1]
    assert frame.startswith("<iframe srcdoc=\"") and "</script>" not in frame
    page = open(path, encoding="utf-8").read()
    assert html.unescape(frame[len('<iframe srcdoc="'):frame.index('" style=')]) == page


def test_not_in_a_notebook_here():
    from femdyn import _view
    assert not _view._in_notebook()


def test_view_never_writes_onto_an_input_even_with_force(tmp_path):
    """Model.view(path=…, force=True) replaces an older page, never the model's own file, the
    robot file it refers to, or the trajectory it draws (as the CLI refuses them)."""
    import shutil
    urdf = tmp_path / "robot.urdf"
    shutil.copy(model_path("models/urdf/arm7.urdf"), urdf)
    ref = tmp_path / "robot.json"
    ref.write_text('{"model": "urdf", "params": {"file": "robot.urdf"}}')
    m = femdyn.load(str(ref))
    before = urdf.read_text()
    for target, what in ((ref, "the model file itself"),
                         (urdf, "the robot file the model refers to")):
        with pytest.raises(ValueError, match=re.escape(f"is {what}")):
            m.view(path=str(target), force=True)
    assert urdf.read_text() == before
    traj = tmp_path / "traj.csv"
    subprocess.run([str(BINARY), "simulate", str(ref), "--t-end", "0.01", "--out", str(traj)],
                   check=True, capture_output=True)
    with pytest.raises(ValueError, match="is the trajectory file"):
        m.view(traj=str(traj), path=str(traj), force=True)
