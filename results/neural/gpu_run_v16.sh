set -e
source .device/env.sh
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
B=.devbin/nbvh; M=.devbin/default_lods5.nbvh; W="--width 1920 --height 1080 --spp 4 --device gpu"
rm -rf /tmp/f; mkdir -p /tmp/f
$B render default $W --classical --out /tmp/f/c.png > /dev/null 2>&1
$B render default $W --classical --out /tmp/f/c.png --stats $OUT/frame_1080p_default_classical_h200_v16.json 2>&1 | tail -1
for cfg in "4 0 0" "4 0 4"; do set -- $cfg
  $B render default $W --model $M --neural-max-leaves $1 --lod $2 --secondary-lod $3 --out /tmp/f/h_$1_$2_$3.png --stats $OUT/frame_1080p_default_lods5_h_$1_$2_$3_h200_v16.json 2>&1 | tail -2
  echo "max-leaves $1 lod $2 secondary-lod $3: $($B flip /tmp/f/c.png /tmp/f/h_$1_$2_$3.png)"
done
$B render default $W --model $M --neural-max-leaves 4 --secondary-lod 4 --neural-path scalar --out /tmp/f/s.png 2>&1 | tail -1
echo "scalar vs coopmat: $($B flip /tmp/f/h_4_0_4.png /tmp/f/s.png)"
$B bench default --model $M --device gpu --spp 4 --repeat 3 --json $OUT/bench_default_lods5_h200_v16.json 2>&1 | tail -12
