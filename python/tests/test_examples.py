"""The worked example of docs/python.md and the batch benchmark run."""
import subprocess
import sys

from conftest import ROOT, subprocess_env


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
