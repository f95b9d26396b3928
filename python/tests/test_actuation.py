"""Actuation (docs/control.md#actuation): Model.actuated as the model says, the Builder's
actuated=, and every Python door that runs the mechanism under a tau refusing one on a coordinate
no actuator drives, as the CLI does."""
import numpy as np
import pytest

import femdyn
from conftest import model_path


def satellite(elbow_actuated=None):
    """A free-floating bus (50 kg) with a two-joint arm: 'shoulder' about z, 'elbow' about y."""
    b = femdyn.Builder("satellite", gravity=[0, 0, 0])
    b.body("bus", "world", type="free", joint="base")
    b.rigid_body("bus", 50, [0, 0, 0], [[4, 0, 0], [0, 5, 0], [0, 0, 6]])
    b.body("upper", "bus", type="revolute", joint="shoulder", xyz=[0.5, 0, 0])
    b.rigid_body("upper", 2, [0.3, 0, 0], [[0.01, 0, 0], [0, 0.06, 0], [0, 0, 0.06]])
    extra = {} if elbow_actuated is None else {"actuated": elbow_actuated}
    b.body("fore", "upper", type="revolute", joint="elbow", axis=[0, 1, 0], xyz=[0.6, 0, 0],
           **extra)
    b.rigid_body("fore", 1, [0.25, 0, 0.02], [[0.005, 0, 0], [0, 0.03, 0], [0, 0, 0.03]])
    return b.build()


def test_actuated_as_the_model_says():
    assert satellite().actuated == [6, 7]  # the free base's 6 rates are not driven
    assert satellite(elbow_actuated=False).actuated == [6]
    assert satellite(elbow_actuated=True).actuated == [6, 7]
    assert femdyn.load(model_path("models/finger.json")).actuated == [0, 1, 2, 3]
    five_bar = femdyn.load(model_path("models/five_bar.json"))  # its elbows are passive
    assert [five_bar.coordinates[i] for i in five_bar.actuated] == ["theta1", "theta2"]
    b = femdyn.Builder("weld")
    with pytest.raises(ValueError, match="without a joint type"):
        b.body("a", "world", actuated=True)


def test_runs_refuse_tau_off_the_actuated_coordinates():
    m = satellite(elbow_actuated=False)
    q0 = m.neutral_configuration()
    on_bus = np.zeros(m.n)
    on_bus[0] = 1.0
    on_elbow = np.zeros(m.n)
    on_elbow[7] = 0.5
    driven = np.zeros(m.n)
    driven[6] = 0.2
    for tau, who in ((on_bus, "'base.vx'.*free joint"), (on_elbow, "'elbow'.*actuated")):
        with pytest.raises(ValueError, match=who):
            femdyn.simulate(m, 0.01, q0=q0, tau=tau)
        with pytest.raises(ValueError, match=who):
            femdyn.simulate(m, 0.01, q0=q0, tau_t=np.array([0.0, 0.01]), tau=np.vstack([driven, tau]))
        sim = femdyn.Simulator(m, integrator="rk4", dt=1e-3, q0=q0)
        with pytest.raises(femdyn.NumericalError, match=who):
            sim.step(tau)
        with pytest.raises(ValueError, match=who):
            sim.run(lambda t, q, qd, tau=tau: tau, 0.005)
    assert femdyn.simulate(m, 0.01, q0=q0, tau=driven)["t"][-1] == pytest.approx(0.01)
    sim = femdyn.Simulator(m, integrator="rk4", dt=1e-3, q0=q0)
    sim.step(driven)
    assert sim.state["qd"][6] > 0  # the shoulder turns; the bus turns back (momentum)
    assert sim.state["qd"][5] < 0


def test_linearize_inputs_are_the_actuated_coordinates():
    m = satellite(elbow_actuated=False)
    q = m.neutral_configuration()
    q[7] = 0.3
    qd = np.linspace(-0.2, 0.3, m.n)
    A, B = m.linearize(q, qd)
    assert A.shape == (2 * m.n, 2 * m.n) and B.shape == (2 * m.n, 1)
    Minv = m.derivatives(q, qd)["Minv"]
    assert np.array_equal(B[m.n:, 0], Minv[:, 6]) and not B[:m.n].any()
