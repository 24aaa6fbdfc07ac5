#!/usr/bin/env bash
# GPU session v11 (issue 4, several leaves per ray per neural round, engine/render/neural_stage.h
# leaves_per_round): classical vs hybrid at 1080p 4 spp, in one run, with the previous binary (one leaf
# per round, build-neuralperf-dev) as the baseline. Writes JSON under $OUT.
set -u
N=build-rounds-dev   # this change (stripped nbvh + default.nbvh)
P=build-neuralperf-dev  # previous code (v10)
source .device/env.sh
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
A="render default --device gpu --width 1920 --height 1080 --spp 4 --wave-pixels 2097152"
H="--model $N/default.nbvh --neural-path coopmat"
$N/nbvh $A --classical --out /tmp/classical.png --stats $OUT/classical.json 2>&1 | grep "render: 1920"
for m in 8 4; do
  $P/nbvh $A $H --neural-max-leaves $m --out /tmp/prev_m$m.png --stats $OUT/prev_m$m.json 2>&1 | grep "render: [1n]"
  for k in 1 2 4; do
    NBVH_NEURAL_LEAVES_PER_ROUND=$k $N/nbvh $A $H --neural-max-leaves $m --out /tmp/k${k}_m$m.png --stats /tmp/k${k}_m$m.json 2>&1 | grep "render: [1n]"
    echo "m$m k$k FLIP vs classical: $($N/nbvh flip /tmp/classical.png /tmp/k${k}_m$m.png | tail -1)  vs prev: $($N/nbvh flip /tmp/prev_m$m.png /tmp/k${k}_m$m.png | tail -1)"
  done
  echo "m$m prev FLIP vs classical: $($N/nbvh flip /tmp/classical.png /tmp/prev_m$m.png | tail -1)"
done
cp /tmp/k4_m8.json /tmp/k4_m4.json /tmp/k2_m8.json /tmp/k2_m4.json $OUT/ 2>/dev/null
for f in $OUT/*.json /tmp/k1_m*.json; do echo "== $f"; python3 -c "
import json; j=json.load(open('$f'))
print('gpu_total_ms', round(j.get('gpu_total_ms',0),2), json.dumps(j.get('neural',{})))
print({k:round(v,2) for k,v in sorted(j['pass_gpu_ms'].items(), key=lambda x:-x[1])[:7]})
"; done
