#!/usr/bin/env bash
set -u
D=build-neuralvk-dev
source .device/env.sh
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
$D/nbvh_bench_neural --device gpu --queries 4194304 --reps 10 --json $OUT/bench_random.json | grep -v "coopmat shape"
$D/nbvh_bench_neural --device gpu --queries 4194304 --reps 10 --coherent --model $D/default.nbvh --json $OUT/bench_coherent_trained.json | grep -v "coopmat shape"
R="$D/nbvh render default --device gpu --width 1920 --height 1080 --spp 4 --wave-pixels 2097152"
$R --classical --out /tmp/classical.png --stats $OUT/classical_stats.json 2>&1 | grep "render: 1920"
$R --model $D/default.nbvh --neural-path scalar --out /tmp/scalar.png --stats /tmp/scalar.json 2>&1 | grep "render: [1n]"
$R --model $D/default.nbvh --neural-path coopmat --out /tmp/coopmat.png --stats $OUT/coopmat_stats.json 2>&1 | grep "render: [1n]"
$R --model $D/default.nbvh --neural-path coopmat --neural-max-leaves 4 --out /tmp/m4.png --stats $OUT/coopmat_max4_stats.json 2>&1 | grep "render: [1n]"
echo "FLIP scalar vs coopmat:"; $D/nbvh flip /tmp/scalar.png /tmp/coopmat.png | tail -1
echo "FLIP classical vs coopmat:"; $D/nbvh flip /tmp/classical.png /tmp/coopmat.png | tail -1
echo "FLIP classical vs coopmat max 4:"; $D/nbvh flip /tmp/classical.png /tmp/m4.png | tail -1
