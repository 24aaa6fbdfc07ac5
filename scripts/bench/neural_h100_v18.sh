#!/usr/bin/env bash
# As run for results/neural/ (moved from results/neural/gpu_run_*.sh; .devbin/ and build-qps-dev/ were that
# session's ignored folders of binaries: nbvh, nbvh_cuda (CUDA build), bench_final = nbvh_bench_neural).
# The v18 code on an H100 (device kind nvidia-h100-x1): neural queries/s (random, coherent) and the
# 1080p hybrid vs classical frame, as on the H200 (neural_h200_v17f.sh). Writes JSON.
set -u
source .device/env.sh
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
D=build-qps-dev/carry; B=.devbin/nbvh; M=.devbin/default_lods5.nbvh
timeout 90 $D/bench_final --device gpu --queries 4194304 --reps 10 --json $OUT/bench_neural_queries_random_h100_v18.json 2>&1 | grep -v "coopmat shape"
timeout 90 $D/bench_final --device gpu --queries 4194304 --reps 10 --coherent --model $D/default.nbvh --json $OUT/bench_neural_queries_coherent_h100_v18.json 2>&1 | grep -v "coopmat shape"
W="--width 1920 --height 1080 --spp 4 --device gpu"
rm -rf /tmp/f; mkdir -p /tmp/f
$B render default $W --classical --out /tmp/f/c.png > /dev/null 2>&1
$B render default $W --classical --out /tmp/f/c.png --stats $OUT/frame_1080p_default_classical_h100_v18.json 2>&1 | tail -1
$B render default $W --model $M --neural-max-leaves 4 --secondary-lod 4 --out /tmp/f/h.png > /dev/null 2>&1
$B render default $W --model $M --neural-max-leaves 4 --secondary-lod 4 --out /tmp/f/h.png --stats $OUT/frame_1080p_default_lods5_h_4_0_4_h100_v18.json 2>&1 | tail -2
echo "hybrid vs classical: $($B flip /tmp/f/c.png /tmp/f/h.png)"
