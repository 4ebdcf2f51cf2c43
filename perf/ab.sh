#!/usr/bin/env bash
# In-process A/B of two versions of the engine on the peers' lattice scene: both are built as
# loadable modules and run in one process, alternated every few steps (perf/ab_lattice.cpp), so a
# machine whose speed drifts (other tenants, clock) slows both alike. Separate processes on a
# shared machine differ by up to 2x within minutes, which buries the 5-20 % a change is worth.
#
#   perf/ab.sh A B [n=40] [rounds=30] [steps=10] [warmup=200] [threads=1]
#   ASPERITY_AB_BONDED=1 perf/ab.sh A B ...     # the lattice bonded (the bond kernel's scene)
#   ASPERITY_AB_WORLD=FILE perf/ab.sh A B ...   # a saved world, e.g. the joint in mid-shear (perf/README.md)
#
# A, B: source trees (directories) or git revisions of this repository, checked out as detached
# worktrees under ${TMPDIR:-/tmp}/asperity-ab/. Each is built in <tree>/build-ab (Release,
# position-independent, no tests; JOBS=2 parallel jobs), which takes a few minutes the first time.
# Both trees need perf/ab_module.cpp (added 2026-11-25): cherry-pick it onto older revisions.
# Prints each build's best and median ns per particle-step, the median of the per-round time
# ratios B/A (the figure to quote), and whether the two trajectories are bitwise the same.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
if [ $# -lt 2 ]; then
  sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
fi

tree() {
  if [ -d "$1" ]; then
    (cd "$1" && pwd)
    return
  fi
  local rev dir
  rev=$(git -C "$here" rev-parse --verify --short "$1^{commit}" 2>/dev/null) || {
    echo "perf/ab.sh: '$1' is neither a directory nor a git revision of $here" >&2
    exit 2
  }
  dir=${TMPDIR:-/tmp}/asperity-ab/$rev
  [ -d "$dir" ] || git -C "$here" worktree add --detach -f "$dir" "$rev" >/dev/null
  echo "$dir"
}

build() {  # build <tree> <targets...>: the A/B build of a tree
  local src=$1
  shift
  if [ ! -f "$src/perf/ab_module.cpp" ]; then
    echo "perf/ab.sh: $src has no perf/ab_module.cpp (older than the A/B tool): cherry-pick it there" >&2
    exit 2
  fi
  cmake -S "$src" -B "$src/build-ab" -DCMAKE_BUILD_TYPE=Release -DASPERITY_AB_MODULE=ON \
    -DASPERITY_TESTS=OFF >/dev/null
  echo "perf/ab.sh: building $src" >&2
  cmake --build "$src/build-ab" -j"${JOBS:-2}" --target "$@" >/dev/null
}

a=$(tree "$1")
b=$(tree "$2")
shift 2
build "$a" asperity_ab ab_lattice
build "$b" asperity_ab
exec "$a/build-ab/perf/ab_lattice" "$a/build-ab/perf/libasperity_ab.so" \
  "$b/build-ab/perf/libasperity_ab.so" "$@"
