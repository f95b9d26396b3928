#!/usr/bin/env python3
"""Which test checks each core header.

  tools/test_map.py          list each core header and its test
  tools/test_map.py --check  exit 1 if a core header is neither included by a test nor listed
                             in COVERED with the test that checks it, if a listed test no longer
                             holds the words it is listed for, or if a listed header is now
                             included by a test (take it off the list)

A header that a test includes is tested directly. The others are building blocks of a public
function whose test checks them against an independent number; COVERED names that test and the
words in it (a test case's name or a call) that show it does, so that deleting the test fails
the check.
"""
import argparse
import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
TEST_DIRS = ("tests",)

# header -> (test file, words the test holds, what checks the header there)
COVERED = {
    "core/derivatives/constraint_derivatives.hpp": (
        "tests/test_loop_derivatives.cpp", "every constraint form",
        "the constrained derivatives against differences, every constraint form"),
    "core/derivatives/loops.hpp": (
        "tests/test_loop_derivatives.cpp", "Bricard's mechanism along v and tau",
        "the constrained forward-dynamics derivatives against differences"),
    "core/derivatives/coupling.hpp": (
        "tests/test_derivatives.cpp", "nonlinear_coupled_tree_json",
        "a coupling law's derivatives against differences"),
    "core/derivatives/points.hpp": (
        "tests/test_derivatives.cpp", "with_springs",
        "the springs' and rods' derivatives (their points' motion) against differences"),
    "core/derivatives/springs.hpp": (
        "tests/test_derivatives.cpp", "with_springs",
        "the two-point springs' derivatives against differences"),
    "core/derivatives/spans.hpp": (
        "tests/test_derivatives.cpp", "with_rods",
        "the spanning elements' derivatives against differences"),
    "core/dynamics/body_loads.hpp": (
        "tests/test_routes.cpp", "on mixed random trees",
        "point loads and body torques (mixed trees) equal on every route"),
    "core/dynamics/coupled_dynamics.hpp": (
        "tests/test_couplings.cpp", "a nonlinear law equal to a linear coupling",
        "the law chain's q̈ against the linear coupling's"),
    "core/dynamics/coupling_chain.hpp": (
        "tests/test_couplings.cpp", "a nonlinear law equal to a linear coupling",
        "the law chain's equations against the linear coupling's"),
    "core/dynamics/span_inertia.hpp": (
        "tests/test_routes.cpp", "with_rods",
        "rods spanning bodies equal on the body and node routes"),
    "core/joints/parameters.hpp": (
        "tests/test_joint_parameters.cpp", "every joint type from its declaration",
        "each type's declared keys through JSON and the builder"),
    "core/model/element.hpp": (
        "tests/test_elements.cpp", "TEST_CASE", "each element type's mass and forces"),
    "core/model/coupling_level.hpp": (
        "tests/test_couplings.cpp", "four-bar", "the coupling level's laws"),
    "core/model/routes.hpp": (
        "tests/test_routes.cpp", "the chosen routes equal the reference routes",
        "the route table's choice against the reference routes"),
    "core/model/attachment.hpp": (
        "tests/test_loops.cpp", "TEST_CASE", "data only: the places loops and springs hold"),
    "core/model/two_point_spring.hpp": (
        "tests/test_derivatives.cpp", "with_springs", "data only: a spring of the model"),
    "core/model/spanning_mass.hpp": (
        "tests/test_routes.cpp", "with_rods", "data only: a rod carried by the body routes"),
    "core/workspace/status.hpp": (
        "tests/test_divergence.cpp", "TEST_CASE", "data only: the failures each door reports"),
}
# The joint types: each is one file pair, tested through the kernel by the tests over every
# type name (a new type is tested by them without a new test).
for joint in ("fixed", "flat", "free", "helical", "planar", "prismatic", "revolute", "spherical",
              "universal"):
    COVERED[f"core/joints/{joint}.hpp"] = (
        "tests/test_joints.cpp", "every joint type",
        "each type's pose, motion subspace and bias against differences, over the type names")


def tracked(pattern):
    return subprocess.run(["git", "ls-files", pattern], cwd=ROOT, check=True,
                          capture_output=True, text=True).stdout.split()


def included_by_tests():
    found = set()
    for f in tracked("tests/*"):
        if f.endswith((".cpp", ".hpp")):
            found |= set(re.findall(r'#include "([^"]+)"', (ROOT / f).read_text(encoding="utf-8")))
    return found


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    direct = included_by_tests()
    failures = []
    headers = tracked("core/*.hpp")
    for h in headers:
        if h in direct:
            if h in COVERED:
                failures.append(f"{h} is included by a test now: take it off COVERED")
            print(f"{h}: included by a test")
            continue
        if h not in COVERED:
            failures.append(f"{h} is included by no test and not in COVERED")
            continue
        test, words, why = COVERED[h]
        path = ROOT / test
        if not path.exists() or words not in path.read_text(encoding="utf-8"):
            failures.append(f"{h}: {test} does not hold {words!r}")
        print(f"{h}: {test} ({why})")
    for h in sorted(set(COVERED) - set(headers)):
        failures.append(f"{h} is listed in COVERED but is not a core header")
    print(f"core headers: {len(headers)}, included by a test: "
          f"{sum(h in direct for h in headers)}, covered through a public function: "
          f"{sum(h not in direct and h in COVERED for h in headers)}")
    if args.check and failures:
        for f in failures:
            print("test_map:", f, file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
