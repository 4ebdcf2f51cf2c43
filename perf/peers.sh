#!/usr/bin/env bash
# Lattice scene on asperity and its peers (LAMMPS, LIGGGHTS, YADE), 1 and 2 cores, in one go:
# prints particle-steps/s and the ratios, appends to perf/results/<cpu-model>.csv (one row per
# engine and core count; load_avg is the 1-minute load when the runs ended: above ~0.5 others were
# using the machine, and wall-clock figures of that run are suspect).
#
#   perf/peers.sh [SCENE=lattice|bonded] [N=40] [STEPS=1000] [ROUNDS=1] [CORES="1 2"]
#                 [ENGINES="asperity lammps liggghts yade"] [FRONT=cpp|lua] [QUIET=0] [GUARD=2]
#
# SCENE=bonded: the bonded block instead (perf/bonded.lua and its YADE twin perf/bonded_yade.py:
# n^3 touching spheres of the REV material, every touching pair bonded, no rotation, the top layer
# pressed down); rows go to perf/results/<cpu-model>-bonded.csv. Only asperity and YADE run it:
# LAMMPS and LIGGGHTS are skipped with the reason (Debian's builds have no bonded granular model),
# FRONT and GUARD do not apply. Each run prints the bonds in the step at its start and end.
#
# The lattice's peer inputs are read where they live (../shared/peers/ beside the repository, or
# PEERS=<dir>); nothing of theirs is copied here. The bonded scene's inputs are the project's own
# (perf/). Missing engines are installed with apt-get (Debian packages lammps, liggghts, yade,
# openmpi-bin) when running as root; an engine that cannot be had is skipped. asperity is
# perf/lattice_bench from BUILD (default build/; BUILD/asperity for FRONT=lua and the bonded
# scene), built if missing. Runs alternate between engines (asperity, lammps, liggghts, yade, then
# the next core count, then the next round) so that a busy machine slows them alike; with
# ROUNDS > 1 the best of the rounds is kept per engine and core count. FRONT=lua times asperity
# through `BUILD/asperity run perf/lattice.lua` instead of perf/lattice_bench (same scene, same
# numbers).
# QUIET=s: on a shared machine, before each run wait up to s seconds for the other processes to
# use less than a quarter of a core (measured over 2 s), so runs are not timed against a build.
# GUARD=x: exit 1 when asperity is below x times LAMMPS at some core count (0: no check).
set -euo pipefail

for kv in "$@"; do
  case "$kv" in
    SCENE=*|N=*|STEPS=*|ROUNDS=*|CORES=*|ENGINES=*|BUILD=*|PEERS=*|FRONT=*|QUIET=*|GUARD=*) export "${kv?}" ;;
    -h|--help) sed -n '2,/^set -e/{/^set -e/!p}' "$0"; exit 0 ;;
    *) echo "peers.sh: unknown argument '$kv' (see --help)" >&2; exit 2 ;;
  esac
done

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/.." && pwd)
source "$here/results_file.sh"
SCENE=${SCENE:-lattice}
case $SCENE in lattice|bonded) ;; *) echo "peers.sh: unknown SCENE '$SCENE' (lattice or bonded)" >&2; exit 2 ;; esac
N=${N:-40}
STEPS=${STEPS:-1000}
ROUNDS=${ROUNDS:-1}
CORES=${CORES:-"1 2"}
ENGINES=${ENGINES:-"asperity lammps liggghts yade"}
BUILD=${BUILD:-$repo/build}
FRONT=${FRONT:-cpp}
QUIET=${QUIET:-0}
GUARD=${GUARD:-2}
PEERS=${PEERS:-$repo/../shared/peers}
if [[ $SCENE == lattice ]]; then
  [[ -f $PEERS/in.lattice.lmp ]] || { echo "peers.sh: no peer inputs in $PEERS (set PEERS=)" >&2; exit 1; }
  PEERS=$(cd "$PEERS" && pwd)
else
  FRONT=lua   # the bonded scene has only the Lua front
fi
work=$(mktemp -d /tmp/asperity-peers.XXXXXX)
trap 'rm -rf "$work"' EXIT
export OMP_NUM_THREADS=1   # the peers: MPI ranks only (Debian's LAMMPS also reads it)
mpirun=(mpirun --allow-run-as-root --bind-to none)

# --- engines ---------------------------------------------------------------------------------
apt_install() {  # package...
  [[ $(id -u) -eq 0 ]] && command -v apt-get >/dev/null || return 1
  echo "peers.sh: installing $* (apt-get)" >&2
  DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "$@" >"$work/apt.log" 2>&1 ||
    { apt-get update >/dev/null 2>&1 && DEBIAN_FRONTEND=noninteractive apt-get install -y \
        --no-install-recommends "$@" >"$work/apt.log" 2>&1; }
}
have() { command -v "$1" >/dev/null 2>&1; }
# Why a peer does not run the bonded scene (empty: it does). The bonded block needs breakable bonds
# between granular spheres (normal, shear and bending stiffness, a strength); a bond style of point
# masses (harmonic, fene, ...) is not that model, and none is put under a peer's name instead.
no_bonded_model() {  # engine
  case $1 in
    lammps)
      if have lmp && lmp -h 2>/dev/null | grep -q 'bpm/'; then
        echo "this LAMMPS has the BPM package, but perf/ has no bonded LAMMPS scene yet"
      else
        echo "no bonded granular model in this LAMMPS build (no BPM package: no bond_style" \
             "bpm/rotational, no pair_style bpm/spring; Debian's lammps 20220106 has none)"
      fi ;;
    liggghts) echo "LIGGGHTS-PUBLIC 3.8 has no bond styles (the cohesion models of its pair gran," \
                   "sjkr and easo, are adhesion, not bonds)" ;;
  esac
}
declare -A available
for e in $ENGINES; do
  if [[ $SCENE == bonded && $e != asperity && -n $(no_bonded_model "$e") ]]; then
    echo "peers.sh: $e skipped for SCENE=bonded: $(no_bonded_model "$e")" >&2
    continue
  fi
  case $e in
    asperity)
      target=lattice_bench bench=$BUILD/perf/lattice_bench
      [[ $FRONT == lua ]] && target=asperity bench=$BUILD/asperity
      if [[ ! -x $bench ]]; then
        echo "peers.sh: building $target in $BUILD" >&2
        cmake -S "$repo" -B "$BUILD" >/dev/null
        lock=(); have flock && lock=(flock /tmp/asperity-build.lock)
        "${lock[@]}" cmake --build "$BUILD" --target "$target" -j2 >/dev/null
      fi
      available[$e]=1 ;;
    lammps)   { have lmp || apt_install lammps; } && { have mpirun || apt_install openmpi-bin; } && available[$e]=1 ;;
    liggghts) { have liggghts || apt_install liggghts; } && { have mpirun || apt_install openmpi-bin; } && available[$e]=1 ;;
    yade)     { have yade || apt_install yade; } && available[$e]=1 ;;
    *) echo "peers.sh: unknown engine '$e'" >&2; exit 2 ;;
  esac
  [[ -n ${available[$e]:-} ]] || echo "peers.sh: $e not available, skipped" >&2
done

# --- one run: prints particle-steps/s on stdout; the engine's output goes to a log -------------
loop_rate() {  # LAMMPS / LIGGGHTS: the last "Loop time of T on P procs for S steps with A atoms"
  awk '/^Loop time of/ { t = $4; s = $9; a = $12 } END { if (t > 0) printf "%.6g\n", a * s / t }' "$1"
}
# Particle-steps per CPU-second of the timed loop, where the engine says how much CPU it had:
# asperity (process CPU time), LAMMPS ("P% CPU use" after the loop). On one core this hardly
# changes when other programs compete for the machine; empty for the others.
cpu_rate() {  # engine log
  case $1 in
    asperity) awk '/^cpu-particle-steps\/s:/ { r = $2 } END { if (r > 0) print r }' "$2" ;;
    lammps) awk '/^Loop time of/ { t = $4; s = $9; a = $12; c = 0 }
                 /% CPU use with/ { c = $1; sub("%", "", c) }
                 END { if (t > 0 && c > 0) printf "%.6g\n", a * s / (t * c / 100) }' "$2" ;;
  esac
}
run_engine() {  # engine cores log
  local e=$1 c=$2 log=$3
  local rank=(); [[ $c -gt 1 ]] && rank=("${mpirun[@]}" -np "$c")
  if [[ $SCENE == bonded ]]; then
    case $e in
      asperity) "$BUILD/asperity" run "$here/bonded.lua" n="$N" steps="$STEPS" threads="$c" warmup=200 >"$log" 2>&1 ;;
      yade) (cd "$work" && yade -n -x -j"$c" "$here/bonded_yade.py" "$N" "$STEPS" warmup=200) >"$log" 2>&1 ;;
    esac
    awk '/^particle-steps\/s:/ { r = $2 } END { if (r > 0) print r }' "$log"
    return
  fi
  case $e in
    asperity)
      if [[ $FRONT == lua ]]; then
        "$BUILD/asperity" run "$here/lattice.lua" n="$N" steps="$STEPS" threads="$c" warmup=200 >"$log" 2>&1
      else
        "$BUILD/perf/lattice_bench" n="$N" steps="$STEPS" threads="$c" warmup=200 >"$log" 2>&1
      fi
      tail -n 1 "$log" | awk '/^particle-steps\/s:/ { print $2 }' ;;
    lammps)
      (cd "$work" && "${rank[@]}" lmp -in "$PEERS/in.lattice.lmp" -var N "$N" -var S "$STEPS" -log none) >"$log" 2>&1
      loop_rate "$log" ;;
    liggghts)
      (cd "$work" && "${rank[@]}" liggghts -in "$PEERS/in.lattice.liggghts" -var N "$N" -var S "$STEPS" -log none) >"$log" 2>&1
      loop_rate "$log" ;;
    yade)
      (cd "$work" && yade -n -x -j"$c" "$PEERS/lattice_yade.py" "$N" "$STEPS") >"$log" 2>&1
      awk -v n="$N" -v s="$STEPS" '/^YADE n=/ { for (i = 1; i <= NF; ++i) if ($i ~ /^time=/) { sub("time=", "", $i); t = $i } }
        END { if (t > 0) printf "%.6g\n", n * n * n * s / t }' "$log" ;;
  esac
}

# The commit is read once, before the first row is appended: the appended CSV itself would mark the
# tree dirty for every later row.
commit=$(git -C "$repo" describe --always --dirty 2>/dev/null || echo unknown)
engine_version() {
  case $1 in
    asperity) echo "$commit" ;;
    lammps)   dpkg-query -W -f '${Version}' lammps 2>/dev/null || echo unknown ;;
    liggghts) dpkg-query -W -f '${Version}' liggghts 2>/dev/null || echo unknown ;;
    yade)     dpkg-query -W -f '${Version}' yade 2>/dev/null || echo unknown ;;
  esac
}

busy_cores() {  # CPU time used by everything over 2 s, in cores
  local a b
  read -r -a a < /proc/stat; sleep 2; read -r -a b < /proc/stat
  awk -v u="$(( (b[1]+b[2]+b[3]+b[6]+b[7]) - (a[1]+a[2]+a[3]+a[6]+a[7]) ))" \
      -v t="$(( (b[1]+b[2]+b[3]+b[4]+b[5]+b[6]+b[7]) - (a[1]+a[2]+a[3]+a[4]+a[5]+a[6]+a[7]) ))" \
      -v c="$(getconf _NPROCESSORS_ONLN)" 'BEGIN { printf "%.2f", (t > 0 ? c * u / t : 0) }'
}
wait_quiet() {
  [[ $QUIET -gt 0 ]] || return 0
  local waited=0 busy
  while busy=$(busy_cores); awk -v b="$busy" 'BEGIN { exit !(b > 0.25) }'; do
    ((waited += 2)) || true
    [[ $waited -ge $QUIET ]] && { echo "  (still busy: $busy cores; timing anyway)" >&2; return 0; }
  done
}

# --- the runs ----------------------------------------------------------------------------------
cpu=$(cpu_model)
declare -A best best_cpu rates median bonds
simd=unknown
if [[ $SCENE == bonded ]]; then
  echo "bonded n=$N ($((N * N * N)) particles, every touching pair bonded), $STEPS timed steps after 200 warm-up, cores: $CORES, rounds: $ROUNDS"
else
  echo "lattice n=$N ($((N * N * N)) particles), $STEPS timed steps after 200 warm-up, cores: $CORES, rounds: $ROUNDS"
fi
echo "cpu: $cpu ($(getconf _NPROCESSORS_ONLN) cores), load average: $(cut -d' ' -f1-3 /proc/loadavg)"
for r in $(seq 1 "$ROUNDS"); do
  for c in $CORES; do
    for e in $ENGINES; do
      [[ -n ${available[$e]:-} ]] || continue
      log=$work/$e.$c.$r.log
      wait_quiet
      rate=$(run_engine "$e" "$c" "$log" || true)
      if [[ -z $rate ]]; then
        echo "  $e, $c core(s): FAILED (last lines of its output:)" >&2
        tail -n 5 "$log" >&2
        continue
      fi
      [[ $e == asperity ]] && simd=$(awk '/^simd:/ { sub(",", "", $2); print $2; exit }' "$log")
      crate=$(cpu_rate "$e" "$log")
      rates[$e,$c,$r]=$rate
      printf '  round %d  %-9s %d core(s)  %12.4g particle-steps/s' "$r" "$e" "$c" "$rate"
      [[ -n $crate ]] && printf '  (%.4g per CPU-second)' "$crate"
      if [[ $SCENE == bonded ]]; then
        b=$(awk '/^bonds in the step:/ { print $5 " -> " $9 }' "$log")
        bonds[$e,$c,$r]=$b
        printf '  bonds %s' "${b:-?}"
      fi
      # asperity's rate over this engine's, same round and core count (asperity runs first)
      a=${rates[asperity,$c,$r]:-}
      [[ $e != asperity && -n $a ]] && awk -v a="$a" -v p="$rate" 'BEGIN { printf "  %.3gx", a / p }'
      printf '\n'
      prev=${best[$e,$c]:-0}
      best[$e,$c]=$(awk -v a="$rate" -v b="$prev" 'BEGIN { print (a > b ? a : b) }')
      if [[ -n $crate ]]; then
        prev=${best_cpu[$e,$c]:-0}
        best_cpu[$e,$c]=$(awk -v a="$crate" -v b="$prev" 'BEGIN { print (a > b ? a : b) }')
      fi
    done
  done
done

# --- table, ratios, log ------------------------------------------------------------------------
echo
printf '%-10s' engine; for c in $CORES; do printf '%16s' "$c core(s)"; done; printf '%16s\n' "asperity/engine"
for e in $ENGINES; do
  [[ -n ${available[$e]:-} ]] || continue
  printf '%-10s' "$e"
  for c in $CORES; do printf '%16.4g' "${best[$e,$c]:-0}"; done
  ratios=""
  for c in $CORES; do
    a=${best[asperity,$c]:-0} p=${best[$e,$c]:-0}
    ratios+=$(awk -v a="$a" -v p="$p" -v c="$c" 'BEGIN { if (p > 0 && a > 0) printf " %.2fx@%s", a / p, c; else printf " -@%s", c }')
  done
  printf '  %s\n' "$ratios"
done
# Paired ratios: asperity against each engine within each round (the two ran minutes apart, so
# a machine whose speed drifts slows both alike); the median over the rounds is the figure to
# quote on a shared machine, with the smallest and largest round.
if [[ $ROUNDS -gt 1 ]]; then
  for e in $ENGINES; do
    [[ $e == asperity || -z ${available[$e]:-} ]] && continue
    line=""
    for c in $CORES; do
      list=""
      for r in $(seq 1 "$ROUNDS"); do
        a=${rates[asperity,$c,$r]:-} p=${rates[$e,$c,$r]:-}
        [[ -n $a && -n $p ]] && list+=$(awk -v a="$a" -v p="$p" 'BEGIN { printf "%.4f ", a / p }')
      done
      [[ -z $list ]] && continue
      median[$e,$c]=$(echo "$list" | tr ' ' '\n' | sed '/^$/d' | sort -g | awk '{ v[NR] = $1 }
        END { printf "%.4f", (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }')
      line+=$(echo "$list" | tr ' ' '\n' | sed '/^$/d' | sort -g | awk -v c="$c" '{ v[NR] = $1 }
        END { m = (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
              printf "  %.2fx@%s (rounds %.2f-%.2f)", m, c, v[1], v[NR] }')
    done
    echo "asperity/$e, median of the rounds' paired ratios:$line"
  done
fi
# The bonded scene is the same work only while the engines hold the same bonds.
if [[ $SCENE == bonded ]]; then
  for e in $ENGINES; do
    [[ $e == asperity || -z ${available[$e]:-} ]] && continue
    for c in $CORES; do
      for r in $(seq 1 "$ROUNDS"); do
        x=${bonds[asperity,$c,$r]:-} y=${bonds[$e,$c,$r]:-}
        [[ -z $x || -z $y ]] && continue
        [[ $x == "$y" ]] || echo "bonds differ, round $r, $c core(s): asperity $x, $e $y (the ratio compares unlike work)"
      done
    done
  done
fi
a1=${best_cpu[asperity,1]:-} l1=${best_cpu[lammps,1]:-}
if [[ -n $a1 && -n $l1 ]]; then
  awk -v a="$a1" -v l="$l1" 'BEGIN { printf "1 core, per CPU-second (robust on a busy machine): asperity %.4g, lammps %.4g, ratio %.2fx\n", a, l, a / l }'
fi
for e in $ENGINES; do
  one=${best[$e,1]:-0} two=${best[$e,2]:-0}
  awk -v e="$e" -v a="$one" -v b="$two" 'BEGIN { if (a > 0 && b > 0) printf "%-10s 1 -> 2 cores: speed-up %.2f, parallel efficiency %.0f %%\n", e, b / a, 50 * b / a }'
done

mkdir -p "$here/results"
csv=$(results_file "$repo" "$([[ $SCENE == bonded ]] && echo -bonded)")
[[ -s $csv ]] || echo "date,cpu_model,simd,commit,engine,engine_version,cores,n,particles,steps,particle_steps_per_s,load_avg,particle_steps_per_cpu_s" >"$csv"
now=$(date -u +%Y-%m-%dT%H:%M:%SZ)
load=$(cut -d' ' -f1 /proc/loadavg)
for e in $ENGINES; do
  for c in $CORES; do
    [[ -n ${best[$e,$c]:-} ]] || continue
    echo "$now,\"$cpu\",$simd,$commit,$e,$(engine_version "$e"),$c,$N,$((N * N * N)),$STEPS,${best[$e,$c]},$load,${best_cpu[$e,$c]:-}" >>"$csv"
  done
done
echo "appended to ${csv#"$repo"/}"

# The guard: asperity at least GUARD x LAMMPS on the lattice, same run, at every core count (the
# median of the paired ratios with ROUNDS > 1, else the ratio of the two runs). GUARD=0: no check.
# The lattice only: the bonded scene has no guard.
status=0
if [[ $SCENE == lattice && ${GUARD} != 0 && -n ${available[lammps]:-} ]]; then
  for c in $CORES; do
    r=${median[lammps,$c]:-}
    if [[ -z $r && -n ${best[asperity,$c]:-} && -n ${best[lammps,$c]:-} ]]; then
      r=$(awk -v a="${best[asperity,$c]}" -v p="${best[lammps,$c]}" 'BEGIN { printf "%.4f", a / p }')
    fi
    [[ -z $r ]] && continue
    if awk -v r="$r" -v g="$GUARD" 'BEGIN { exit !(r < g) }'; then
      printf 'guard FAILED: asperity/lammps %.2fx on %s core(s), below %sx\n' "$r" "$c" "$GUARD"
      status=1
    else
      printf 'guard held: asperity/lammps %.2fx on %s core(s) (at least %sx)\n' "$r" "$c" "$GUARD"
    fi
  done
fi
exit $status
