"""Model.derivatives, inverse_derivatives and linearize against numpy central differences (flat
models: q + h e_k), the CLI's `femdyn linearize --json`, and the refusal of uncovered models."""
import numpy as np
import pytest

import femdyn
from conftest import cli_json, model_path, numbers, state

FLAT = ["models/finger.json", "models/finger_coupled.json", "models/branched_tree.json",
        "models/urdf/arm7.urdf", "models/finger_fourbar.json", "models/hand_fourbar.json",
        "models/iftomm_a05_flyball.json"]


def central(f, x, h=1e-6):
    cols = []
    for k in range(x.size):
        e = np.zeros_like(x)
        e[k] = h
        cols.append((f(x + e) - f(x - e)) / (2 * h))
    return np.stack(cols, axis=1)


def rel(a, b):
    return np.abs(a - b).max() / max(np.abs(b).max(), 1e-12)


@pytest.mark.parametrize("name", FLAT)
def test_forward_and_inverse_derivatives_against_differences(name):
    m = femdyn.load(model_path(name))
    q, qd, qdd0 = state(m.n, seed=5)
    # τ of a moderate q̈: a random τ on the light finger makes q̈ ~1e6 and its differences noise.
    tau = m.inverse_dynamics(q, qd, qdd0)
    d = m.derivatives(q, qd, tau)
    assert np.array_equal(d["qdd"], m.forward_dynamics(q, qd, tau))
    assert rel(d["dqdd_dq"], central(lambda x: m.forward_dynamics(x, qd, tau), q)) < 1e-7
    assert rel(d["dqdd_dv"], central(lambda x: m.forward_dynamics(q, x, tau), qd)) < 1e-7
    assert rel(d["Minv"] @ m.mass_matrix(q), np.eye(m.n)) < 1e-10
    qdd = d["qdd"]
    i = m.inverse_derivatives(q, qd, qdd)
    assert rel(i["tau"], tau) < 1e-10
    assert rel(i["dtau_dq"], central(lambda x: m.inverse_dynamics(x, qd, qdd), q)) < 1e-7
    assert rel(i["dtau_dv"], central(lambda x: m.inverse_dynamics(q, x, qdd), qd)) < 1e-7
    # ∂q̈/∂q = −M⁻¹ ∂τ/∂q at the q̈ of the state.
    assert rel(d["dqdd_dq"], -d["Minv"] @ i["dtau_dq"]) < 1e-10


@pytest.mark.parametrize("name", ["models/finger.json", "models/finger_fourbar.json",
                                  "models/iftomm_a05_flyball.json"])
def test_linearize_equals_the_cli(name):
    m = femdyn.load(model_path(name))
    q, qd, tau = state(m.n, seed=7)
    A, B = m.linearize(q, qd, tau)
    n = m.n
    assert A.shape == (2 * n, 2 * n) and B.shape == (2 * n, n)
    assert np.array_equal(A[:n, n:], np.eye(n)) and np.all(A[:n, :n] == 0)
    out = cli_json("linearize", name, "--q", numbers(q), "--qd", numbers(qd),
                   "--tau", numbers(tau), "--json")
    assert out["n"] == n and out["coordinates"] == m.coordinates
    assert np.array_equal(np.array(out["A"]), A) and np.array_equal(np.array(out["B"]), B)


def test_uncovered_model_is_refused():
    m = femdyn.load(model_path("models/finger_paper.json"))
    with pytest.raises(femdyn.ModelError, match="body-level form"):
        m.derivatives(np.zeros(m.n))


@pytest.mark.parametrize("threads", [1, 3])
@pytest.mark.parametrize("name", ["models/finger.json", "models/space_robot.json"])
def test_batches_equal_single_calls(name, threads):
    m = femdyn.load(model_path(name))
    rng = np.random.default_rng(8)
    k = 7
    q = np.tile(m.neutral_configuration(), (k, 1))
    if m.n_q == m.n:
        q += rng.uniform(-0.5, 0.5, q.shape)
    else:  # the free base's position, then the arm's joints (its quaternion kept)
        q[:, :3] += rng.uniform(-0.5, 0.5, (k, 3))
        q[:, 7:] += rng.uniform(-0.5, 0.5, (k, m.n_q - 7))
    qd = rng.uniform(-1, 1, (k, m.n))
    tau = rng.uniform(-1e-3, 1e-3, (k, m.n))
    d = m.derivatives_batch(q, qd, tau, threads=threads)
    A, B = m.linearize_batch(q, qd, tau, threads=threads)
    assert d["dqdd_dq"].shape == (k, m.n, m.n) and A.shape == (k, 2 * m.n, 2 * m.n)
    # B's inputs are the actuated coordinates' tau: all but a free base's (docs/control.md).
    assert B.shape == (k, 2 * m.n, len(m.actuated))
    for i in range(k):
        one = m.derivatives(q[i], qd[i], tau[i])
        for key in ("qdd", "dqdd_dq", "dqdd_dv", "Minv"):
            assert np.array_equal(d[key][i], one[key]), key
        a, b = m.linearize(q[i], qd[i], tau[i])
        assert np.array_equal(A[i], a) and np.array_equal(B[i], b)
        assert np.array_equal(b[m.n:], one["Minv"][:, m.actuated]) and not b[:m.n].any()


def test_batches_refuse_and_name_the_row():
    with pytest.raises(femdyn.ModelError):
        femdyn.load(model_path("models/finger_paper.json")).derivatives_batch(np.zeros((2, 4)))
    m = femdyn.load(model_path("models/finger.json"))
    q = np.zeros((3, m.n))
    assert m.derivatives_batch(np.zeros((0, m.n)))["Minv"].shape == (0, m.n, m.n)
    qd = np.zeros((3, m.n))
    qd[2, 0] = np.nan  # a bad row is named
    with pytest.raises(ValueError, match="row 2, entry 0"):
        m.derivatives_batch(q, qd)
    qd[2, 0] = 1e101  # beyond the range the equations' products stay finite in
    with pytest.raises(ValueError, match="row 2, entry 0"):
        m.linearize_batch(q, qd)
