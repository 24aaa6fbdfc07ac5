#!/usr/bin/env bash
# GPU session v19: fewer registers for the fused kernel's MLP by keeping the K-tile loop of each layer
# a loop ([[dont_unroll]]; the 8 accumulators stay statically indexed): k4 / k2 = that with 4 / 2 levels
# gathered at once; base = the v17/v18 kernel. Prints figures (pipeline statistics included).
set -u
D=build-qps-dev/carry
source .device/env.sh
export NBVH_PIPELINE_STATS=1
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
for v in ${VARIANTS:-base k4 k2}; do
  echo "=== variant $v"
  timeout 60 $D/bench_$v --device gpu --queries 4194304 --reps 10 2>&1 | grep -i "fp32 (fused\|breakdown\|scalar vs coopmat:\|error\|coop32.*Register" | sort -u
  timeout 60 $D/bench_$v --device gpu --queries 4194304 --reps 10 --coherent --model $D/default.nbvh 2>&1 | grep -i "fp32 (fused\|breakdown\|scalar vs coopmat:\|error"
done
