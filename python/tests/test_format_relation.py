"""One truth across formats (docs/robustness.md#one-truth): the same random mechanism written as
femdyn JSON, as URDF and as MJCF loads into the same equations. Each file is written here from one
random description, by rules of each format's own (URDF's link frames and rpy, MJCF's body pos and
quat with the joint at the body's origin), so that a reader that turns an axis, an origin or an
inertia differently fails. M^s, h, Q, q̈ and τ are compared coordinate by coordinate, by name.

40 random mechanisms, times FEMDYN_RELATION_SCALE (default 1; the nightly-size run of
docs/robustness.md sets it higher)."""
import json
import os

import numpy as np
import pytest

import femdyn

MODELS = 40 * max(1, int(os.environ.get("FEMDYN_RELATION_SCALE", "1")))


def rpy_matrix(r, p, y):
    """R = Rz(y) Ry(p) Rx(r), URDF's convention."""
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def rpy_quaternion(r, p, y):
    """The unit quaternion (w, x, y, z) of rpy_matrix(r, p, y), by half angles (no matrix)."""
    def axis(k, a):
        q = np.zeros(4)
        q[0], q[k] = np.cos(a / 2), np.sin(a / 2)
        return q

    def mul(a, b):
        w1, v1, w2, v2 = a[0], a[1:], b[0], b[1:]
        return np.r_[w1 * w2 - v1 @ v2, w1 * v2 + w2 * v1 + np.cross(v1, v2)]

    return mul(axis(3, y), mul(axis(2, p), axis(1, r)))


def num(x):
    return repr(float(x))


def nums(v):
    return " ".join(num(x) for x in v)


def random_mechanism(rng, ball):
    """Bodies in a random tree: (name, parent index or -1, joint kind, xyz, rpy, axis, mass, com,
    inertia about the com in body axes). The root is free on half of them; with `ball`, some joints
    are spherical (JSON and MJCF only: URDF has no ball joint)."""
    n = int(rng.integers(2, 7))
    kinds = ["revolute", "prismatic", "fixed"] + (["spherical"] if ball else [])
    bodies = []
    for i in range(n):
        parent = -1 if i == 0 else int(rng.integers(0, i))
        kind = ("free" if rng.random() < 0.5 else "revolute") if i == 0 else \
            str(rng.choice(kinds, p=[0.45, 0.25, 0.15, 0.15] if ball else [0.5, 0.3, 0.2]))
        xyz = np.zeros(3) if kind == "free" else rng.uniform(-0.6, 0.6, 3)
        rpy = np.zeros(3) if kind == "free" else rng.uniform(-np.pi, np.pi, 3)
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        # a physical inertia: positive principal moments obeying the triangle inequality, turned
        a, b = rng.uniform(0.01, 0.1, 2)
        c = rng.uniform(abs(a - b) + 0.005, a + b - 0.001)
        turn = rpy_matrix(*rng.uniform(-np.pi, np.pi, 3))
        inertia = turn @ np.diag([a, b, c]) @ turn.T
        bodies.append(dict(name=f"b{i}", parent=parent, kind=kind, xyz=xyz, rpy=rpy, axis=axis,
                           mass=float(rng.uniform(0.3, 3)), com=rng.uniform(-0.3, 0.3, 3),
                           inertia=inertia, inertial_rpy=rng.uniform(-np.pi, np.pi, 3)))
    return bodies


def json_text(bodies):
    out = []
    for b in bodies:
        joint = {"name": f"j_{b['name']}", "type": b["kind"]}
        if b["kind"] != "free":
            joint["origin"] = {"xyz": list(b["xyz"]), "rpy": list(b["rpy"])}
        if b["kind"] in ("revolute", "prismatic"):
            joint["axis"] = list(b["axis"])
        out.append({"name": b["name"],
                    "parent": "world" if b["parent"] < 0 else bodies[b["parent"]]["name"],
                    "joint": joint,
                    "elements": [{"type": "rigid_body", "mass": b["mass"], "com": list(b["com"]),
                                  "inertia": b["inertia"].tolist()}]})
    return json.dumps({"name": "relation", "gravity": [0, 0, -9.81], "bodies": out})


def urdf_text(bodies):
    """URDF: the inertia written in a frame of its own (inertial rpy), I' = Rᵀ I R."""
    lines = ['<robot name="relation">', '<link name="world"/>']
    for b in bodies:
        turn = rpy_matrix(*b["inertial_rpy"])
        i = turn.T @ b["inertia"] @ turn
        lines += [f'<link name="{b["name"]}"><inertial>',
                  f'<origin xyz="{nums(b["com"])}" rpy="{nums(b["inertial_rpy"])}"/>',
                  f'<mass value="{num(b["mass"])}"/>',
                  f'<inertia ixx="{num(i[0, 0])}" iyy="{num(i[1, 1])}" izz="{num(i[2, 2])}" '
                  f'ixy="{num(i[0, 1])}" ixz="{num(i[0, 2])}" iyz="{num(i[1, 2])}"/>',
                  '</inertial></link>']
        kind = {"free": "floating", "revolute": "continuous"}.get(b["kind"], b["kind"])
        parent = "world" if b["parent"] < 0 else bodies[b["parent"]]["name"]
        lines += [f'<joint name="j_{b["name"]}" type="{kind}">',
                  f'<parent link="{parent}"/><child link="{b["name"]}"/>',
                  f'<origin xyz="{nums(b["xyz"])}" rpy="{nums(b["rpy"])}"/>']
        if b["kind"] in ("revolute", "prismatic"):
            lines.append(f'<axis xyz="{nums(b["axis"])}"/>')
        if b["kind"] == "prismatic":
            lines.append('<limit lower="-1" upper="1" effort="100" velocity="10"/>')
        lines.append("</joint>")
    lines.append("</robot>")
    return "\n".join(lines)


def mjcf_text(bodies):
    """MJCF: each body's pos and quat (from rpy by half angles), the joint at its origin, the
    inertia in body axes (fullinertia)."""
    children = {i: [k for k, b in enumerate(bodies) if b["parent"] == i]
                for i in range(-1, len(bodies))}

    def body(k, depth):
        b, pad = bodies[k], "  " * depth
        i = b["inertia"]
        lines = [f'{pad}<body name="{b["name"]}" pos="{nums(b["xyz"])}" '
                 f'quat="{nums(rpy_quaternion(*b["rpy"]))}">',
                 f'{pad}  <inertial pos="{nums(b["com"])}" mass="{num(b["mass"])}" '
                 f'fullinertia="{nums([i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]])}"/>']
        joint = {"revolute": "hinge", "prismatic": "slide", "spherical": "ball", "free": "free"}
        if b["kind"] in joint:
            axis = f' axis="{nums(b["axis"])}"' if b["kind"] in ("revolute", "prismatic") else ""
            lines.append(f'{pad}  <joint name="j_{b["name"]}" type="{joint[b["kind"]]}"{axis}/>')
        for c in children[k]:
            lines += body(c, depth + 1)
        return lines + [f"{pad}</body>"]

    lines = ['<mujoco model="relation">', '<compiler angle="radian"/>', "<worldbody>"]
    for k in children[-1]:
        lines += body(k, 1)
    return "\n".join(lines + ["</worldbody>", "</mujoco>"])


def random_state(m, rng):
    q = m.neutral_configuration()
    names = m.configuration
    k = 0
    while k < len(q):
        if names[k].endswith(".qw"):  # a unit quaternion
            w = rng.normal(size=4)
            q[k:k + 4] = w / np.linalg.norm(w)
            k += 4
        else:
            q[k] = rng.uniform(-1, 1)
            k += 1
    return q, rng.uniform(-1, 1, m.n), rng.uniform(-2, 2, m.n)


def in_order(values, names, order):
    """values indexed by `names`, put in the order of `order` (rows, and columns of a matrix)."""
    index = [names.index(o) for o in order]
    values = np.asarray(values)
    return values[np.ix_(index, index)] if values.ndim == 2 else values[index]


def rel(a, b, floor):
    """|a − b|∞ relative to |b|∞, or to `floor` where b is smaller (h of a mechanism at rest is
    round-off about zero: its scale is then that of M q̇², not its own)."""
    return float(np.max(np.abs(a - b)) / max(floor, np.max(np.abs(b))))


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize("seed", range(MODELS))
def test_the_same_mechanism_in_json_urdf_and_mjcf_has_the_same_equations(seed, tmp_path):
    rng = np.random.default_rng(4300 + seed)
    ball = seed % 3 == 2
    bodies = random_mechanism(rng, ball)
    files = {"json": write(tmp_path, "m.json", json_text(bodies)),
             "mjcf": write(tmp_path, "m.xml", mjcf_text(bodies))}
    if not ball:
        files["urdf"] = write(tmp_path, "m.urdf", urdf_text(bodies))
    models = {k: femdyn.load(p) for k, p in files.items()}
    ref = models["json"]
    for _ in range(3):
        q, qd, tau = random_state(ref, rng)
        eq = ref.equations(q, qd, tau)
        tau_id = ref.inverse_dynamics(q, qd, eq.qdd)
        for fmt, m in models.items():
            assert sorted(m.coordinates) == sorted(ref.coordinates), fmt
            assert sorted(m.configuration) == sorted(ref.configuration), fmt
            qf = in_order(q, ref.configuration, m.configuration)
            qdf = in_order(qd, ref.coordinates, m.coordinates)
            tauf = in_order(tau, ref.coordinates, m.coordinates)
            other = m.equations(qf, qdf, tauf)
            names, order = m.coordinates, ref.coordinates
            force = np.max(np.abs(eq.M)) * max(1, np.max(qd) ** 2) + np.max(np.abs(eq.Q))
            for what, mine, theirs, tol, floor in (
                    ("M", other.M, eq.M, 1e-13, 0),
                    ("h", other.h, eq.h, 1e-13, force),
                    ("Q", other.Q, eq.Q, 1e-13, force),
                    ("qdd", other.qdd, eq.qdd, 1e-11, 1)):
                assert rel(in_order(mine, names, order), theirs, floor) < tol, (fmt, what)
            tau_back = m.inverse_dynamics(qf, qdf, in_order(eq.qdd, order, names))
            assert rel(in_order(tau_back, names, order), tau_id, force) < 1e-11, (fmt, "tau")
