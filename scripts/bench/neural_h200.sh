#!/usr/bin/env bash
# The run behind results/neural/'s H200 query figures (code 6c9c2e0; .devbin/ and build-qps-dev/ were that
# session's ignored folders of binaries: nbvh_cuda (CUDA build), bench_final = nbvh_bench_neural).
# nbvh_bench_neural, random and coherent queries (the fp16-accumulator kernel is checked too), then the
# coherent queries of a paper-size model of the default scene trained on this GPU with the CUDA backend.
# The 1080p frame figures of that run are superseded by results/perf/ (scripts/bench/ab_frames.sh).
set -u
source .device/env.sh
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
D=build-qps-dev/carry; BC=.devbin/nbvh_cuda
for q in random coherent; do
  extra=""; [ $q = coherent ] && extra="--coherent --model $D/default.nbvh"
  timeout 90 $D/bench_final --device gpu --queries 4194304 --reps 10 $extra --json $OUT/bench_neural_queries_${q}_h200.json 2>&1 | grep -v "coopmat shape"
done
rm -rf /tmp/f; mkdir -p /tmp/f
/usr/bin/time -f "train wall %e s" $BC train default --backend cuda --lods 5 -o /tmp/f/default_cuda.nbvh --log /tmp/f/train.csv 2>&1 | tail -4
$BC info /tmp/f/default_cuda.nbvh 2>&1 | head -12
timeout 90 $D/bench_final --device gpu --queries 4194304 --reps 10 --coherent --model /tmp/f/default_cuda.nbvh --json $OUT/bench_neural_queries_coherent_cudamodel_h200.json 2>&1 | grep -v "coopmat shape"
