#!/usr/bin/env bash
# A/B of CUDA training binaries in one run on one GPU (issue 14, results/cuda_training.md): each
# `bench_cuda_training` binary's fixed-cut step benchmark on the dragon (paper configuration: batch 2^18,
# T = 2^18, a cut of 2,048 leaves, mean of 100 steps after 20 warm-up; with the next batch drawn ahead,
# and every phase in sequence), REPS rounds with the binaries interleaved (clocks and caches drift alike);
# then the CUDA tests of TESTS (when given) and the paper-size training (official Chess schedule, 25,249
# nodes, 10,000 steps) of each binary in FULL. Prints the "full step", "phases" and "training" lines,
# writes every log and JSON to OUT.
# Usage (GPU machine, after `source .device/env.sh`): scripts/bench/ab_training.sh OUT NAME=BINARY...
#   e.g. scripts/bench/ab_training.sh $OUT old=.device/tr/bench-OLD new=build/tests/cuda/bench_cuda_training
# Env: DRAGON (xz-packed glb, default .device/study/dragon/dragon_vrip.glb.xz), REPS (default 2),
#      FULL (names to train at paper size, default: every one), TESTS (an nbvh_cuda_tests binary; its
#      scene tests read BUNNY, an xz-packed tar of scenes/stanford_bunny, default
#      .device/scenes/stanford_bunny.tar.xz).
set -euo pipefail
cd "$(dirname "$0")/../.."
source scripts/bench/lib.sh
OUT=$1
shift
[ $# -ge 1 ] || { echo "usage: $0 OUT NAME=BINARY..." >&2; exit 2; }
declare -A BIN
NAMES=()
for a in "$@"; do
  [[ $a == *=* ]] || { echo "$0: '$a' is not NAME=BINARY" >&2; exit 2; }
  BIN[${a%%=*}]=${a#*=}
  NAMES+=("${a%%=*}")
done
T=${TMPDIR:-/tmp}/nbvh_ab_training
mkdir -p "$OUT" "$T"
unpack "${DRAGON:-.device/study/dragon/dragon_vrip.glb.xz}" "$T/dragon_vrip.glb"
(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader || echo "no nvidia-smi") | tee "$OUT/device.txt"
for r in $(seq 1 "${REPS:-2}"); do
  for v in "${NAMES[@]}"; do
    "${BIN[$v]}" --scene "$T/dragon_vrip.glb" --skip-train --json "$OUT/skip_${v}_$r.json" > "$OUT/skip_${v}_$r.log" 2>&1
    grep -E 'full step|phases' "$OUT/skip_${v}_$r.log" | sed "s/^/$v $r: /"
  done
done
if [ -n "${TESTS:-}" ]; then
  mkdir -p "$T/shared/scenes"
  if [ -f "${BUNNY:-.device/scenes/stanford_bunny.tar.xz}" ]; then
    tar -xJf "${BUNNY:-.device/scenes/stanford_bunny.tar.xz}" -C "$T/shared/scenes/"
  fi
  rc=0
  NBVH_SHARED_DIR="$T/shared" timeout 300 "$TESTS" > "$OUT/cuda_tests.log" 2>&1 || rc=$?
  echo "tests rc $rc: $(grep -E '^\[  (PASSED|FAILED)' "$OUT/cuda_tests.log" | tr '\n' ' ')"
  grep -E 'same rays|clip_regular' "$OUT/cuda_tests.log" || true
fi
for v in ${FULL:-${NAMES[*]}}; do
  "${BIN[$v]}" --scene "$T/dragon_vrip.glb" --json "$OUT/full_$v.json" > "$OUT/full_$v.log" 2>&1
  grep -E 'full step|training:' "$OUT/full_$v.log" | sed "s/^/$v full: /"
done
