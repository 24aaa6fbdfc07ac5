#!/usr/bin/env bash
# Occupancy masks A/B (results/perf/ab_occupancy_h100.json): flag_sweep.sh with the masks off and on
# (frame times, 1080p 16 spp, models trained in the same call), then per scene a 960x540 2048-spp
# classical reference (seed 7), a classical render and the hybrid with masks on and off (seed 0), and
# their FLIPs (OUT/flip2048.txt). Usage (GPU machine): scripts/bench/occupancy_ab.sh OUT
set -euo pipefail
cd "$(dirname "$0")/../.."
source .device/env.sh
mkdir -p "$1"
OUT=$1
VARIANTS=$'off|--neural-occupancy off\non|' REPS=3 scripts/bench/flag_sweep.sh $OUT/sweep > $OUT/sweep.txt 2>&1 || echo sweep failed
T=${TMPDIR:-/tmp}/nbvh_sweep
B=.device/study/bin/nbvh
R=(--width 960 --height 540 --max-depth 8 --exposure 0 --spp 2048)
for scene in default dragon; do
  if [ $scene = default ]; then S=(default); C=(--classical); else S=("$T/dragon.glb"); C=(--neural '*' --classical); fi
  $B render "${S[@]}" "${C[@]}" "${R[@]}" --seed 7 --out $T/${scene}_ref.png > /dev/null 2>&1
  $B render "${S[@]}" "${C[@]}" "${R[@]}" --out $T/${scene}_cl.png > /dev/null 2>&1
  for o in on off; do $B render "${S[@]}" --model $T/$scene.nbvh "${R[@]}" --neural-occupancy $o --out $T/${scene}_$o.png --stats $OUT/${scene}_2048_$o.json > /dev/null 2>&1; done
  echo "$scene floor(cl vs ref) $($B flip $T/${scene}_ref.png $T/${scene}_cl.png | tail -1) on-vs-ref $($B flip $T/${scene}_ref.png $T/${scene}_on.png | tail -1) off-vs-ref $($B flip $T/${scene}_ref.png $T/${scene}_off.png | tail -1) on-vs-cl(same seed) $($B flip $T/${scene}_cl.png $T/${scene}_on.png | tail -1) off-vs-cl $($B flip $T/${scene}_cl.png $T/${scene}_off.png | tail -1)" | tee -a $OUT/flip2048.txt
done
grep -h "occupancy masks" $OUT/sweep/train_*.log
cat $OUT/sweep.txt | tail -30
