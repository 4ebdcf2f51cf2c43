#!/bin/sh
# Runs the Lua API fuzz driver (fuzz.lua) over many seeds, in chunks with a time limit each, and
# tallies the outcomes: a chunk that dies of a signal or a sanitizer report is a crash, one that
# outlives its limit a hang; fuzz.lua itself reports calls that return success with non-finite
# state (silent NaN). A failing chunk is rerun seed by seed to name the seeds.
#
#   tests/fuzz/run.sh ASPERITY_EXE [FIRST_SEED [LAST_SEED [CHUNK [CALLS]]]]
#   e.g. tests/fuzz/run.sh build/asperity 1 20000 200            (release build)
#        tests/fuzz/run.sh build-asan/asperity 1 3000 100         (ASan + UBSan build)
# Output files go to ${FUZZ_OUT:-/tmp/asperity-fuzz}. Exit status 0 only when every seed passed.
set -u
exe=${1:?usage: run.sh ASPERITY_EXE [FIRST [LAST [CHUNK [CALLS]]]]}
first=${2:-1}
last=${3:-1000}
chunk=${4:-100}
calls=${5:-60}
limit=${FUZZ_TIMEOUT:-300}
out=${FUZZ_OUT:-/tmp/asperity-fuzz}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1} UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}

sequences=0 calls_total=0 crashes=0 hangs=0 silent=0 failed_seeds=""

# One run of seeds A..B; sets rc and appends the summary numbers.
run() {
  log="$out/seeds-$1-$2.log"
  timeout -s KILL "$limit" "$exe" run "$here/fuzz.lua" out="$out/files-$1" seeds="$1-$2" calls="$calls" >"$log" 2>&1
  rc=$?
}

tally() {  # the summary line of the last run
  line=$(grep '^fuzz: seeds' "$log" | tail -1)
  if [ -n "$line" ]; then
    sequences=$((sequences + $(echo "$line" | sed 's/.*sequences \([0-9]*\).*/\1/')))
    calls_total=$((calls_total + $(echo "$line" | sed 's/.*calls \([0-9]*\).*/\1/')))
    silent=$((silent + $(echo "$line" | sed 's/.*silent NaN \([0-9]*\).*/\1/')))
  fi
}

a=$first
while [ "$a" -le "$last" ]; do
  b=$((a + chunk - 1))
  [ "$b" -gt "$last" ] && b=$last
  run "$a" "$b"
  if [ "$rc" -eq 0 ] && grep -q '^PASS' "$log"; then
    tally
  else
    # Seed by seed, to count and name the culprits.
    s=$a
    while [ "$s" -le "$b" ]; do
      run "$s" "$s"
      tally
      if [ "$rc" -eq 0 ] && grep -q '^PASS' "$log"; then
        rm -f "$log"
      elif [ "$rc" -eq 137 ]; then
        hangs=$((hangs + 1)); sequences=$((sequences + 1)); failed_seeds="$failed_seeds $s(hang)"
      elif grep -q '^fuzz: seeds' "$log"; then
        failed_seeds="$failed_seeds $s(silent-nan)"
      else
        crashes=$((crashes + 1)); sequences=$((sequences + 1)); failed_seeds="$failed_seeds $s(crash)"
      fi
      s=$((s + 1))
    done
  fi
  a=$((b + 1))
done

echo "fuzz $exe: seeds $first-$last, sequences $sequences, calls $calls_total, crashes $crashes, hangs $hangs, silent NaN $silent"
[ -n "$failed_seeds" ] && echo "failed seeds (logs in $out):$failed_seeds"
[ "$crashes" -eq 0 ] && [ "$hangs" -eq 0 ] && [ "$silent" -eq 0 ]
