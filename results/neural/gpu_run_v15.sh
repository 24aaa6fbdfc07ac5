#!/usr/bin/env bash
# GPU session v15 (issue 4, fused coopmat kernel; one stripped nbvh_bench_neural per variant under
# build-qps-dev/carry, default.nbvh = the v10 model). Run 1 printed variants base (= v10 kernel g),
# s, s2, s4, s8, b4 (same loop with `for v in base s s2 s4 s8 b4`; s8 = the committed kernel); this is
# run 2: base, v15 (= s8 as straight-line code, slower; files renamed *_straight_*), g128 / g32 (= that
# built with NB_NEURAL_GROUP 128 / 32). See results/neural/README.md v15. Writes JSON under $OUT.
set -u
D=build-qps-dev/carry
source .device/env.sh
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
for v in base v15 g128 g32; do
  echo "=== variant $v"
  timeout 60 $D/bench_$v --device gpu --queries 4194304 --reps 10 --json $OUT/bench_random_$v.json 2>&1 | grep -v "coopmat shape" | grep -i "G queries\|breakdown\|scalar vs\|error"
  timeout 60 $D/bench_$v --device gpu --queries 4194304 --reps 10 --coherent --model $D/default.nbvh --json $OUT/bench_coherent_$v.json 2>&1 | grep -v "coopmat shape" | grep -i "G queries\|breakdown\|scalar vs\|error"
done
