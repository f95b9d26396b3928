#!/usr/bin/env python3
"""Functions over 80 lines and files over 600 lines outside tests, measured with Universal Ctags.

  tools/long_functions.py          list them, longest first
  tools/long_functions.py --check  exit 1 if a function over 80 lines is neither in ALLOWED (an
                                   argument table, with its reason) nor in PENDING (not yet split),
                                   or a file is over 600, or a compile pass (a function in
                                   compile/) is over 40

The standard (docs/design.md, "Sizes"): a function over 80 lines or a file over 600 needs a reason.
"""
import argparse
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
FUNCTION_LINES, FILE_LINES = 80, 600
COMPILE_PASS_LINES = 40  # compile/ runs once per model: its passes stay small (issue 47)
# function -> why it may be long (docs/design.md, "Sizes").
ALLOWED = {
    "bind_builder": "the Python Builder's argument table: one .def per method, each a few lines",
    "bind_model": "the Python Model's argument table: one .def per method",
    "stress_cases": "the table of the stress suite's cases, one entry each",
}
# Not yet split: listed so that the check stops any new one, and shrinking (empty since issue 47).
PENDING = set()


def sources():
    out = subprocess.run(["git", "ls-files", "*.cpp", "*.hpp"], cwd=ROOT, check=True,
                         capture_output=True, text=True).stdout.split()
    return [f for f in out if not f.startswith("tests/")]


def functions(files):
    try:
        out = subprocess.run(
            ["ctags", "-L", "-", "--languages=C++", "--kinds-C++=f", "--fields=+ne", "-x",
             "--_xformat=%{end} %{line} %{name} %{input}"],
            cwd=ROOT, input="\n".join(files), check=True, capture_output=True, text=True).stdout
    except FileNotFoundError:
        sys.exit("long_functions: Universal Ctags (ctags) is needed: tools/setup.sh --all")
    for line in out.splitlines():
        end, start, name, path = line.split(" ", 3)
        if end.isdigit():
            yield int(end) - int(start) + 1, name, f"{path}:{start}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    files = sources()
    found = list(functions(files))
    long = sorted((f for f in found if f[0] > FUNCTION_LINES), reverse=True)
    long_passes = sorted((f for f in found if f[0] > COMPILE_PASS_LINES and
                          f[2].startswith("compile/") and f[0] <= FUNCTION_LINES), reverse=True)
    big = sorted(((sum(1 for _ in open(ROOT / f, encoding="utf-8")), f) for f in files),
                 reverse=True)
    big = [(n, f) for n, f in big if n > FILE_LINES]
    failures = []
    for n, name, where in long:
        why = ALLOWED.get(name) or ("not yet split" if name in PENDING else None)
        print(f"{n:4d}  {name}  {where}" + (f"  ({why})" if why else ""))
        if not why:
            failures.append(f"{name} ({where}) has {n} lines")
    for n, name, where in long_passes:
        print(f"{n:4d}  {name}  {where}  (a compile pass over {COMPILE_PASS_LINES})")
        failures.append(f"compile pass {name} ({where}) has {n} lines")
    for name in sorted(PENDING - {name for _, name, _ in long}):
        failures.append(f"{name} is no longer over {FUNCTION_LINES} lines: take it off PENDING")
    for n, f in big:
        print(f"{n:4d}  file {f}")
        failures.append(f"{f} has {n} lines")
    print(f"functions over {FUNCTION_LINES} lines: {len(long)}, files over {FILE_LINES}: "
          f"{len(big)}, compile passes over {COMPILE_PASS_LINES}: {len(long_passes)}")
    if args.check and failures:
        for f in failures:
            print("long_functions:", f, file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
