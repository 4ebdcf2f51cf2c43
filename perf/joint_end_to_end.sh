#!/usr/bin/env bash
# The joint end to end, as a user runs it: the genesis, then the rigid, elastic and fracture
# shears of one surface at one size, one after the other on the same cores, each a plain
# `asperity run scripts/joint.lua` command. Prints the wall time of each phase (genesis, closure
# and set-up, shear), the cost per particle-step of each shear and the run's peak memory, and
# appends one row per model to perf/results/<cpu-model>-joint.csv.
#
#   perf/joint_end_to_end.sh                                  # 2 cm S1, 14 MPa, 2 threads
#   SIZE=0.1 perf/joint_end_to_end.sh                         # the thesis's 10 cm
#   SIZE=0.05 SURFACE=S5 STRESS=21 THREADS=1 OUT=out/e2e perf/joint_end_to_end.sh
#
# SPEEDUP (default 4) is passed to the elastic run (joint.lua refuses it for the rigid and
# fracture models); EXTRA adds key=value parameters to every run. The specimen is packed by the
# first run into a cache of its own under OUT (a fresh genesis each time, so it is measured);
# CACHE=DIR reuses a folder instead.
set -euo pipefail
cd "$(dirname "$0")/.."
SIZE=${SIZE:-0.02}
SURFACE=${SURFACE:-S1}
STRESS=${STRESS:-14}
THREADS=${THREADS:-2}
SPEEDUP=${SPEEDUP:-4}
MODELS=${MODELS:-"rigid elastic fracture"}
EXTRA=${EXTRA:-}
OUT=${OUT:-out/end_to_end}
BIN=${BIN:-build/asperity}
[ -x "$BIN" ] || { echo "$0: $BIN not found: build first (cmake --build build)" >&2; exit 2; }
mkdir -p "$OUT"
CACHE=${CACHE:-"$OUT/cache.$$"}
commit=$(git describe --always --dirty 2>/dev/null || echo unknown)
source perf/results_file.sh
cpu=$(cpu_model)
csv=$(results_file . -joint)
[ -f "$csv" ] || echo "date,cpu_model,commit,size_m,surface,stress_mpa,model,threads,speedup,particles,genesis_s,setup_s,shear_s,shear_steps,ns_per_particle_step,wall_s,load_avg,peak_memory_mb" > "$csv"

start=$(date +%s)
for model in $MODELS; do
  speed=1
  [ "$model" = elastic ] && speed=$SPEEDUP
  dir="$OUT/${SURFACE}_${model}"
  echo "== $model (size $SIZE m, $SURFACE, $STRESS MPa, threads $THREADS, speedup $speed)"
  "$BIN" run scripts/joint.lua surface="$SURFACE" size="$SIZE" stress="$STRESS" model="$model" \
    speedup="$speed" threads="$THREADS" cache="$CACHE" out="$dir" $EXTRA > "$dir.log" 2>&1 \
    || { echo "$model failed: see $dir.log" >&2; tail -3 "$dir.log" >&2; exit 1; }
  tail -1 "$dir.log"
  # The phases from summary.json: the genesis counts only in the run that packed the specimen.
  python3 - "$dir/summary.json" "$csv" "$cpu" "$commit" "$SIZE" "$SURFACE" "$STRESS" "$model" "$THREADS" "$speed" <<'EOF'
import json, sys, time, os
path, csv, cpu, commit, size, surface, stress, model, threads, speed = sys.argv[1:]
s = json.load(open(path))
genesis = s["specimen_seconds"] if s["specimen_packed"] else 0.0
wall, shear = s["wall_seconds"], s["shear_seconds"]
setup = wall - shear - genesis
n, steps = s["n_particles"], s["shear_steps"]
ns = 1e9 * shear / max(1, n * steps)
load = os.getloadavg()[0]
memory = s.get("peak_memory_bytes", 0) / 2**20  # of the whole run (the genesis too, where it packed)
print(f"   genesis {genesis:8.0f} s   closure + set-up {setup:7.0f} s   shear {shear:7.0f} s "
      f"({steps} steps, {ns:.1f} ns per particle-step, {n} particles)   total {wall:7.0f} s   "
      f"peak memory {memory:.0f} MB")
with open(csv, "a") as f:
    f.write(f'{time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())},"{cpu}",{commit},{size},{surface},{stress},'
            f'{model},{threads},{speed},{n},{genesis:.1f},{setup:.1f},{shear:.1f},{steps},{ns:.2f},{wall:.1f},{load:.2f},'
            f'{memory:.0f}\n')
EOF
done
echo "== end to end: $(( $(date +%s) - start )) s (rows in $csv)"
