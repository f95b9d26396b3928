"""femdyn from Python: equations of motion of mechanisms by the equivalent-element method.

    import femdyn
    model = femdyn.load("models/finger.json")
    eq = model.equations(q, qd, tau)        # eq.M, eq.h, eq.Q, eq.qdd (numpy)

docs/python.md describes the module. Errors: femdyn.ModelError (a ValueError) for a bad model
file, femdyn.NumericalError (an ArithmeticError) for a singular mass matrix or an overflow at a
state, ValueError for a bad argument ("q: expected shape (4,), got (3,)", NaN or Inf entries).
"""
from ._femdyn import (  # noqa: F401
    Builder,
    Equations,
    Model,
    ModelError,
    NumericalError,
    load,
    simulate,
    with_simbody,
)

from ._sweep import grid, sweep  # noqa: F401,E402  (pandas and dask are imported on use)

if with_simbody:
    from ._femdyn import validate  # noqa: F401

__all__ = ["Builder", "Equations", "Model", "ModelError", "NumericalError", "grid", "load", "simulate",
           "sweep", "with_simbody"] + (["validate"] if with_simbody else [])

for _cls in (Builder, Equations, Model, ModelError, NumericalError):
    _cls.__module__ = "femdyn"
del _cls
