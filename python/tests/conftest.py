"""Shared fixtures: the repository, the femdyn CLI, and a seeded random state per model.

ctest sets FEMDYN_SOURCE_DIR, FEMDYN_BINARY and PYTHONPATH (python/CMakeLists.txt); run by hand:
    PYTHONPATH=build/python python3 -m pytest python/tests
"""
import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

ROOT = pathlib.Path(os.environ.get("FEMDYN_SOURCE_DIR",
                                   pathlib.Path(__file__).resolve().parents[2]))
BINARY = pathlib.Path(os.environ.get("FEMDYN_BINARY", ROOT / "build" / "femdyn"))

# Models of every kind: space bars, full inertias, every element type, couplings (linear and a
# four-bar law), URDF robots (mimic joints, prismatic axes), and a 22-DOF hand.
MODELS = ["models/pendulum.json", "models/finger.json", "models/finger_coupled.json",
          "models/finger_fourbar.json", "models/finger_paper.json",
          "models/spatial_double_pendulum.json", "models/branched_tree.json",
          "models/hand.json", "models/urdf/arm7.urdf", "models/urdf/hand16.urdf",
          "models/urdf/gantry.urdf"]


@pytest.fixture(scope="session")
def root():
    return ROOT


def model_path(name):
    return str(ROOT / name)


def state(n, seed, k=None):
    """q, qd, tau (shape (n,), or (k, n) with k): seeded, moderate."""
    rng = np.random.default_rng(seed)
    shape = (n,) if k is None else (k, n)
    return (rng.uniform(-0.5, 0.5, shape), rng.uniform(-2, 2, shape), rng.uniform(-1, 1, shape))


def numbers(x):
    """A vector as the CLI reads it, every double to round-trip precision."""
    return ",".join(repr(float(v)) for v in x)


def cli_json(*args):
    out = subprocess.run([str(BINARY), *map(str, args)], cwd=ROOT, capture_output=True,
                         text=True, check=True)
    return json.loads(out.stdout)


def subprocess_env():
    """The environment for a script run by a test: this femdyn first on an absolute PYTHONPATH
    (a relative one, as in a by-hand run, would not survive another working directory)."""
    import femdyn

    package_dir = os.path.dirname(os.path.dirname(os.path.abspath(femdyn.__file__)))
    path = [package_dir] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    return dict(os.environ, PYTHONPATH=os.pathsep.join(path), MPLBACKEND="Agg")
