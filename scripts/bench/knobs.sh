#!/usr/bin/env bash
# GPU machine (results/perf/knobs_h200.txt, issue 14): one binary, hybrid leaves-per-round x wave paths, classical wave paths; 1080p 16 spp, interleaved reps
set -euo pipefail
B=${NBVH:-.device/study/bin/nbvh}; OUT=$1; T=/tmp/knobs; mkdir -p $T $OUT
source "$(dirname "$0")/lib.sh"
unpack .device/study/dragon/dragon_vrip.glb.xz $T/dragon.glb
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | tee $OUT/device.txt
$B train default --out $T/default.nbvh > $OUT/train_default.log 2>&1
$B train $T/dragon.glb --neural '*' --out $T/dragon.nbvh > $OUT/train_dragon.log 2>&1
R=(--width 1920 --height 1080 --max-depth 8 --exposure 0)
V=("c 8388608" "c 16777216" "4 8388608" "2 8388608" "1 8388608" "2 16777216" "1 16777216")
for scene in default dragon; do
  if [ $scene = default ]; then S=(default); else S=($T/dragon.glb); fi
  $B render "${S[@]}" --model $T/$scene.nbvh "${R[@]}" --spp 4 --out $T/warm.png >/dev/null 2>&1
  for rep in 1 2; do for v in "${V[@]}"; do set -- $v
    if [ $1 = c ]; then A=(--classical); [ $scene = dragon ] && A=(--neural '*' --classical); else A=(--model $T/$scene.nbvh --neural-leaves-per-round $1); fi
    $B render "${S[@]}" "${A[@]}" "${R[@]}" --wave-pixels $2 --spp 16 --out $T/${scene}_$1_$2.png --stats $OUT/${scene}_$1_$2_$rep.json > $T/log 2>&1 || { echo "FAIL $scene $v"; tail -2 $T/log; }
  done; done
  for v in "2 8388608" "1 8388608" "2 16777216"; do set -- $v; echo "$scene K=$1 W=$2 vs K=4: $($B flip $T/${scene}_4_8388608.png $T/${scene}_$1_$2.png 2>&1 | tail -1)"; done
done
python3 - $OUT <<'PY'
import json,glob,os,sys
d=sys.argv[1]; rows={}
for f in sorted(glob.glob(os.path.join(d,"*_[12].json"))):
  k=os.path.basename(f)[:-7]; j=json.load(open(f)); rows.setdefault(k,[]).append(j["gpu_total_ms"]/j["spp"])
  n=j.get("neural") or {}
  rows[k+"_q"]=(n.get("queries_per_ray"),n.get("queries_per_second"))
for k in sorted(rows):
  if not k.endswith("_q"): print("%-28s best %.3f ms/spp  all %s  q/ray,q/s %s"%(k,min(rows[k]),rows[k],rows.get(k+"_q")))
PY
