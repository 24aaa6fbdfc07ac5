#!/usr/bin/env bash
# As run for results/neural/ (moved from results/neural/gpu_run_*.sh; .devbin/ and build-qps-dev/ were that
# session's ignored folders of binaries: nbvh, nbvh_cuda (CUDA build), bench_final = nbvh_bench_neural).
# GPU session v17, final run (committed figures): the final kernel (weight tiles, paired gather of 4
# levels at once) in nbvh_bench_neural (random and coherent queries; the fp16-accumulator kernel is
# checked too), the 1080p frame (classical, hybrid coopmat, hybrid scalar) and `nbvh bench` with the
# v14 CPU-trained model, then a paper-size model of the default scene trained on this GPU with the
# CUDA backend and rendered the same way. Writes JSON/PNG under $OUT.
set -u
source .device/env.sh
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
D=build-qps-dev/carry; B=.devbin/nbvh; BC=.devbin/nbvh_cuda; M=.devbin/default_lods5.nbvh
for q in random coherent; do
  extra=""; [ $q = coherent ] && extra="--coherent --model $D/default.nbvh"
  timeout 90 $D/bench_final --device gpu --queries 4194304 --reps 10 $extra --json $OUT/bench_neural_queries_${q}_h200_v17.json 2>&1 | grep -v "coopmat shape"
done
W="--width 1920 --height 1080 --spp 4 --device gpu"
rm -rf /tmp/f; mkdir -p /tmp/f
$B render default $W --classical --out /tmp/f/c.png > /dev/null 2>&1
$B render default $W --classical --out /tmp/f/c.png --stats $OUT/frame_1080p_default_classical_h200_v17.json 2>&1 | tail -1
$B render default $W --model $M --neural-max-leaves 4 --secondary-lod 4 --out /tmp/f/h.png > /dev/null 2>&1
$B render default $W --model $M --neural-max-leaves 4 --secondary-lod 4 --out /tmp/f/h.png --stats $OUT/frame_1080p_default_lods5_h_4_0_4_h200_v17.json 2>&1 | tail -2
echo "hybrid vs classical: $($B flip /tmp/f/c.png /tmp/f/h.png)"
$B render default $W --model $M --neural-max-leaves 4 --secondary-lod 4 --neural-path scalar --out /tmp/f/s.png 2>&1 | tail -1
echo "scalar vs coopmat: $($B flip /tmp/f/h.png /tmp/f/s.png)"
$B bench default --model $M --device gpu --spp 4 --repeat 3 --json $OUT/bench_default_lods5_h200_v17.json 2>&1 | tail -8
echo "=== paper-size model trained with CUDA on this GPU"
/usr/bin/time -f "train wall %e s" $BC train default --backend cuda --lods 5 -o /tmp/f/default_cuda.nbvh --log /tmp/f/train.csv 2>&1 | tail -4
$BC info /tmp/f/default_cuda.nbvh 2>&1 | head -12
timeout 90 $D/bench_final --device gpu --queries 4194304 --reps 10 --coherent --model /tmp/f/default_cuda.nbvh --json $OUT/bench_neural_queries_coherent_cudamodel_h200_v17.json 2>&1 | grep -v "coopmat shape"
for cfg in "4 0 4" "8 0 0"; do set -- $cfg
  $B render default $W --model /tmp/f/default_cuda.nbvh --neural-max-leaves $1 --lod $2 --secondary-lod $3 --out /tmp/f/hc_$1_$2_$3.png > /dev/null 2>&1
  $B render default $W --model /tmp/f/default_cuda.nbvh --neural-max-leaves $1 --lod $2 --secondary-lod $3 --out /tmp/f/hc_$1_$2_$3.png --stats /tmp/f/hc_$1_$2_$3.json 2>&1 | tail -2
  echo "cuda model, max-leaves $1 lod $2 secondary-lod $3 vs classical: $($B flip /tmp/f/c.png /tmp/f/hc_$1_$2_$3.png)"
done
cp /tmp/f/hc_4_0_4.json $OUT/frame_1080p_default_cudamodel_h_4_0_4_h200_v17.json
cp /tmp/f/hc_4_0_4.png $OUT/hybrid_cudamodel_m4_sec4_1080p.png
tail -1 /tmp/f/train.csv
