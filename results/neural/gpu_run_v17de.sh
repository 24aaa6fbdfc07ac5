#!/usr/bin/env bash
# GPU session v17, runs 4 and 5: bench variants (build-qps-dev/carry/bench_<v>) and candidate nbvh
# builds (.devbin/nbvh_<b>) in one run; prints figures and keeps the benches' JSON except DROP's (only
# 8 files come back).
#   run 4: VARIANTS="ppt ut ph1 ph2 uh1 uh2" DROP="ph1 uh1" BUILDS="v16 ppt ut ph2 uh2 v16": weight tiles (t) with the
#          paired (p) or unpaired (u) gather, and the MLP on 16 rows at a time (h1: layer loop, h2:
#          straight-line) to cut registers;
#   run 5: VARIANTS="p1 p2 p4 u1 u2 u4" DROP="p1 u1" BUILDS="v16 ppt p2 p4 u4": paired / unpaired gather with tiles
#          and 1, 2 or 4 levels fetched at once (8 * G loads in flight).
set -u
D=build-qps-dev/carry
source .device/env.sh
export NBVH_PIPELINE_STATS=1
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
for v in $VARIANTS; do
  echo "=== variant $v"
  timeout 60 $D/bench_$v --device gpu --queries 4194304 --reps 10 --json $OUT/bench_random_$v.json 2>&1 | grep -v "coopmat shape" | grep -i "cooperative matrix\|breakdown\|scalar vs\|error\|coop32.*Register" | sort -u
  timeout 60 $D/bench_$v --device gpu --queries 4194304 --reps 10 --coherent --model $D/default.nbvh --json $OUT/bench_coherent_$v.json 2>&1 | grep -v "coopmat shape" | grep -i "cooperative matrix\|breakdown\|scalar vs\|error"
done
for v in $DROP; do rm -f $OUT/bench_*_$v.json; done
unset NBVH_PIPELINE_STATS
M=.devbin/default_lods5.nbvh; W="--width 1920 --height 1080 --spp 4 --device gpu"
rm -rf /tmp/f; mkdir -p /tmp/f
B=.devbin/nbvh_v16
$B render default $W --classical --out /tmp/f/c.png > /dev/null 2>&1
$B render default $W --classical --out /tmp/f/c.png 2>&1 | tail -1
for b in $BUILDS; do B=.devbin/nbvh_$b
  $B render default $W --model $M --neural-max-leaves 4 --secondary-lod 4 --out /tmp/f/h_$b.png > /dev/null 2>&1
  echo "--- $b"; $B render default $W --model $M --neural-max-leaves 4 --secondary-lod 4 --out /tmp/f/h_$b.png 2>&1 | tail -2
  echo "$b hybrid vs classical: $($B flip /tmp/f/c.png /tmp/f/h_$b.png), vs v16: $($B flip /tmp/f/h_v16.png /tmp/f/h_$b.png)"
done
