#!/usr/bin/env bash
# One GPU session of the neural benchmarks (issue 4). Writes JSON/PNG under $OUT.
set -u
D=build-neuralvk-dev
source .device/env.sh
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
$D/nbvh_bench_neural --device gpu --queries 4194304 --reps 10 --json $OUT/bench_random.json | grep -v "coopmat shape"
$D/nbvh_bench_neural --device gpu --queries 4194304 --reps 10 --coherent --model $D/default.nbvh --json $OUT/bench_coherent_trained.json | grep -v "coopmat shape"
W=${WAVE:-2097152}
R="$D/nbvh render default --device gpu --width 1920 --height 1080 --spp 4 --wave-pixels $W"
$R --classical --out /tmp/classical.png --stats $OUT/classical_stats.json 2>&1 | grep "render: 1920"
$R --model $D/default.nbvh --neural-path scalar --out /tmp/scalar.png --stats $OUT/scalar_stats.json 2>&1 | grep "render: [1n]"
$R --model $D/default.nbvh --neural-path coopmat --out $OUT/coopmat.png --stats $OUT/coopmat_stats.json 2>&1 | grep "render: [1n]"
$R --model $D/default.nbvh --neural-path coopmat --neural-max-leaves 4 --out /tmp/m4.png --stats /tmp/m4.json 2>&1 | grep "render: 1920"
$R --model $D/default.nbvh --neural-path coopmat --lod 0 --secondary-lod 1 --out /tmp/l1.png --stats /tmp/l1.json 2>&1 | grep "render: 1920"
echo "FLIP scalar vs coopmat:"; $D/nbvh flip /tmp/scalar.png $OUT/coopmat.png | tail -1
echo "FLIP classical vs coopmat:"; $D/nbvh flip /tmp/classical.png $OUT/coopmat.png | tail -1
echo "FLIP classical vs coopmat max 4 leaves:"; $D/nbvh flip /tmp/classical.png /tmp/m4.png | tail -1
echo "FLIP classical vs scalar:"; $D/nbvh flip /tmp/classical.png /tmp/scalar.png | tail -1
$D/nbvh flip /tmp/classical.png $OUT/coopmat.png --heatmap $OUT/flip_classical_vs_coopmat.png 2>&1 | tail -1
for f in $OUT/classical_stats.json $OUT/scalar_stats.json $OUT/coopmat_stats.json /tmp/m4.json /tmp/l1.json; do echo "== $f"; python3 -c "
import json,sys; j=json.load(open('$f')); print('gpu_total_ms', round(j['gpu_total_ms'],2), 'spp', j['spp'], json.dumps(j.get('neural',{}))); print({k:round(v,2) for k,v in sorted(j['pass_gpu_ms'].items(), key=lambda x:-x[1])[:9]})"; done
cp /tmp/m4.json $OUT/coopmat_max4_stats.json
