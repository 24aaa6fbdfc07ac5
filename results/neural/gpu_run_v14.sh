set -e
source .device/env.sh
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
B=.devbin/nbvh; M=.devbin/default_lods5.nbvh; W="--width 1920 --height 1080 --spp 4 --device gpu --wave-pixels 2097152"
rm -rf /tmp/img2; mkdir -p /tmp/img2
$B render default $W --classical --out /tmp/img2/c.png --stats /tmp/img2/classical.json 2>&1 | tail -1
$B render default $W --classical --out /tmp/img2/c.png --stats /tmp/img2/classical.json 2>&1 | tail -1
for cfg in "4 0 0" "4 0 3" "4 0 4" "8 0 4" "3 0 4"; do set -- $cfg
  $B render default $W --model $M --neural-max-leaves $1 --lod $2 --secondary-lod $3 --out /tmp/img2/h_$1_$2_$3.png --stats /tmp/img2/h_$1_$2_$3.json 2>&1 | tail -2
  echo "max-leaves $1 lod $2 secondary-lod $3: $($B flip /tmp/img2/c.png /tmp/img2/h_$1_$2_$3.png)"
done
python3 - <<'PY'
import json,glob,os
c=json.load(open('/tmp/img2/classical.json'))['gpu_total_ms']
for f in sorted(glob.glob('/tmp/img2/h_*.json')):
    d=json.load(open(f)); print(os.path.basename(f), round(d['gpu_total_ms'],2), 'ms', round(d['gpu_total_ms']/c,3), 'x classical', round(c,2))
PY
cp /tmp/img2/classical.json $OUT/frame_1080p_default_classical_h200_v14.json
for f in /tmp/img2/h_*.json; do cp $f $OUT/frame_1080p_default_lods5_$(basename $f .json)_h200_v14.json; done
cp /tmp/img2/h_4_0_4.png $OUT/hybrid_lods5_m4_sec4_1080p.png
