"""femdyn.Builder: a mechanism described in Python without JSON is the model its JSON file
loads (to the bit), and bad arguments get the loader's messages (docs/python.md, "Builder")."""
import json

import numpy as np
import pytest

import femdyn
from conftest import model_path, state

# Every element form, a four-bar law closed by a rod, a polynomial of two joints, a linear
# coupling, a spring, a damper, limits and a load (the model of tests/test_builder.cpp).
DOCUMENT = {
    "name": "everything", "gravity": [0.3, -9.81, -1.0],
    "bodies": [
        {"name": "crank", "parent": "world",
         "joint": {"name": "j1", "type": "revolute", "axis": [0, 0, 1]},
         "nodes": {"tip": [0.1, 0, 0]},
         "elements": [{"type": "lumped_point", "node": "tip", "mass": 0.2},
                      {"type": "rod", "nodes": ["tip", "rocker/tip"], "mass": 0.05}]},
        {"name": "rocker", "parent": "world",
         "joint": {"name": "j2", "type": "revolute", "axis": [0, 0, 1],
                   "origin": {"xyz": [0.3, 0, 0]}},
         "nodes": {"tip": [0.2, 0, 0]},
         "elements": [{"type": "lumped_point", "node": "tip", "mass": 0.3},
                      {"type": "rotary_node", "node": [0.1, 0, 0],
                       "inertia": [[0.001, 0.0001, 0], [0.0001, 0.002, 0], [0, 0, 0.0025]]}]},
        {"name": "arm", "parent": "rocker",
         "joint": {"name": "j3", "type": "revolute", "axis": [0, 1, 0.2],
                   "origin": {"xyz": [0.2, 0, 0], "rpy": [0.1, 0.2, 0.3]},
                   "spring": {"stiffness": 2, "rest": 0.3}, "damping": 0.05},
         "elements": [{"type": "rigid_body", "mass": 0.5, "com": [0.1, 0, 0.01],
                       "inertia": [[0.002, 0.0002, 0], [0.0002, 0.003, 0.0001],
                                   [0, 0.0001, 0.004]]}]},
        {"name": "slider", "parent": "arm",
         "joint": {"name": "j4", "type": "prismatic", "axis": [1, 0.2, 0],
                   "origin": {"xyz": [0.25, 0, 0]}, "limits": [-0.2, 0.3]},
         "elements": [{"type": "space_bar", "nodes": [[0, 0, 0], [0.2, 0.02, 0]], "mass": 0.4,
                       "inertia": [[0.0001, 0, 0], [0, 0.0014, 0], [0, 0, 0.0014]]}]},
        {"name": "hand", "parent": "slider",
         "joint": {"name": "j5", "type": "revolute", "axis": [1, 0, 0],
                   "origin": {"xyz": [0.2, 0.02, 0]}},
         "elements": [{"type": "lumped_point", "node": [0, 0.05, 0], "mass": 0.1},
                      {"type": "space_bar", "nodes": [[0, 0, 0], [0.01, 0.1, 0.02]],
                       "density": 2700, "area": 1e-4, "Iy": 2e-9, "Iz": 3e-9,
                       "section_y": [1, 0, 0.3]}]},
        {"name": "finger", "parent": "hand",
         "joint": {"name": "j6", "type": "revolute", "axis": [0, 0, 1],
                   "origin": {"xyz": [0, 0.05, 0]}},
         "elements": [{"type": "lumped_point", "node": [0.04, 0, 0], "mass": 0.05}]}],
    "couplings": [
        {"joint": "j2", "follows": "j1",
         "four_bar": {"ground": 0.3, "input": 0.1, "coupler": 0.35, "output": 0.2,
                      "output_offset": 0}},
        {"joint": "j5", "follows": ["j3", "j4"], "polynomial": [[0.5, 1, 0], [0.2, 1, 1]]},
        {"joint": "j6", "follows": [{"joint": "j3", "ratio": -0.7}], "offset": 0.1}],
    "loads": [{"body": "arm", "point": [0.1, 0, 0.05], "force": [1, -2, 0.5],
               "torque": [0.1, 0, -0.2]}]}


def built():
    b = femdyn.Builder("everything", gravity=[0.3, -9.81, -1.0])
    b.body("crank", "world", type="revolute", joint="j1", axis=[0, 0, 1])
    b.node("crank", "tip", [0.1, 0, 0])
    b.body("rocker", "world", type="revolute", joint="j2", axis=[0, 0, 1], xyz=[0.3, 0, 0])
    b.node("rocker", "tip", [0.2, 0, 0])
    b.lumped_point("crank", "tip", 0.2)
    b.rod("crank", "tip", "rocker/tip", 0.05)
    b.lumped_point("rocker", "tip", 0.3)
    b.rotary_node("rocker", [0.1, 0, 0], [[0.001, 0.0001, 0], [0.0001, 0.002, 0], [0, 0, 0.0025]])
    b.body("arm", "rocker", type="revolute", joint="j3", axis=[0, 1, 0.2], xyz=[0.2, 0, 0],
           rpy=[0.1, 0.2, 0.3], stiffness=2, rest=0.3, damping=0.05)
    b.rigid_body("arm", 0.5, [0.1, 0, 0.01],
                 np.array([[0.002, 0.0002, 0], [0.0002, 0.003, 0.0001], [0, 0.0001, 0.004]]))
    b.body("slider", "arm", type="prismatic", joint="j4", axis=[1, 0.2, 0], xyz=[0.25, 0, 0],
           limits=(-0.2, 0.3))
    b.space_bar("slider", [0, 0, 0], [0.2, 0.02, 0], 0.4, np.diag([0.0001, 0.0014, 0.0014]))
    b.body("hand", "slider", type="revolute", joint="j5", axis=[1, 0, 0], xyz=[0.2, 0.02, 0])
    b.lumped_point("hand", [0, 0.05, 0], 0.1)
    b.space_bar("hand", [0, 0, 0], [0.01, 0.1, 0.02], density=2700, area=1e-4, Iy=2e-9, Iz=3e-9,
                section_y=[1, 0, 0.3])
    b.body("finger", "hand", type="revolute", joint="j6", axis=[0, 0, 1], xyz=[0, 0.05, 0])
    b.lumped_point("finger", [0.04, 0, 0], 0.05)
    b.coupling("j2", "j1", four_bar={"ground": 0.3, "input": 0.1, "coupler": 0.35,
                                     "output": 0.2, "output_offset": 0})
    b.coupling("j5", ["j3", "j4"], polynomial=[[0.5, 1, 0], [0.2, 1, 1]])
    b.coupling("j6", [{"joint": "j3", "ratio": -0.7}], offset=0.1)
    b.load("arm", point=[0.1, 0, 0.05], force=[1, -2, 0.5], torque=[0.1, 0, -0.2])
    return b.build()


@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    path = tmp_path_factory.mktemp("builder") / "everything.json"
    path.write_text(json.dumps(DOCUMENT))
    return built(), femdyn.load(str(path))


def test_builder_equals_json(pair):
    a, b = pair
    assert a.coordinates == b.coordinates == ["j1", "j3", "j4"]
    assert a.n_u == b.n_u
    assert a.correlation_table() == b.correlation_table()
    assert a.info() == b.info()
    for seed in range(8):
        q, qd, tau = state(a.n, seed)
        ea, eb = a.equations(q, qd, tau), b.equations(q, qd, tau)
        for key in ("M", "h", "Q", "qdd"):
            assert np.array_equal(ea[key], eb[key]), key  # the same arithmetic: to the bit
        assert np.array_equal(a.tensor(q), b.tensor(q))
        assert a.energy(q, qd) == b.energy(q, qd)


def test_builder_model_validates_against_simbody(pair):
    if not femdyn.with_simbody:
        pytest.skip("built without Simbody")
    report = femdyn.validate(pair[0], states=5, t_end=0.05)
    assert report["pass"], report


@pytest.mark.parametrize("call,error,message", [
    (lambda b: b.lumped_point("link", [0, 0, -1], -1), femdyn.ModelError,
     "arm (builder): /bodies/0/elements/0/mass: must be positive, got -1"),
    (lambda b: b.lumped_point("link", "tip", 1), femdyn.ModelError,
     "arm (builder): /bodies/0/elements/0/node: unknown node 'tip' (not in the body's nodes)"),
    (lambda b: b.lumped_point("nope", [0, 0, 0], 1), femdyn.ModelError,
     "unknown body 'nope'"),
    (lambda b: b.rotary_node("link", [0, 0, 0], np.diag([1, 1, 3])), femdyn.ModelError,
     "arm (builder): /bodies/0/elements/0/inertia: inertia violates the triangle inequality"),
    (lambda b: b.rigid_body("link", 1, [0, 0], np.eye(3)), ValueError,
     "com: expected shape (3,), got (2,)"),
    (lambda b: b.rigid_body("link", 1, [0, np.nan, 0], np.eye(3)), ValueError, "com: NaN or Inf"),
    (lambda b: b.rod("link", [0, 0, 0], [1, 0, 0], 1e300), femdyn.ModelError,
     "is out of range"),
    (lambda b: b.body("x", "world", type="hinge"), ValueError, "joint type: unknown 'hinge'"),
    (lambda b: b.coupling("j", "k", four_bar={"ground": -1}), femdyn.ModelError,
     "arm (builder): /couplings/0/four_bar/ground: must be positive, got -1"),
    (lambda b: b.coupling("j", "k", ratio="x"), femdyn.ModelError, "/couplings/0/ratio"),
    (lambda b: b.coupling("j", object()), TypeError, "follows: cannot use a object here"),
    (lambda b: b.load("link", force=[1, 2]), ValueError, "force: expected shape (3,), got (2,)"),
])
def test_builder_bad_arguments(call, error, message):
    b = femdyn.Builder("arm")
    b.body("link", "world", type="revolute", joint="j")
    with pytest.raises(error) as e:
        call(b)
    assert message in str(e.value)


def test_builder_compile_errors_name_the_place():
    b = femdyn.Builder("arm")
    b.body("link", "world", type="revolute", joint="j")
    b.lumped_point("link", [0, 0, -1], 1)
    b.body("other", "missing", type="revolute")
    with pytest.raises(femdyn.ModelError, match=r"^arm \(builder\): /bodies/1"):
        b.build()
    # A failed call leaves the builder as it was: the model still builds without it.
    b2 = femdyn.Builder("ok")
    b2.body("link", "world", type="revolute")
    with pytest.raises(femdyn.ModelError):
        b2.lumped_point("link", [1, 0, 0], -2)
    b2.lumped_point("link", [1, 0, 0], 2)  # 1 m from the z axis: M = m l² = 2
    assert b2.build().mass_matrix([0.0])[0, 0] == pytest.approx(2.0)


@pytest.mark.parametrize("argument,value", [
    ("axis", [0, 1, 0]), ("damping", 0.1), ("stiffness", 2.0), ("rest", 0.3),
    ("limits", (-1, 1)), ("xyz", [0.1, 0, 0]), ("rpy", [0, 0, 0.5]), ("joint", "elbow"),
    ("damping", 0.0),  # given is given, whatever its value
])
def test_joint_arguments_without_a_type_are_refused(argument, value):
    """A body without type= is welded to its parent: a joint argument given with it would be
    ignored (or weld a body meant to move), so it is a ValueError naming the argument, and the
    builder is left as it was."""
    b = femdyn.Builder("arm")
    with pytest.raises(ValueError, match=rf"^{argument}: given without a joint type"):
        b.body("link", "world", **{argument: value})
    b.body("link", "world", type="revolute", **{argument: value})  # with a type it is a joint
    b.lumped_point("link", [0.5, 0, 0], 1.0)
    assert b.build().n == 1


@pytest.mark.parametrize("argument,value", [
    ("axis", [0, 0, 1]), ("damping", 0.1), ("stiffness", 2.0), ("rest", 0.3), ("limits", (-1, 1)),
])
def test_a_fixed_joint_takes_no_motion_arguments(argument, value):
    """As the JSON loader refuses them on a fixed joint (docs/model-format.md)."""
    b = femdyn.Builder("arm")
    with pytest.raises(ValueError, match=rf"^{argument}: a fixed joint has no motion"):
        b.body("link", "world", type="fixed", **{argument: value})


def test_a_weld_is_said_with_type_fixed():
    """A welded body: without type= (at the parent's origin), or with type='fixed' and its
    origin and name. Neither adds a coordinate; the link below keeps M = m l² = 1 * 0.5²."""
    masses = []
    for weld in ({}, {"type": "fixed", "xyz": [0.2, 0, 0], "joint": "weld"}):
        b = femdyn.Builder("arm")
        b.body("base", "world", **weld)
        b.body("link", "base", type="revolute", axis=[0, 0, 1])
        b.lumped_point("link", [0.5, 0, 0], 1.0)
        model = b.build()
        assert model.coordinates == ["link"]
        masses.append(model.mass_matrix([0.0])[0, 0])
    assert masses[0] == pytest.approx(0.25) and masses[1] == pytest.approx(0.25)


JOINTS = {
    "name": "every joint", "gravity": [0, -9.81, 0],
    "bodies": [
        {"name": "base", "parent": "world", "joint": {"name": "base", "type": "free"},
         "elements": [{"type": "rigid_body", "mass": 3, "com": [0, 0, 0],
                       "inertia": {"ixx": 0.1, "iyy": 0.12, "izz": 0.08}}]},
        {"name": "cardan", "parent": "base",
         "joint": {"name": "u", "type": "universal", "axis": [0, 0, 1], "axis2": [1, 0, 0],
                   "origin": {"xyz": [0.2, 0, 0]}},
         "elements": [{"type": "rigid_body", "mass": 1, "com": [0.1, 0, 0],
                       "inertia": {"ixx": 0.01, "iyy": 0.02, "izz": 0.02}}]},
        {"name": "screw", "parent": "cardan",
         "joint": {"name": "s", "type": "helical", "axis": [1, 0, 0], "pitch": 0.01,
                   "origin": {"xyz": [0.2, 0, 0]}},
         "elements": [{"type": "rigid_body", "mass": 0.5, "com": [0.05, 0.02, 0],
                       "inertia": {"ixx": 0.002, "iyy": 0.003, "izz": 0.003}}]}]}


def test_builder_takes_every_joint_type_with_axis2_and_pitch(tmp_path):
    b = femdyn.Builder("every joint", gravity=[0, -9.81, 0])
    b.body("base", "world", type="free")
    b.rigid_body("base", 3, [0, 0, 0], np.diag([0.1, 0.12, 0.08]))
    b.body("cardan", "base", type="universal", joint="u", axis=[0, 0, 1], axis2=[1, 0, 0],
           xyz=[0.2, 0, 0])
    b.rigid_body("cardan", 1, [0.1, 0, 0], np.diag([0.01, 0.02, 0.02]))
    b.body("screw", "cardan", type="helical", joint="s", axis=[1, 0, 0], pitch=0.01,
           xyz=[0.2, 0, 0])
    b.rigid_body("screw", 0.5, [0.05, 0.02, 0], np.diag([0.002, 0.003, 0.003]))
    a = b.build()
    path = tmp_path / "joints.json"
    path.write_text(json.dumps(JOINTS))
    j = femdyn.load(str(path))
    assert a.coordinates == j.coordinates and a.n == 9
    rng = np.random.default_rng(5)
    q = rng.uniform(-1, 1, 10)
    q[3:7] /= np.linalg.norm(q[3:7])
    qd, tau = rng.uniform(-1, 1, 9), rng.uniform(-1, 1, 9)
    ea, ej = a.equations(q, qd, tau), j.equations(q, qd, tau)
    for key in ("M", "h", "Q", "qdd"):
        assert np.array_equal(ea[key], ej[key]), key
    with pytest.raises(ValueError, match="pitch: only a helical joint has a pitch"):
        femdyn.Builder("x").body("a", type="revolute", pitch=0.1)
    with pytest.raises(ValueError, match="axis2: given without a joint type"):
        femdyn.Builder("x").body("a", axis2=[1, 0, 0])
    b2 = femdyn.Builder("x")
    b2.body("a", type="universal", axis=[0, 0, 1])
    b2.lumped_point("a", [0.1, 0, 0], 1)
    with pytest.raises(femdyn.ModelError, match="a universal joint needs its second axis"):
        b2.build()


def test_builder_joint_takes_a_sample_range():
    # sample_range= is the JSON key's (docs/model-format.md): the same model, shown by info;
    # refused where it is not positive, and on a joint of several coordinates (compile's words).
    b = femdyn.Builder("arm")
    b.body("link", "world", type="revolute", joint="j", sample_range=0.2)
    b.lumped_point("link", [0.5, 0, 0], 1.0)
    doc = {"name": "arm", "bodies": [{"name": "link", "parent": "world",
           "joint": {"name": "j", "type": "revolute", "axis": [0, 0, 1], "sample_range": 0.2},
           "elements": [{"type": "lumped_point", "node": [0.5, 0, 0], "mass": 1.0}]}]}
    a, c = b.build(), femdyn.loads(json.dumps(doc))
    assert a.info()["joints"] == c.info()["joints"]
    assert a.info()["joints"][0]["sample_range"] == 0.2
    with pytest.raises(ValueError, match="sample_range: must be positive"):
        femdyn.Builder("x").body("link", "world", type="revolute", sample_range=0)
    bad = femdyn.Builder("ball")
    bad.body("link", "world", type="spherical", sample_range=0.2)
    bad.lumped_point("link", [0.5, 0, 0], 1.0)
    with pytest.raises(femdyn.ModelError, match="sample_range: is the half range of a joint of one"):
        bad.build()
