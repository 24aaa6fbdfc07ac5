#!/usr/bin/env bash
# How the noise floor falls with spp (issue 11: "converged" study images): classical renders of the default
# scene and Chess (paper camera) at 960x540, max depth 8, against a 16384-spp classical reference (seed
# 1000): the same renderer at 256 .. 4096 spp (seed 1) and at 16384 spp with another seed (seed 2000, the
# reference's own floor); then a default-trained hybrid (`nbvh train default`) at growing spp against the
# same reference. LDR-FLIP of the PNGs at the reference's auto exposure. Prints one line per render
# (FLIP, GPU ms, wall ms). Writes OUT/noise_floor.log and the references' PNGs.
# Usage (GPU machine, after `source .device/env.sh`): scripts/bench/noise_floor.sh OUT
# Env: NBVH (xz-packed binary, default .device/study/bin/nbvh.xz), CHESS (.device/study/chess).
set -uo pipefail
cd "$(dirname "$0")/../.."
OUT=$1
mkdir -p "$OUT"
source scripts/bench/lib.sh
B=/tmp/nbvh_floor
unpack "${NBVH:-.device/study/bin/nbvh.xz}" $B && chmod +x $B
CHESS=${CHESS:-.device/study/chess}
unpack "$CHESS/abeautifulgame.glb.xz" /tmp/chess.glb
{
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
W=(--width 960 --height 540 --max-depth 8)
CH=(/tmp/chess.glb --camera 0.600,0.358,0.179,-0.197,-0.197,-0.057,45 --env "$CHESS/photo_studio_loft_hall_512x256.hdr" --env-rotation 285)
timed() { # NAME ARGS...: render, print FLIP against REF, GPU and wall ms
  local name=$1; shift
  local t0 t1; t0=$(date +%s%N)
  $B render "$@" --out /tmp/$name.png > /tmp/$name.log 2>&1
  t1=$(date +%s%N)
  echo "$name: $($B flip "$REF" /tmp/$name.png 2>&1 | grep -i mean); $(grep -o '[0-9.]* ms GPU' /tmp/$name.log); wall $(( (t1 - t0) / 1000000 )) ms"
}
for s in default chess; do
  if [ $s = default ]; then S=(default); else S=("${CH[@]}"); fi
  $B render "${S[@]}" "${W[@]}" --classical --spp 16384 --seed 1000 --out /tmp/${s}_ref.png > /tmp/${s}_ref.log 2>&1
  REF=/tmp/${s}_ref.png
  E=$(grep -o "exposure [-+0-9.]* stops" /tmp/${s}_ref.log | awk '{print $2}')
  echo "$s reference: $(grep -o '[0-9.]* ms GPU' /tmp/${s}_ref.log), exposure $E"
  timed ${s}_16384_seed2000 "${S[@]}" "${W[@]}" --classical --spp 16384 --seed 2000 --exposure "$E"
  for spp in 4096 2048 1024 512 256; do
    timed ${s}_$spp "${S[@]}" "${W[@]}" --classical --spp $spp --seed 1 --exposure "$E"
  done
  cp /tmp/${s}_ref.png "$OUT/"
done
$B train default --out /tmp/d.nbvh > /tmp/train.log 2>&1; tail -1 /tmp/train.log
REF=/tmp/default_ref.png
E=$(grep -o "exposure [-+0-9.]* stops" /tmp/default_ref.log | awk '{print $2}')
for spp in 256 1024 4096; do
  timed hybrid_$spp default "${W[@]}" --model /tmp/d.nbvh --spp $spp --seed 1 --exposure "$E"
done
} 2>&1 | tee "$OUT/noise_floor.log"
