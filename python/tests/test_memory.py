"""Memory refused up front (core/workspace/memory.hpp, issue 22): every call that allocates by its
arguments' size estimates the memory first and, beyond the limit, raises a ValueError with one
line: what needs how much, the limit, and how to proceed. The tests lower the limit with
femdyn.set_max_memory, so nothing depends on the machine's memory."""
import numpy as np
import pytest

import femdyn
from conftest import model_path


@pytest.fixture
def small_limit():
    femdyn.set_max_memory(1e-4)  # 100 kB
    yield
    femdyn.set_max_memory(None)


@pytest.fixture(scope="module")
def finger():
    return femdyn.load(model_path("models/finger.json"))


def test_simulate_t_eval_is_refused_up_front(finger, small_limit):
    with pytest.raises(ValueError) as e:
        femdyn.simulate(finger, 1.0, t_eval=np.linspace(0, 1, 100000))
    text = str(e.value)
    assert text.startswith("simulate: n = 4 coordinates with dopri and 1e+05 rows needs ")
    assert text.endswith("if that much memory is free, or fewer t_eval times")
    assert "femdyn.set_max_memory(" in text and "\n" not in text


def test_fixed_step_rows_are_refused_up_front(finger, small_limit):
    with pytest.raises(ValueError, match=r"^simulate: .* rows needs .*a larger every$"):
        femdyn.simulate(finger, 10.0, integrator="rk4", dt=1e-4)


def test_batches_are_refused_up_front(finger, small_limit):
    q = np.zeros((2000, 4))
    with pytest.raises(ValueError, match=r"^equations_batch of 2000 states of n = 4 coordinates "
                                         r"on \d+ threads needs .* split the batch into parts"):
        finger.equations_batch(q)
    with pytest.raises(ValueError, match=r"^forward_dynamics_batch of 20000 states"):
        finger.forward_dynamics_batch(np.zeros((20000, 4)), threads=1)  # 640 kB of results


def test_within_the_limit_nothing_changes(finger):
    femdyn.set_max_memory(1.0)
    try:
        r = finger.equations_batch(np.zeros((10, 4)))
        assert r["M"].shape == (10, 4, 4)
    finally:
        femdyn.set_max_memory(None)
    with pytest.raises(ValueError, match="^max_memory: expected a positive number of GB"):
        femdyn.set_max_memory(-1)


@pytest.mark.skipif(not femdyn.with_simbody, reason="built without Simbody")
def test_validate_samples_are_refused_up_front(finger):
    """samples=10**9 took 22 s and 4 GB before "MemoryError: std::bad_alloc"; its samples are in
    the estimate, so it is refused before any state."""
    with pytest.raises(ValueError, match=r"validating n = 4 coordinates .* of memory, beyond"):
        femdyn.validate(finger, samples=10**9, max_memory=1.0)


def test_derivatives_are_refused_up_front():
    """derivatives, linearize and inverse_derivatives estimate their n × n buffers and results
    first (they ended in numpy's MemoryError on a 10,000-body tree: issue 45)."""
    m = femdyn.load(model_path("models/hand.json"))
    q = m.neutral_configuration()
    femdyn.set_max_memory(1e-5)  # 10 kB: below the hand's 22 x 22 buffers
    try:
        for call in ("derivatives", "linearize", "inverse_derivatives"):
            with pytest.raises(ValueError, match=rf"^{call} of n = 22 coordinates needs .* "
                                                 r"femdyn\.set_max_memory\("):
                getattr(m, call)(q)
    finally:
        femdyn.set_max_memory(None)
    assert m.linearize(q)[0].shape == (44, 44)
