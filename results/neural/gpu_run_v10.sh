#!/usr/bin/env bash
# GPU session v10 (issue 4, kernel variants g p, see engine/render/neural_model_gpu.h):
# all in one run. Writes JSON/PNG under $OUT.
set -u
D=build-neuralperf-dev
source .device/env.sh
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
for v in g p; do
  echo "=== variant $v"
  J=$OUT; [ $v = base ] && J=/tmp
  NBVH_NEURAL_COOP_VARIANT=$v $D/nbvh_bench_neural --device gpu --queries 4194304 --reps 10 --json $J/bench_random_$v.json | grep -v "coopmat shape" | grep -i "G queries\|breakdown\|scalar vs"
  NBVH_NEURAL_COOP_VARIANT=$v $D/nbvh_bench_neural --device gpu --queries 4194304 --reps 10 --coherent --model $D/default.nbvh --json $J/bench_coherent_$v.json | grep -v "coopmat shape" | grep -i "G queries\|breakdown\|scalar vs"
done
R="$D/nbvh render default --device gpu --width 1920 --height 1080 --spp 4 --wave-pixels 2097152"
$R --classical --out /tmp/classical.png --stats $OUT/classical_stats.json 2>&1 | grep "render: 1920"
for v in g p; do
  S=$OUT; [ $v = p ] && S=/tmp
  NBVH_NEURAL_COOP_VARIANT=$v $R --model $D/default.nbvh --neural-path coopmat --out /tmp/c_$v.png --stats $S/coopmat_$v.json 2>&1 | grep "render: [1n]"
  NBVH_NEURAL_COOP_VARIANT=$v $R --model $D/default.nbvh --neural-path coopmat --neural-max-leaves 4 --out /tmp/m4_$v.png --stats $S/coopmat_max4_$v.json 2>&1 | grep "render: [1n]"
  echo "FLIP classical vs coopmat $v:"; $D/nbvh flip /tmp/classical.png /tmp/c_$v.png | tail -1
  echo "FLIP classical vs coopmat max4 $v:"; $D/nbvh flip /tmp/classical.png /tmp/m4_$v.png | tail -1
  echo "FLIP g vs $v:"; $D/nbvh flip /tmp/c_g.png /tmp/c_$v.png | tail -1
done
for f in $OUT/classical_stats.json $OUT/coopmat*.json /tmp/coopmat*.json; do echo "== $f"; python3 -c "
import json; j=json.load(open('$f'))
if 'gpu_total_ms' in j: print('gpu_total_ms', round(j['gpu_total_ms'],2), json.dumps(j.get('neural',{}))); print({k:round(v,2) for k,v in sorted(j['pass_gpu_ms'].items(), key=lambda x:-x[1])[:6]})
"; done
