#!/usr/bin/env bash
# GPU session v17 (issue 4): paired-lane hash-grid gather. One stripped nbvh_bench_neural per variant
# under build-qps-dev/carry: head (= v16 kernel), p (paired gather), pp (paired + 64-bit staging
# stores + output stride 20), pp4 (pp with 4 loads in flight instead of 8); then the 1080p hybrid frame
# with the pp build (.devbin/nbvh) and the v16 build (.devbin/nbvh_v16) in the same run.
set -u
D=build-qps-dev/carry
source .device/env.sh
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
for v in head p pp pp4; do
  echo "=== variant $v"
  timeout 60 $D/bench_$v --device gpu --queries 4194304 --reps 10 --json $OUT/bench_random_$v.json 2>&1 | grep -v "coopmat shape" | grep -i "G queries\|breakdown\|scalar vs\|error"
  timeout 60 $D/bench_$v --device gpu --queries 4194304 --reps 10 --coherent --model $D/default.nbvh --json $OUT/bench_coherent_$v.json 2>&1 | grep -v "coopmat shape" | grep -i "G queries\|breakdown\|scalar vs\|error"
done
M=.devbin/default_lods5.nbvh; W="--width 1920 --height 1080 --spp 4 --device gpu"
rm -rf /tmp/f; mkdir -p /tmp/f
for b in nbvh nbvh_v16; do B=.devbin/$b
  $B render default $W --classical --out /tmp/f/c_$b.png > /dev/null 2>&1
  $B render default $W --classical --out /tmp/f/c_$b.png --stats /tmp/f/c_$b.json 2>&1 | tail -1
  $B render default $W --model $M --neural-max-leaves 4 --secondary-lod 4 --out /tmp/f/h_$b.png > /dev/null 2>&1
  $B render default $W --model $M --neural-max-leaves 4 --secondary-lod 4 --out /tmp/f/h_$b.png --stats /tmp/f/h_$b.json 2>&1 | tail -2
  echo "$b hybrid vs classical: $($B flip /tmp/f/c_$b.png /tmp/f/h_$b.png)"
done
echo "hybrid new vs v16: $(.devbin/nbvh flip /tmp/f/h_nbvh.png /tmp/f/h_nbvh_v16.png)"
cp /tmp/f/h_nbvh.json $OUT/frame_1080p_default_lods5_h_4_0_4_h200_v17.json
cp /tmp/f/c_nbvh.json $OUT/frame_1080p_default_classical_h200_v17.json
