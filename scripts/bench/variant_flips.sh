#!/usr/bin/env bash
# Frame times and converged FLIPs of render-flag variants, one binary, one GPU call (issue 14):
# flag_sweep.sh over VARIANTS (1080p, 16 spp, models trained in the call, REPS interleaved rounds), then
# per scene a FLIP_SPP classical reference (seed 7), a classical render (seed 0: the noise floor) and
# each hybrid variant (seed 0) at FLIP_W x FLIP_H, and their FLIPs against the reference and against
# the classical render of the same seed (OUT/flips.txt; stats of each render in OUT/SCENE_flip_NAME.json).
# Usage (GPU machine, after `source .device/env.sh`): VARIANTS=$'off|--neural-occupancy off\non|' scripts/bench/variant_flips.sh OUT
# Env: as flag_sweep.sh (SCENES among them), plus FLIP_W (960), FLIP_H (540), FLIP_SPP (2048). The occupancy A/B of
# results/perf/ab_occupancy_h100.json is the VARIANTS above with REPS=3. FRAMES=0: no frame times, the
# models trained here (TRAIN_ARGS too); KEEP_IMAGES=1: the compared PNGs go to OUT (SCENE_ref.png, the
# reference; SCENE_cl.png, the classical image of the variants' seed; SCENE_v_NAME.png), for
# scripts/bench/panel.py.
set -euo pipefail
cd "$(dirname "$0")/../.."
source scripts/bench/lib.sh
OUT=$1
mkdir -p "$OUT"
T=${TMPDIR:-/tmp}/nbvh_sweep
B=${NBVH:-.device/study/bin/nbvh}
if [ "${FRAMES:-1}" = 0 ]; then
  mkdir -p "$T"
  # shellcheck disable=SC2206
  TA=(${TRAIN_ARGS:-})
  for scene in ${SCENES:-default dragon}; do
    bench_scene "$scene" "$T"
    "$B" train "${SRC[@]}" "${NEURAL[@]}" "${TA[@]}" --out "$T/$scene.nbvh" > "$OUT/train_$scene.log" 2>&1
  done
else
  REPS=${REPS:-3} scripts/bench/flag_sweep.sh "$OUT/sweep" > "$OUT/sweep.txt" 2>&1 || echo sweep failed
fi
I=$T
if [ "${KEEP_IMAGES:-0}" = 1 ]; then I=$OUT; fi
R=(--width "${FLIP_W:-960}" --height "${FLIP_H:-540}" --max-depth "${MAX_DEPTH:-8}" --exposure 0 --spp "${FLIP_SPP:-2048}")
mapfile -t V <<< "${VARIANTS:?VARIANTS: lines NAME|FLAGS}"
# shellcheck disable=SC2206
SC=(${SCENES:-default dragon})
for scene in "${SC[@]}"; do
  bench_scene "$scene" "$T"
  S=("${SRC[@]}" "${VIEW[@]}"); C=("${NEURAL[@]}" --classical)
  $B render "${S[@]}" "${C[@]}" "${R[@]}" --seed 7 --out "$I/${scene}_ref.png" > /dev/null 2>&1
  $B render "${S[@]}" "${C[@]}" "${R[@]}" --out "$I/${scene}_cl.png" > /dev/null 2>&1
  line="$scene floor(classical vs ref) $($B flip "$I/${scene}_ref.png" "$I/${scene}_cl.png" | tail -1)"
  for v in "${V[@]}"; do
    name=${v%%|*}
    # shellcheck disable=SC2206
    F=(${v#*|})
    $B render "${S[@]}" --model "$T/$scene.nbvh" "${F[@]}" "${R[@]}" --out "$I/${scene}_v_$name.png" \
      --stats "$OUT/${scene}_flip_$name.json" > /dev/null 2>&1
    line="$line | $name: vs ref $($B flip "$I/${scene}_ref.png" "$I/${scene}_v_$name.png" | tail -1), vs classical (same seed) $($B flip "$I/${scene}_cl.png" "$I/${scene}_v_$name.png" | tail -1)"
  done
  echo "$line" | tee -a "$OUT/flips.txt"
done
grep -h "occupancy masks" "$OUT"/sweep/train_*.log || true
if [ -f "$OUT/sweep.txt" ]; then tail -30 "$OUT/sweep.txt"; fi
