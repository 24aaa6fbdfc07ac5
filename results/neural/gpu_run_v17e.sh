#!/usr/bin/env bash
# GPU session v17, run 5: weight tiles + paired (p) or unpaired (u) gather with 1, 2 or 4 levels
# fetched at once (8 * G loads in flight); then the 1080p hybrid frame of candidate builds vs v16.
set -u
D=build-qps-dev/carry
source .device/env.sh
export NBVH_PIPELINE_STATS=1
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
for v in p1 p2 p4 u1 u2 u4; do
  echo "=== variant $v"
  timeout 60 $D/bench_$v --device gpu --queries 4194304 --reps 10 --json $OUT/bench_random_$v.json 2>&1 | grep -v "coopmat shape" | grep -i "cooperative matrix\|breakdown\|scalar vs\|error\|coop32.*Register" | sort -u
  timeout 60 $D/bench_$v --device gpu --queries 4194304 --reps 10 --coherent --model $D/default.nbvh --json $OUT/bench_coherent_$v.json 2>&1 | grep -v "coopmat shape" | grep -i "cooperative matrix\|breakdown\|scalar vs\|error"
done
rm -f $OUT/bench_*_p1.json $OUT/bench_*_u1.json
unset NBVH_PIPELINE_STATS
M=.devbin/default_lods5.nbvh; W="--width 1920 --height 1080 --spp 4 --device gpu"
rm -rf /tmp/f; mkdir -p /tmp/f
B=.devbin/nbvh_v16
$B render default $W --classical --out /tmp/f/c.png > /dev/null 2>&1
$B render default $W --classical --out /tmp/f/c.png 2>&1 | tail -1
for b in v16 ppt p2 p4 u4; do B=.devbin/nbvh_$b
  $B render default $W --model $M --neural-max-leaves 4 --secondary-lod 4 --out /tmp/f/h_$b.png > /dev/null 2>&1
  echo "--- $b"; $B render default $W --model $M --neural-max-leaves 4 --secondary-lod 4 --out /tmp/f/h_$b.png 2>&1 | tail -2
  echo "$b hybrid vs classical: $($B flip /tmp/f/c.png /tmp/f/h_$b.png), vs v16: $($B flip /tmp/f/h_v16.png /tmp/f/h_$b.png)"
done
