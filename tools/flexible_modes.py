#!/usr/bin/env python3
"""The cantilever's natural frequencies (at rest and spinning) from femdyn's linearisation against beam theory, as the
number of segments of a flexible bar grows: the table of docs/flexible.md.

Usage: PYTHONPATH=build/python tools/flexible_modes.py            prints the table
       PYTHONPATH=build/python tools/flexible_modes.py --update   rewrites it in docs/flexible.md
       PYTHONPATH=build/python tools/flexible_modes.py --check    fails if the docs' table differs

The bar: steel (E = 210 GPa, G = 81 GPa, ρ = 7850 kg/m³), L = 1 m, a 1 mm square section with
I_z = 2 I_y (so that the two bending planes differ) and J = 2 I_y, clamped, no gravity. Closed
forms: bending ω_k = (β_k L)² √(EI/(ρA L⁴)), β_k L = 1.8751, 4.6941, 7.8548; the first torsion
and stretch modes (π/2L) √(GJ/(ρ I_p)) and (π/2L) √(E/ρ). Each mode's error is that of the
nearest frequency femdyn finds; its order is log2 of the ratio of the errors at n and 2n.
"""
import math
import os
import sys

import numpy as np

import femdyn

E, G, RHO, B, L = 2.1e11, 8.1e10, 7850.0, 1e-3, 1.0
A, IY = B * B, B ** 4 / 12
IZ, J = 2 * IY, 2 * IY
SEGMENTS = (4, 8, 16, 32, 64, 128)
DOC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "docs", "flexible.md")
TABLES = {  # marker in docs/flexible.md: the function that makes its table
    "modes": "modes_table",
    "spinning": "spinning_table",
}
# Hodges & Rutkowski (AIAA J. 19(11), 1981), table 1: a uniform cantilever's first flapwise
# frequency on a hub of radius 0 turning at λ, both in units of √(EI/(ρA L⁴)).
ROTATING = (3.5160, 3.6817, 4.1373, 4.7973, 5.5850, 6.4495, 7.3604, 8.2996, 9.2568, 10.2257,
            11.2023)


def exact_modes():
    bl = (1.8751040687119611, 4.6940911329741745, 7.8547574382376126)
    modes = [(f"bending y {k + 1}", b * b * math.sqrt(E * IY / (RHO * A * L ** 4)))
             for k, b in enumerate(bl)]
    modes += [(f"bending z {k + 1}", b * b * math.sqrt(E * IZ / (RHO * A * L ** 4)))
              for k, b in enumerate(bl)]
    modes.append(("torsion 1", math.pi / (2 * L) * math.sqrt(G * J / (RHO * (IY + IZ)))))
    modes.append(("stretch 1", math.pi / (2 * L) * math.sqrt(E / RHO)))
    return modes


def frequencies(m, qd=None):
    z = np.zeros(m.n)
    ev = np.linalg.eigvals(m.linearize(np.zeros(m.n_q), z if qd is None else qd, z)[0])
    return np.sort(ev.imag[ev.imag > 0])


def cantilever(n):
    b = femdyn.Builder("cantilever")
    b.flexible_bar("bar", "world", length=L, segments=n,
                   section={"E": E, "G": G, "density": RHO, "area": A, "Iy": IY, "Iz": IZ, "J": J})
    return b.build()


def spinning(n):
    """The bar on a hub turning about z, inextensible and without torsion (as the reference)."""
    b = femdyn.Builder("spinning")
    b.body("hub", "world", type="revolute", joint="hub", axis=[0, 0, 1])
    b.rigid_body("hub", 1.0, [0, 0, 0], np.eye(3))
    b.flexible_bar("bar", "hub", length=L, segments=n, axial=False, torsion=False,
                   section={"E": E, "density": RHO, "area": A, "Iy": IY, "Iz": 4 * IY})
    return b.build()


def spinning_table():
    unit = math.sqrt(E * IY / (RHO * A * L ** 4))
    sizes = (8, 16, 32, 64)
    rows = ["| λ = Ω/√(EI/ρAL⁴) | reference ω | " + " | ".join(f"n = {n}" for n in sizes) +
            " | order |", "|---|---|" + "---|" * (len(sizes) + 1)]
    errors = {}
    for n in sizes:
        m = spinning(n)
        errors[n] = []
        for lam, ref in enumerate(ROTATING):
            qd = np.zeros(m.n)
            qd[0] = lam * unit
            w = frequencies(m, qd) / unit
            errors[n].append(float(np.min(np.abs(w - ref)) / ref))
    for lam, ref in enumerate(ROTATING):
        order = math.log2(errors[16][lam] / errors[32][lam])
        rows.append(f"| {lam} | {ref:.4f} | " +
                    " | ".join(f"{errors[n][lam]:.1e}" for n in sizes) + f" | {order:.2f} |")
    return "\n".join(rows) + "\n"


def modes_table():
    modes = exact_modes()
    errors = {}
    for n in SEGMENTS:
        w = frequencies(cantilever(n))
        errors[n] = [float(np.min(np.abs(w - x)) / x) for _, x in modes]
    head = "| mode | exact ω (rad/s) | " + " | ".join(f"n = {n}" for n in SEGMENTS) + " | order |"
    rows = [head, "|---|---|" + "---|" * (len(SEGMENTS) + 1)]
    for k, (name, x) in enumerate(modes):
        # the order between the two finest pairs before rotary inertia shows (n = 32 → 64)
        order = math.log2(errors[32][k] / errors[64][k])
        rows.append(f"| {name} | {x:.6g} | " +
                    " | ".join(f"{errors[n][k]:.1e}" for n in SEGMENTS) + f" | {order:.2f} |")
    return "\n".join(rows) + "\n"


def main():
    tables = {key: globals()[make]() for key, make in TABLES.items()}
    if len(sys.argv) < 2:
        for text in tables.values():
            sys.stdout.write(text + "\n")
        return 0
    doc = original = open(DOC).read()
    for key, text in tables.items():
        begin = f"<!-- {key} table: tools/flexible_modes.py --update -->\n"
        end = f"<!-- end of {key} table -->"
        start, stop = doc.index(begin) + len(begin), doc.index(end)
        doc = doc[:start] + text + doc[stop:]
    if sys.argv[1] == "--check":
        if doc != original:
            sys.stderr.write("docs/flexible.md: a table is stale; run tools/flexible_modes.py "
                             "--update\n")
            return 1
        return 0
    with open(DOC, "w") as f:
        f.write(doc)
    return 0


if __name__ == "__main__":
    sys.exit(main())
