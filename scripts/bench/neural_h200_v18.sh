#!/usr/bin/env bash
# As run for results/neural/ (moved from results/neural/gpu_run_*.sh; .devbin/ and build-qps-dev/ were that
# session's ignored folders of binaries: nbvh, nbvh_cuda (CUDA build), bench_final = nbvh_bench_neural).
# GPU session v18 (same day as v17): a ray whose queued group is its last (fewer leaves found than
# looked for, or leaf budget spent: NB_NRAY_PENDING_LAST) is finished by the resumed round without
# re-traversing. The v17 build (.devbin/nbvh_v17) and this build (.devbin/nbvh) in one run, default
# scene 1080p 4 spp, v14 CPU-trained model. Writes the JSON of this build's frames under $OUT.
set -u
source .device/env.sh
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
M=.devbin/default_lods5.nbvh; W="--width 1920 --height 1080 --spp 4 --device gpu"
rm -rf /tmp/f; mkdir -p /tmp/f
for b in nbvh_v17 nbvh nbvh_v17 nbvh; do B=.devbin/$b
  $B render default $W --classical --out /tmp/f/c_$b.png > /dev/null 2>&1
  echo "--- $b"; $B render default $W --classical --out /tmp/f/c_$b.png --stats /tmp/f/c_$b.json 2>&1 | tail -1
  for cfg in "4 0 4" "8 0 4"; do set -- $cfg
    $B render default $W --model $M --neural-max-leaves $1 --secondary-lod $3 --out /tmp/f/h_${b}_$1.png > /dev/null 2>&1
    $B render default $W --model $M --neural-max-leaves $1 --secondary-lod $3 --out /tmp/f/h_${b}_$1.png --stats /tmp/f/h_${b}_$1.json 2>&1 | tail -2
    python3 -c "import json;d=json.load(open('/tmp/f/h_${b}_$1.json'));p=d['pass_gpu_ms'];print('  max-leaves $1: traverse %.2f shadow %.2f query %.2f ms' % (p['passes/neural_traverse.comp'], p['passes/neural_shadow.comp'], p['passes/neural_query.comp']))"
  done
done
for n in 4 8; do echo "max-leaves $n, this build vs v17: $(.devbin/nbvh flip /tmp/f/h_nbvh_v17_$n.png /tmp/f/h_nbvh_$n.png); vs classical: $(.devbin/nbvh flip /tmp/f/c_nbvh.png /tmp/f/h_nbvh_$n.png)"; done
cp /tmp/f/c_nbvh.json $OUT/frame_1080p_default_classical_h200_v18.json
cp /tmp/f/h_nbvh_4.json $OUT/frame_1080p_default_lods5_h_4_0_4_h200_v18.json
cp /tmp/f/h_nbvh_8.json $OUT/frame_1080p_default_lods5_h_8_0_4_h200_v18.json
