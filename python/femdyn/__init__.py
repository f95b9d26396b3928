"""femdyn from Python: equations of motion of mechanisms by the equivalent-element method.

    import femdyn
    model = femdyn.load("models/finger.json")
    eq = model.equations(q, qd, tau)        # eq.M, eq.h, eq.Q, eq.qdd (numpy)

docs/python.md describes the module. Errors: femdyn.ModelError (a ValueError) for a bad model
file, femdyn.NumericalError (an ArithmeticError) for a singular mass matrix or an overflow at a
state, ValueError for a bad argument ("q: expected shape (4,), got (3,)", NaN or Inf entries).

The compiled extension femdyn._femdyn is built for one interpreter (femdyn/_build_info.py, written
by CMake): under another Python version, or a Python without numpy, importing femdyn raises an
ImportError that names both interpreters.
"""
import sys

from . import _build_info

__version__ = _build_info.version  # CMake's project(VERSION), as `femdyn --version` prints it


def _interpreter_error(error):
    """The extension (or numpy, which every call needs) cannot be imported here: say which
    interpreter femdyn was built for and which one this is, with the original reason."""
    here = "%d.%d" % sys.version_info[:2]
    # The reason with its causes: pybind11's "initialization failed" is caused by, e.g., "No
    # module named 'numpy'".
    reasons = [str(error)]
    while error.__cause__ is not None and len(reasons) < 4:
        error = error.__cause__
        reasons.append(str(error))
    return ImportError(
        f"femdyn was built for Python {_build_info.python_version} "
        f"({_build_info.python_executable}); this is Python {here} ({sys.executable}): "
        f"{': '.join(reasons)}. Run femdyn with {_build_info.python_executable}, or build it for "
        f"this interpreter (cmake -DPython3_EXECUTABLE={sys.executable})", name=__name__)


# The extension first (under another Python version its file name does not match), then numpy,
# which every argument and result needs (pybind11's module initialisation imports it already).
try:
    from ._femdyn import (  # noqa: F401
        Builder,
        Equations,
        Model,
        ModelError,
        NumericalError,
        Simulator,
        load,
        loads,
        set_max_memory,
        simulate,
        with_simbody,
    )

    import numpy  # noqa: F401
except ImportError as _error:
    raise _interpreter_error(_error) from _error

from ._sweep import grid, sweep  # noqa: F401,E402  (pandas and dask are imported on use)

if with_simbody:
    from ._femdyn import validate  # noqa: F401

__all__ = ["Builder", "Equations", "Model", "ModelError", "NumericalError", "grid", "load",
           "loads", "set_max_memory", "simulate", "sweep", "with_simbody"] + (["validate"] if with_simbody else [])

if hasattr(Model, "_write_view"):  # built with the 3-D view (web/node_modules, docs/view.md)
    from ._view import view as _view

    Model.view = _view
    del _view

for _cls in (Builder, Equations, Model, ModelError, NumericalError):
    _cls.__module__ = "femdyn"
del _cls
