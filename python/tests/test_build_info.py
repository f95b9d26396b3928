"""What this build is: femdyn.__version__ (CMake's project VERSION, the string `femdyn --version`
prints), and the ImportError that names both interpreters when femdyn is imported by a Python
it was not built for (docs/python.md, "Build and import")."""
import os
import pathlib
import re
import shutil
import subprocess
import sys

import pytest

import femdyn
from conftest import BINARY, ROOT

PACKAGE = pathlib.Path(femdyn.__file__).parent


def test_version_is_cmakes_and_the_clis():
    cmake = re.search(r"project\(femdyn VERSION ([0-9.]+)", (ROOT / "CMakeLists.txt").read_text())
    assert femdyn.__version__ == cmake.group(1)
    cli = subprocess.run([str(BINARY), "--version"], capture_output=True, text=True)
    assert cli.returncode == 0 and cli.stdout == f"femdyn {femdyn.__version__}\n"


def built_for():
    """The Python version the extension was compiled for, from its file name (cpython-311-…)."""
    (extension,) = PACKAGE.glob("_femdyn.*.so")
    tag = re.search(r"\.cpython-(\d)(\d+)", extension.name)
    return f"{tag.group(1)}.{tag.group(2)}"


def import_error(python, path):
    """The last line of what `python -c "import femdyn"` prints with `path` (a list of
    directories) as its PYTHONPATH."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(map(str, path)))
    out = subprocess.run([python, "-c", "import femdyn"], cwd=path[0], env=env,
                         capture_output=True, text=True, timeout=120)
    assert out.returncode != 0
    return out.stderr.strip().splitlines()[-1]


def check_message(line, python_version, executable, reason):
    """The message names the build's interpreter (a real one, of the extension's version), this
    interpreter, and the original reason."""
    built = re.match(r"ImportError: femdyn was built for Python (\d+\.\d+) \((.+?)\); this is "
                     r"Python (\d+\.\d+) \((.+?)\): (.+)$", line)
    assert built, line
    assert built.group(1) == built_for()
    version = "import sys; print('%d.%d' % sys.version_info[:2])"
    named = subprocess.run([built.group(2), "-c", version], capture_output=True, text=True)
    assert named.stdout.strip() == built_for()
    assert built.group(3) == python_version and built.group(4) == executable
    assert reason in built.group(5)
    assert f"Run femdyn with {built.group(2)}" in line


def test_without_the_extension(tmp_path):
    """The package as another Python version sees it: its ABI tag finds no _femdyn (simulated by
    a copy of the pure-Python files alone)."""
    (tmp_path / "femdyn").mkdir()
    for f in PACKAGE.glob("*.py"):
        shutil.copy(f, tmp_path / "femdyn")
    line = import_error(sys.executable, [tmp_path])
    check_message(line, "%d.%d" % sys.version_info[:2], sys.executable,
                  "No module named 'femdyn._femdyn'")


def test_without_numpy(tmp_path):
    """A Python of the right version without numpy (simulated by a numpy that cannot be
    imported, first on the path): every call needs numpy, so the import says so at once."""
    (tmp_path / "numpy").mkdir()
    (tmp_path / "numpy" / "__init__.py").write_text(
        "raise ModuleNotFoundError(\"No module named 'numpy'\", name='numpy')\n")
    line = import_error(sys.executable, [tmp_path, PACKAGE.parent])
    check_message(line, "%d.%d" % sys.version_info[:2], sys.executable,
                  "No module named 'numpy'")


def other_pythons():
    """Interpreters on PATH of another version than the extension's (none on most machines)."""
    found = []
    for minor in range(6, 20):
        name = f"python3.{minor}"
        path = shutil.which(name)
        if not path or f"3.{minor}" == built_for():
            continue
        run = subprocess.run([path, "-c", "import sys; print(sys.executable)"],
                             capture_output=True, text=True)
        if run.returncode == 0:  # (a pyenv shim of a version not enabled fails here)
            found.append((f"3.{minor}", run.stdout.strip()))
    return found


@pytest.mark.parametrize("version,executable", other_pythons() or [pytest.param(
    None, None, marks=pytest.mark.skip(reason="no Python of another version on PATH"))])
def test_another_python_version(version, executable):
    line = import_error(executable, [PACKAGE.parent])
    check_message(line, version, executable, "femdyn._femdyn")
