"""Batches equal single calls exactly; forward and inverse dynamics invert each other; D
contracts to h; M^s and the energy agree with the equations."""
import numpy as np
import pytest

import femdyn
from conftest import MODELS, model_path, state


@pytest.fixture(scope="module", params=["models/finger.json", "models/finger_fourbar.json",
                                        "models/branched_tree.json", "models/hand.json",
                                        "models/urdf/hand16.urdf"])
def model(request):
    return femdyn.load(model_path(request.param))


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_batch_equals_single_calls(model, threads):
    k = 17
    q, qd, tau = state(model.n, seed=11, k=k)
    b = model.equations_batch(q, qd, tau, threads=threads)
    assert b["M"].shape == (k, model.n, model.n) and b["qdd"].shape == (k, model.n)
    assert b["ok"].all()
    fd = model.forward_dynamics_batch(q, qd, tau, threads=threads)
    inv = model.inverse_dynamics_batch(q, qd, fd, threads=threads)
    for i in range(k):
        eq = model.equations(q[i], qd[i], tau[i])
        assert np.array_equal(b["M"][i], eq.M)
        assert np.array_equal(b["h"][i], eq.h)
        assert np.array_equal(b["Q"][i], eq.Q)
        assert np.array_equal(b["qdd"][i], eq.qdd)
        assert np.array_equal(fd[i], model.forward_dynamics(q[i], qd[i], tau[i]))
        assert np.array_equal(inv[i], model.inverse_dynamics(q[i], qd[i], fd[i]))


def test_batch_defaults_and_empty(model):
    q, _, _ = state(model.n, seed=2, k=4)
    b = model.equations_batch(q)
    assert np.all(b["h"] == 0)
    assert np.array_equal(model.forward_dynamics_batch(q), b["qdd"])
    e = model.equations_batch(np.zeros((0, model.n)))
    assert e["M"].shape == (0, model.n, model.n)


def test_forward_inverse_round_trip(model):
    q, qd, tau = state(model.n, seed=5)
    qdd = model.forward_dynamics(q, qd, tau)
    back = model.inverse_dynamics(q, qd, qdd)
    assert np.allclose(back, tau, rtol=0, atol=1e-9 * (1 + np.abs(model.equations(q).Q).max()))
    eq = model.equations(q, qd, tau)
    assert np.allclose(eq.M @ qdd + eq.h, eq.Q, rtol=1e-10,
                       atol=1e-10 * np.abs(eq.Q).max())


def test_tensor_contracts_to_h(model):
    q, qd, _ = state(model.n, seed=9)
    D = model.tensor(q)
    assert D.shape == (model.n,) * 3
    h = np.einsum("abc,b,c->a", D, qd, qd)
    ref = model.bias(q, qd)
    assert np.allclose(h, ref, rtol=0, atol=1e-11 * max(1, np.abs(ref).max()))
    assert np.array_equal(ref, model.equations(q, qd).h) or np.allclose(
        ref, model.equations(q, qd).h, rtol=1e-13, atol=1e-13 * np.abs(ref).max())


def test_mass_matrix_and_energy(model):
    q, qd, _ = state(model.n, seed=4)
    M = model.mass_matrix(q)
    assert np.allclose(M, model.equations(q).M, rtol=1e-13, atol=1e-13 * np.abs(M).max())
    assert np.allclose(M, M.T, rtol=0, atol=1e-14 * np.abs(M).max())
    e = model.energy(q, qd)
    assert e["kinetic"] == pytest.approx(0.5 * qd @ M @ qd, rel=1e-12)
    assert e["total"] == pytest.approx(e["kinetic"] + e["potential"], rel=1e-15)


def test_inputs_read_in_place_and_untouched(model):
    q, qd, tau = state(model.n, seed=1, k=3)
    copies = [x.copy() for x in (q, qd, tau)]
    model.equations_batch(q, qd, tau)
    for x, c in zip((q, qd, tau), copies):
        assert np.array_equal(x, c)
    # Fortran order, int dtype and lists are converted, with the same result
    assert np.array_equal(model.forward_dynamics_batch(np.asfortranarray(q), qd, tau),
                          model.forward_dynamics_batch(q, qd, tau))
    assert np.array_equal(model.equations([0] * model.n).M,
                          model.equations(np.zeros(model.n)).M)


def test_batches_and_simulate_release_the_gil():
    """While a batch (or a simulation) runs in one Python thread, another keeps running."""
    import threading
    import time

    model = femdyn.load(model_path("models/hand.json"))
    q, qd, tau = state(model.n, seed=3, k=20000)
    calls = [lambda: model.equations_batch(q, qd, tau, threads=1),
             lambda: femdyn.simulate(model, 2.0, q[0], qd[0], integrator="rk4", dt=1e-4)]
    for call in calls:
        worker = threading.Thread(target=call)
        start = time.perf_counter()
        worker.start()
        count = 0
        while worker.is_alive():
            count += 1
        worker.join()
        elapsed = time.perf_counter() - start
        assert elapsed > 0.02  # long enough to tell
        assert count > 1000, (count, elapsed)
