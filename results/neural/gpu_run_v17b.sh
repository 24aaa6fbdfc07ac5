#!/usr/bin/env bash
# GPU session v17, run 2: head (= v16 kernel), pp (paired gather + 64-bit staging, run 1), m (head +
# division-free index modulo in shared/hashgrid.h), um (m + 64-bit staging, unpaired gather),
# pm (pp + division-free modulo). Only 8 files come back: JSON of the last 4 variants.
set -u
D=build-qps-dev/carry
source .device/env.sh
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
for v in head pp m um pm; do
  echo "=== variant $v"
  timeout 60 $D/bench_$v --device gpu --queries 4194304 --reps 10 --json $OUT/bench_random_$v.json 2>&1 | grep -v "coopmat shape" | grep -i "G queries\|breakdown\|scalar vs\|error"
  timeout 60 $D/bench_$v --device gpu --queries 4194304 --reps 10 --coherent --model $D/default.nbvh --json $OUT/bench_coherent_$v.json 2>&1 | grep -v "coopmat shape" | grep -i "G queries\|breakdown\|scalar vs\|error"
done
rm -f $OUT/bench_*_head.json
