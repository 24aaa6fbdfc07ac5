#!/bin/sh
# What each scene's specialization saves (issue 12), on the GPU machine in one run:
#   nbvh bench-features over the default scene and ../shared/scenes (results/render/features.*).
# Prepare on the build machine (FOLDER ignored, e.g. .device/feat; carry FOLDER, .gl, .device/env.sh,
# .device/lib; the whole carry + tree must stay under 64 MiB, hence xz):
#   strip -o FOLDER/nbvh BUILD/app/nbvh && ../shared/device/prepare.sh FOLDER/nbvh && xz -f FOLDER/nbvh
#   for s in stanford_bunny stanford_dragon flight_helmet sheen_cloth smithsonian_usnm1145291 balloon \
#            abeautifulgame; do (cd ../shared/scenes && tar cf - $s) | xz > FOLDER/scenes/$s.tar.xz; done
# Run: source .device/env.sh && scripts/bench/bench_features.sh FOLDER   (writes into $OUT)
# Settings: 1920x1080, 4 spp, max depth 8 (the frame figures of results/), median of 9 frames.
set -eu
DIR=${1:?usage: bench_features.sh FOLDER}
OUT=${OUT:?OUT must name the output folder}
TMP=$(mktemp -d)
unpack() { # SRC.xz: to stdout with xz, else Python's lzma
  if command -v xz >/dev/null; then xz -dc "$1"
  else python3 -c 'import lzma, shutil, sys; shutil.copyfileobj(lzma.open(sys.argv[1]), sys.stdout.buffer)' "$1"; fi
}
unpack "$DIR/nbvh.xz" > "$TMP/nbvh" && chmod +x "$TMP/nbvh"
for f in "$DIR"/scenes/*.tar.xz; do unpack "$f" | tar x -C "$TMP"; done
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv,noheader || true
S="$TMP"
"$TMP/nbvh" bench-features default "$S/stanford_bunny/stanford_bunny.glb" "$S/stanford_dragon/dragon_vrip.glb" \
  "$S/flight_helmet/FlightHelmet.gltf" "$S/sheen_cloth/SheenCloth.gltf" \
  "$S/smithsonian_usnm1145291/usnm_1145291.glb" "$S/balloon/scene.gltf" \
  "$S/abeautifulgame/abeautifulgame.glb" \
  --device gpu --width 1920 --height 1080 --spp 4 --max-depth 8 --repeat 9 \
  --json "$OUT/features.json" --markdown "$OUT/features.md" 2>&1 | tee "$OUT/log.txt"
