#!/usr/bin/env bash
# GPU session v17, run 7 (after the final run): final kernel vs G = 8 levels at once (g8) and vs the
# grid buffer declared `restrict` (r4). Prints figures only.
set -u
D=build-qps-dev/carry
source .device/env.sh
export NBVH_PIPELINE_STATS=1
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
for v in final g8 r4; do
  echo "=== variant $v"
  timeout 60 $D/bench_$v --device gpu --queries 4194304 --reps 10 2>&1 | grep -i "fp32 (fused\|breakdown\|scalar vs coopmat:\|error\|coop32.*Register" | sort -u
  timeout 60 $D/bench_$v --device gpu --queries 4194304 --reps 10 --coherent --model $D/default.nbvh 2>&1 | grep -i "fp32 (fused\|breakdown\|scalar vs coopmat:\|error"
done
