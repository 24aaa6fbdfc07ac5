set -e
source .device/env.sh
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | tee $OUT/lod_run.txt
B=.devbin/nbvh; M=.devbin/default_lods3.nbvh; W="--width 1920 --height 1080 --spp 4 --device gpu --wave-pixels 2097152"
mkdir -p /tmp/img
$B render default $W --classical --out /tmp/img/c.png --stats /tmp/img/classical.json 2>&1 | tail -1
$B render default $W --classical --out /tmp/img/c.png --stats /tmp/img/classical.json 2>&1 | tail -1 | tee -a $OUT/lod_run.txt
for cfg in "8 0 0" "8 0 2" "4 0 0" "4 0 2" "4 0 1"; do set -- $cfg
  $B render default $W --model $M --neural-max-leaves $1 --lod $2 --secondary-lod $3 --out /tmp/img/h_$1_$2_$3.png --stats /tmp/img/h_$1_$2_$3.json 2>&1 | tail -2 | tee -a $OUT/lod_run.txt
  echo "max-leaves $1 lod $2 secondary-lod $3: $($B flip /tmp/img/c.png /tmp/img/h_$1_$2_$3.png)" | tee -a $OUT/lod_run.txt
done
python3 - <<'PY' | tee -a $OUT/lod_run.txt
import json,glob,os
c=json.load(open('/tmp/img/classical.json'))['gpu_total_ms']
for f in sorted(glob.glob('/tmp/img/h_*.json')):
    d=json.load(open(f)); print(os.path.basename(f), round(d['gpu_total_ms'],2), 'ms', round(d['gpu_total_ms']/c,3), 'x classical', c)
PY
cp /tmp/img/classical.json $OUT/frame_1080p_default_classical_h200_v13.json
for f in /tmp/img/h_*.json; do cp $f $OUT/frame_1080p_default_lods3_$(basename $f .json)_h200_v13.json; done
cp /tmp/img/h_8_0_2.png $OUT/hybrid_lod0_secondary2_1080p.png
