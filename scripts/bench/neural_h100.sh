#!/usr/bin/env bash
# The run behind results/neural/'s H100 query figures (code c6db4f5; build-qps-dev/ was that session's
# ignored folder of binaries: bench_final = nbvh_bench_neural): random and coherent queries, as on the
# H200 (neural_h200.sh). The 1080p frame figures of that run are superseded by results/perf/.
set -u
source .device/env.sh
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
D=build-qps-dev/carry
timeout 90 $D/bench_final --device gpu --queries 4194304 --reps 10 --json $OUT/bench_neural_queries_random_h100.json 2>&1 | grep -v "coopmat shape"
timeout 90 $D/bench_final --device gpu --queries 4194304 --reps 10 --coherent --model $D/default.nbvh --json $OUT/bench_neural_queries_coherent_h100.json 2>&1 | grep -v "coopmat shape"
