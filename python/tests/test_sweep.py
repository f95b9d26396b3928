"""femdyn.grid and femdyn.sweep; the Dask example on a LocalCluster of 2 workers on 127.0.0.1
gives the numbers of the serial run."""
import subprocess
import sys

import pandas
import pytest

import femdyn
from conftest import ROOT, subprocess_env


def square(x, y):
    return {"z": x * x + y}


def test_grid_and_serial_sweep():
    cases = femdyn.grid(x=[1, 2, 3], y=[0, 10])
    assert cases[:3] == [{"x": 1, "y": 0}, {"x": 1, "y": 10}, {"x": 2, "y": 0}]
    table = femdyn.sweep(square, cases)
    assert isinstance(table, pandas.DataFrame)
    assert list(table.columns) == ["x", "y", "z"]
    assert list(table["z"]) == [1, 11, 4, 14, 9, 19]


def test_sweep_refuses_clashing_keys():
    with pytest.raises(ValueError, match="repeats its keys"):
        femdyn.sweep(lambda z: {"z": z}, [{"z": 1}])


def test_dask_example_equals_serial(tmp_path):
    env = subprocess_env()
    out = subprocess.run([sys.executable, str(ROOT / "examples" / "dask_sweep.py"), "--quick",
                          "--check-serial", "--out", str(tmp_path)], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    assert "distributed equals serial: True" in out.stdout
    table = pandas.read_csv(tmp_path / "finger_sweep.csv")
    assert len(table) == 8 and set(table["integrator"]) == {"rk4", "euler", "dopri", "bdf"}
    # order 4 and 1: halving rk4's step divides its error by about 16, euler's by 2
    rk4 = table[table.integrator == "rk4"]["error"].to_numpy()
    euler = table[table.integrator == "euler"]["error"].to_numpy()
    assert 10 < rk4[0] / rk4[1] < 20 and 1.8 < euler[0] / euler[1] < 2.2
    assert (tmp_path / "finger_sweep.png").stat().st_size > 10000


def test_dask_example_help_is_whole():
    """--help exits 0 with the docstring's whole first sentence (it used to stop at the end of
    the docstring's first line, mid-sentence), and every help text is a full sentence."""
    script = ROOT / "examples" / "dask_sweep.py"
    env = dict(subprocess_env(), COLUMNS="1000")  # argparse wraps at the width: no wrapping
    out = subprocess.run([sys.executable, str(script), "--help"], env=env, capture_output=True,
                         text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    text = " ".join(out.stdout.split())
    assert ("A parameter study on dask.distributed (docs/python.md#sweeps): the finger's error "
            "against run time across proximal link lengths and integrators.") in text
    assert "exits 1 unless every number but the timings is equal." in text  # the epilog, whole
    import importlib.util

    spec = importlib.util.spec_from_file_location("dask_sweep", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)  # (main() runs only as a script)
    parser = module.parser()
    helps = [a.help for a in parser._actions if a.help and a.dest != "help"]
    assert len(helps) == 4
    for h in [parser.description, parser.epilog] + helps:
        assert h[0].isupper() and h.endswith("."), h
        assert " ".join(h.split()) in text  # shown whole
