#!/usr/bin/env bash
# Every C++ file git tracks is formatted by .clang-format (Google style, 100 columns).
# Exits non-zero and lists the first differences otherwise. Fix with:
#   git ls-files '*.cpp' '*.hpp' | xargs clang-format -i
# Run by ctest ("format: …") and so by the README's test command and CI.
set -euo pipefail
cd "$(dirname "$0")/.."
format=${CLANG_FORMAT:-clang-format}
if ! command -v "$format" >/dev/null; then
  echo "check-format: $format not found (tools/setup.sh --all installs it)" >&2
  exit 1
fi
if ! git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  echo "check-format: not a git checkout; nothing to check" >&2
  exit 0
fi
files=$(git ls-files '*.cpp' '*.hpp')
if ! out=$(echo "$files" | xargs "$format" --dry-run --Werror 2>&1); then
  echo "$out" | grep -E 'error:' | head -20 >&2
  echo "check-format: $(echo "$out" | grep -c 'error:') places differ from .clang-format;" \
       "fix with: git ls-files '*.cpp' '*.hpp' | xargs $format -i" >&2
  exit 1
fi
echo "check-format: $(echo "$files" | wc -l) files follow .clang-format"
