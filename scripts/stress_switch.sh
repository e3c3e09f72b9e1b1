#!/usr/bin/env bash
# Issue 41's stress must-show at full size, for an idle machine: the operator's switch time
# δ ∈ {0.5, 2, 7} s, rounds with and without holds for N = 2, 3, 4 (10⁶ executions at N = 2,
# 10⁵ at N = 3 and 4) and the continuous cell for N = 2, 3, 8 (10⁵ executions each), split into
# seeded batches (each a separate `xtask stress` run of at most ~20 minutes on a quiet machine;
# seeds 1, 2, … so the batches draw different problems). Every batch fails on a tick with two
# robots low-confidence, on two robots' low-confidence ticks fewer than k = switch_ticks(δ, tick)
# ticks apart (measured on the ticks the robots traversed, beam adversary included), or on an
# unfinished execution; the script stops at the first failing batch.
#
# Usage: scripts/stress_switch.sh [OUT_DIR]   (default results/stress_switch; logs per batch)
# Environment: DELTAS="0.5 2 7" to choose switch times; MAX_BUSY=0.7 to run the continuous
# batches with the operator's load cap as well (the paced coordinator; default: none);
# DRY_RUN=1 prints the commands only.
# Reduced sizes run on the shared machine: docs/decisions.md, "The switch time at run time
# (issue 41)", "Issue 41's must-shows run: …" and "Issue 41 line by line (issue 41)".
# Size reading: "10⁶ executions at N = 2" is read per row (each δ, with and without holds), the
# stricter of the readings; every other row 10⁵. A deterministic policy's run on a problem is
# run once and replayed for its other executions (the counts identical, `digest` line of each
# log); the batches run here and their sums: "Issue 41's stress at the issue's sizes (issue 41)".
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-results/stress_switch}"
mkdir -p "$out"
deltas="${DELTAS:-0.5 2 7}"
if [[ -z "${DRY_RUN:-}" ]]; then cargo build --quiet --release -p xtask; fi
x=target/release/xtask
cap=()
if [[ -n "${MAX_BUSY:-}" ]]; then cap=(--max-busy "$MAX_BUSY"); fi

run() { # name, command…
  local name="$1"; shift
  echo "$(date -u +%FT%TZ) $name: $*"
  if [[ -n "${DRY_RUN:-}" ]]; then return; fi
  /usr/bin/time -f "%e s wall" "$@" >"$out/$name.log" 2>&1 || {
    echo "FAILED: $name (see $out/$name.log)"; tail -20 "$out/$name.log"; exit 1; }
  grep -E "switch time|overlap|backward|unfinished|digest|s wall" "$out/$name.log" | sed 's/^/    /'
}

for d in $deltas; do
  # Rounds: N = 2 at 10 batches of 10⁵ (10⁶), N = 3 and 4 at 2 batches of 5·10⁴ (10⁵).
  for holds in "" "--holds"; do
    tag="${holds:+holds}"; tag="${tag:-plain}"
    for b in $(seq 1 10); do
      run "rounds_n2_${tag}_d${d}_b$b" "$x" stress --robots 2 $holds --executions 100000 \
        --problems 100 --seed "$b" --switch-s "$d"
    done
    for n in 3 4; do
      for b in 1 2; do
        run "rounds_n${n}_${tag}_d${d}_b$b" "$x" stress --robots "$n" $holds --executions 50000 \
          --problems 100 --seed "$b" --switch-s "$d"
      done
    done
  done
  # Continuous: 10⁵ executions of 10 tasks per robot (5 at N = 8) per N, in batches.
  for n in 2 3 8; do
    if [[ $n == 8 ]]; then batches=20; tasks=5; else batches=10; tasks=10; fi
    per=$((100000 / batches))
    for b in $(seq 1 "$batches"); do
      run "cont_n${n}_d${d}_b$b" "$x" stress --cell continuous --robots "$n" --tasks "$tasks" \
        --executions "$per" --problems 100 --seed "$b" --switch-s "$d" ${cap[@]+"${cap[@]}"}
    done
  done
done
echo "all batches passed; logs in $out"
