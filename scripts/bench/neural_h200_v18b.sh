#!/usr/bin/env bash
# As run for results/neural/ (moved from results/neural/gpu_run_*.sh; .devbin/ and build-qps-dev/ were that
# session's ignored folders of binaries: nbvh, nbvh_cuda (CUDA build), bench_final = nbvh_bench_neural).
# GPU session v18, run 2 (committed figures of the v18 code): `nbvh bench` per LoD with the v14 CPU
# model, then a paper-size model of the default scene trained on this GPU (CUDA backend, defaults,
# --lods 5) and rendered at 1080p 4 spp: <= 4 leaves/ray with secondary LoD 4, and <= 8 leaves/ray on
# the finest cut; FLIP vs the classical reference.
set -u
source .device/env.sh
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
B=.devbin/nbvh; BC=.devbin/nbvh_cuda; M=.devbin/default_lods5.nbvh
W="--width 1920 --height 1080 --spp 4 --device gpu"
rm -rf /tmp/f; mkdir -p /tmp/f
$B bench default --model $M --device gpu --spp 4 --repeat 3 --json $OUT/bench_default_lods5_h200_v18.json 2>&1 | tail -8
/usr/bin/time -f "train wall %e s" $BC train default --backend cuda --lods 5 -o /tmp/f/default_cuda.nbvh 2>&1 | tail -3
$B render default $W --classical --out /tmp/f/c.png > /dev/null 2>&1
$B render default $W --classical --out /tmp/f/c.png --stats /tmp/f/c.json 2>&1 | tail -1
for cfg in "4 0 4" "8 0 0"; do set -- $cfg
  $B render default $W --model /tmp/f/default_cuda.nbvh --neural-max-leaves $1 --lod $2 --secondary-lod $3 --out /tmp/f/hc_$1_$2_$3.png > /dev/null 2>&1
  $B render default $W --model /tmp/f/default_cuda.nbvh --neural-max-leaves $1 --lod $2 --secondary-lod $3 --out /tmp/f/hc_$1_$2_$3.png --stats $OUT/frame_1080p_default_cudamodel_h_$1_$2_$3_h200_v18.json 2>&1 | tail -2
  echo "cuda model, max-leaves $1 lod $2 secondary-lod $3 vs classical: $($B flip /tmp/f/c.png /tmp/f/hc_$1_$2_$3.png)"
done
$B bench default --model /tmp/f/default_cuda.nbvh --device gpu --spp 4 --repeat 3 --json $OUT/bench_default_cudamodel_h200_v18.json 2>&1 | tail -8
cp /tmp/f/hc_4_0_4.png $OUT/hybrid_cudamodel_m4_sec4_1080p.png
cp /tmp/f/c.png $OUT/classical_1080p_4spp.png
