#!/usr/bin/env bash
# What each scene's specialization saves (issue 12), on the GPU machine in one run:
#   nbvh bench-features over the default scene and ../shared/scenes (results/render/features.*).
# Prepare on the build machine (FOLDER ignored, e.g. .device/feat; carry FOLDER, .gl, .device/env.sh,
# .device/lib; the whole carry + tree must stay under 64 MiB, hence xz):
#   strip -o FOLDER/nbvh BUILD/app/nbvh && ../shared/device/prepare.sh FOLDER/nbvh && xz -f FOLDER/nbvh
#   for s in stanford_bunny stanford_dragon flight_helmet sheen_cloth smithsonian_usnm1145291 balloon \
#            abeautifulgame; do (cd ../shared/scenes && tar cf - $s) | xz > FOLDER/scenes/$s.tar.xz; done
# Run: source .device/env.sh && scripts/bench/bench_features.sh FOLDER   (writes into $OUT)
# Settings: 1920x1080, 4 spp, max depth 8 (the frame figures of results/), median of 9 frames.
set -euo pipefail
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
# The scenes whose packs came along (a run may leave one out to keep the carry under 64 MiB).
SCENES=(default)
for f in stanford_bunny/stanford_bunny.glb stanford_dragon/dragon_vrip.glb flight_helmet/FlightHelmet.gltf \
         sheen_cloth/SheenCloth.gltf smithsonian_usnm1145291/usnm_1145291.glb balloon/scene.gltf \
         abeautifulgame/abeautifulgame.glb; do
  if [ -f "$S/$f" ]; then SCENES+=("$S/$f"); else echo "bench_features.sh: $f not packed, left out"; fi
done
"$TMP/nbvh" bench-features "${SCENES[@]}" \
  --device gpu --width 1920 --height 1080 --spp 4 --max-depth 8 --repeat 9 \
  --json "$OUT/features.json" --markdown "$OUT/features.md" 2>&1 | tee "$OUT/log.txt"
