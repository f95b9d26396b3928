"""Echoed user text (issue 22): every message, from Python or from the command line, is one line
with no control character; NUL in a path or a name is refused; CSV columns cannot shift (a
joint named "a,b" is one quoted column that pandas reads back)."""
import json
import re
import subprocess

import numpy as np
import pandas as pd
import pytest

import femdyn
from conftest import BINARY, ROOT, model_path

# ESC, a line break, DEL, the C1 control U+009B, and how messages show them.
CONTROLS = [("\x1b[31m", r"\x1b[31m"), ("a\nb", r"a\x0ab"), ("\x7f", r"\x7f"),
            ("\u009b", r"\xc2\x9b")]
UNSAFE = re.compile("[\x00-\x1f\x7f-\x9f]")


def one_printable_line(text):
    return UNSAFE.search(text) is None


def two_joints(a, b):
    def body(name, parent, joint):
        return {"name": name, "parent": parent,
                "joint": {"name": joint, "type": "revolute", "axis": [0, 1, 0]},
                "elements": [{"type": "lumped_point", "node": [1, 0, 0], "mass": 1}]}
    return {"name": "two", "bodies": [body("l1", "world", a), body("l2", "l1", b)]}


@pytest.mark.parametrize("raw,shown", CONTROLS)
def test_value_errors_are_one_escaped_line(raw, shown):
    b = femdyn.Builder("m")
    with pytest.raises(ValueError) as e:
        b.body("arm", type="hinge" + raw)
    assert str(e.value) == ("joint type: unknown 'hinge" + shown +
                            "' (expected revolute, continuous, prismatic, fixed, helical, screw, universal, planar, spherical, ball or free)")
    model = femdyn.load(model_path("models/pendulum.json"))
    with pytest.raises(ValueError) as e:
        femdyn.simulate(model, 0.1, integrator="rk4" + raw)
    assert str(e.value) == "integrator: 'rk4" + shown + "' is not one of rk4, euler, dopri, bdf"


@pytest.mark.parametrize("raw,shown", CONTROLS)
def test_model_errors_are_one_escaped_line(tmp_path, raw, shown):
    doc = json.loads((ROOT / "models" / "pendulum.json").read_text())
    doc["bodies"][0]["joint"]["sp" + raw] = 1
    path = tmp_path / "m.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(femdyn.ModelError) as e:
        femdyn.load(str(path))
    assert str(e.value) == f"{path}: /bodies/0/joint/sp{shown}: unknown key 'sp{shown}'"
    with pytest.raises(femdyn.ModelError) as e:
        femdyn.load(str(tmp_path / ("x" + raw + ".json")))
    assert one_printable_line(str(e.value))
    assert ("x" + shown + ".json: cannot open file") in str(e.value)


def test_nul_in_a_path_or_a_name_is_refused(tmp_path):
    (tmp_path / "a").write_text("{}")  # what 'a\0b.json' used to open
    with pytest.raises(ValueError) as e:
        femdyn.load(str(tmp_path / "a\x00b.json"))
    assert not isinstance(e.value, femdyn.ModelError)
    assert str(e.value).startswith("path: '")
    assert str(e.value).endswith(r"a\x00b.json' contains a NUL character (at byte %d)"
                                 % len(str(tmp_path / "a")))
    for call, arg in [(lambda: femdyn.Builder("m\x00"), "name"),
                      (lambda: femdyn.Builder("m").body("b\x00"), "name"),
                      (lambda: femdyn.Builder("m").body("b", parent="w\x00"), "parent"),
                      (lambda: femdyn.Builder("m").body("b", type="revolute", joint="j\x00"),
                       "joint"),
                      (lambda: femdyn.Builder("m").node("b\x00", "n", [0, 0, 0]), "body"),
                      (lambda: femdyn.Builder("m").lumped_point("b", "n\x00", 1.0), "node"),
                      (lambda: femdyn.simulate(femdyn.load(model_path("models/pendulum.json")),
                                               0.1, integrator="rk4\x00"), "integrator")]:
        with pytest.raises(ValueError) as e:
            call()
        assert str(e.value).startswith(arg + ": '")
        assert "contains a NUL character" in str(e.value)


def run_cli(*args, cwd=ROOT):
    return subprocess.run([str(BINARY).encode(), *args], cwd=cwd, capture_output=True)


@pytest.mark.parametrize("raw", [b"\x1b[2J", b"x\ny", b"\x7f", b"\xc2\x9b", b"\xff"])
def test_cli_messages_are_one_line_without_control_bytes(tmp_path, raw):
    pendulum = model_path("models/pendulum.json").encode()
    (tmp_path / "file").write_text("")
    for args, code in [([raw], 2), ([b"info", pendulum, b"--" + raw], 2), ([b"info", raw], 1),
                       ([b"simulate", pendulum, b"--t-end", b"1", b"--integrator", raw], 2),
                       ([b"simulate", pendulum, b"--t-end", b"1", b"--tau-csv", raw], 1),
                       ([b"import", raw + b".urdf", b"-o", b"out.json"], 1)]:
        r = run_cli(*args, cwd=tmp_path)
        assert r.returncode == code, r.stderr
        assert r.stderr.endswith(b"\n")
        line = r.stderr[:-1].decode("utf-8")  # valid UTF-8: bytes that are not are escaped
        assert one_printable_line(line), line


@pytest.mark.parametrize("names", [("a,b", "c"), ('say "hi"', "x, y")])
def test_csv_columns_do_not_shift_with_pandas(tmp_path, names):
    model = tmp_path / "m.json"
    model.write_text(json.dumps(two_joints(*names)))
    out = tmp_path / "traj.csv"
    r = run_cli(b"simulate", str(model).encode(), b"--t-end", b"0.01", b"--integrator", b"rk4", b"--dt", b"0.005",
                b"--out", str(out).encode())
    assert r.returncode == 0, r.stderr
    frame = pd.read_csv(out)
    a, b = names
    assert list(frame.columns) == ["t", "q_" + a, "q_" + b, "qd_" + a, "qd_" + b, "kinetic",
                                   "potential", "total", "work"]
    assert frame.shape == (3, 9)
    assert np.allclose(frame["t"], [0, 0.005, 0.01])
    assert frame.notna().all().all()
    track = tmp_path / "track.csv"
    r = run_cli(b"track", str(model).encode(), b"--to", b"0.1,0.2", b"--duration", b"0.1",
                b"--steps", b"10", b"--csv", str(track).encode())
    assert r.returncode == 0, r.stderr
    frame = pd.read_csv(track)
    assert list(frame.columns) == ["t"] + [p + n for p in ("q_ref_", "tau_", "q_sim_")
                                           for n in names]
    assert frame.shape == (11, 7)
    assert frame.notna().all().all()
    # --tau-csv reads the quoted header back.
    tau = tmp_path / "tau.csv"
    pd.DataFrame({"t": [0.0, 1.0], "tau_" + a: [0.1, 0.1], b: [0.0, 0.0]}).to_csv(tau,
                                                                                  index=False)
    r = run_cli(b"simulate", str(model).encode(), b"--t-end", b"0.5", b"--tau-csv",
                str(tau).encode())
    assert r.returncode == 0, r.stderr
