#!/usr/bin/env bash
# GPU session v17, run 3: head (= v16 kernel), pp (paired gather + 64-bit staging), ppt (pp + 16x16
# weight tiles stored contiguously), ut (ppt with the unpaired 8-load gather). Every binary prints the
# driver's pipeline statistics (NBVH_PIPELINE_STATS=1) of the kernels it creates.
set -u
D=build-qps-dev/carry
source .device/env.sh
export NBVH_PIPELINE_STATS=1
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
for v in head pp ppt ut; do
  echo "=== variant $v"
  timeout 60 $D/bench_$v --device gpu --queries 4194304 --reps 10 --json $OUT/bench_random_$v.json 2>&1 | grep -v "coopmat shape" | grep -i "G queries\|breakdown\|scalar vs\|error\|statistics" | sort -u
  timeout 60 $D/bench_$v --device gpu --queries 4194304 --reps 10 --coherent --model $D/default.nbvh --json $OUT/bench_coherent_$v.json 2>&1 | grep -v "coopmat shape" | grep -i "G queries\|breakdown\|scalar vs\|error"
done
