#!/usr/bin/env bash
# Shared by the GPU-machine bench scripts (sourced): unpacking carried inputs and the three bench scenes.

unpack() { # SRC.xz DST: xz, else Python's lzma (the GPU machine may have either)
  if command -v xz >/dev/null; then xz -dc "$1" > "$2"
  else python3 -c 'import lzma, shutil, sys; shutil.copyfileobj(lzma.open(sys.argv[1]), open(sys.argv[2], "wb"))' "$1" "$2"; fi
}

# bench_setup OUT NAME: sets B (the binary: NBVH, default .device/study/bin/nbvh) and T (a scratch folder,
# TMPDIR/nbvh_NAME), creates both folders and writes OUT/device.txt (the GPU and driver, also printed).
bench_setup() {
  B=${NBVH:-.device/study/bin/nbvh}
  T=${TMPDIR:-/tmp}/nbvh_$2
  mkdir -p "$1" "$T"
  (nvidia-smi --query-gpu=name,driver_version --format=csv,noheader || echo "no nvidia-smi") | tee "$1/device.txt"
}

# bench_scene NAME TMP: sets SRC (the scene), NEURAL (its neural-node flags: for training and for the
# classical render) and VIEW (render-only flags: camera, environment, exposure) for default, dragon (every
# mesh neural) or chess (the paper's camera and environment, scripts/bench/chess.sh), unpacking a carried
# scene into TMP once. Train: `nbvh train "${SRC[@]}" "${NEURAL[@]}"`; classical render: `nbvh render
# "${SRC[@]}" "${NEURAL[@]}" --classical "${VIEW[@]}"`; hybrid: `nbvh render "${SRC[@]}" --model M "${VIEW[@]}"`.
bench_scene() {
  NEURAL=(); VIEW=()
  case "$1" in
    default) SRC=(default) ;;
    dragon)
      [ -f "$2/dragon.glb" ] || unpack "${DRAGON:-.device/study/dragon/dragon_vrip.glb.xz}" "$2/dragon.glb"
      SRC=("$2/dragon.glb"); NEURAL=(--neural '*') ;;
    chess)
      [ -f "$2/chess.glb" ] || unpack .device/study/chess/abeautifulgame.glb.xz "$2/chess.glb"
      SRC=("$2/chess.glb")
      VIEW=(--camera 0.600,0.358,0.179,-0.197,-0.197,-0.057,45
            --env .device/study/chess/photo_studio_loft_hall_512x256.hdr --env-rotation 285) ;;
    *) echo "bench_scene: scene must be default, dragon or chess, not '$1'" >&2; return 2 ;;
  esac
}
