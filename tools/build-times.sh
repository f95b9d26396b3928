#!/usr/bin/env bash
# The slowest compile units of a Ninja build (docs/building.md): each unit's wall time from the
# build directory's .ninja_log (its last build of every output), and, for a unity batch, the
# source files it compiles together. Also the total compile time of each target.
#   tools/build-times.sh [N] [BUILD_DIR]      default: 10 units, ./build
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-10}
dir=${2:-build}
log=$dir/.ninja_log
if ! [[ $n =~ ^[0-9]+$ ]]; then
  echo "usage: tools/build-times.sh [N] [BUILD_DIR]" >&2
  exit 2
fi
[ -f "$log" ] || { echo "build-times: $log not found (a Ninja build: tools/setup.sh)" >&2; exit 1; }

# .ninja_log v5: start end mtime output hash; a rebuilt output appears again, later lines win.
src_dir=$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' "$dir/CMakeCache.txt" 2>/dev/null || true)
units=$(awk 'NR > 1 && $4 ~ /\.o$/ { t[$4] = ($2 - $1) / 1000 }
             END { for (o in t) printf "%.1f\t%s\n", t[o], o }' "$log" | sort -g -r)

echo "slowest $n compile units (s):"
echo "$units" | head -n "$n" | while IFS=$'\t' read -r secs obj; do
  src=${obj#*.dir/}
  src=${src%.o}
  case $src in
    Unity/*)  # a unity batch: the sources it includes
      batch=$dir/${obj%.o}
      batch=$(dirname "$batch")/$(basename "$batch")
      files=$(grep -o '"[^"]*"' "$batch" 2>/dev/null | tr -d '"' | sed "s|^${src_dir:-$PWD}/||" | tr '\n' ' ')
      printf '  %6.1f  %s: %s\n' "$secs" "${obj%%.dir/*}" "$files" ;;
    *) printf '  %6.1f  %s\n' "$secs" "$src" ;;
  esac
done
echo "compile time by target (s):"
echo "$units" | awk -F'\t' '{ tgt = $2; sub(/\.dir\/.*/, "", tgt); sub(/.*CMakeFiles\//, "", tgt)
                              s[tgt] += $1; c[tgt]++; all += $1 }
                              END { for (t in s) printf "  %7.1f  %s (%d units)\n", s[t], t, c[t]
                                    printf "  %7.1f  all\n", all }' | sort -g -r
