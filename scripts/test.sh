#!/usr/bin/env bash
# Installs, builds and runs the whole test suite (unit, lavapipe, slow; cuda tests skip without a GPU).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cd build
ctest --output-on-failure -j"$(nproc)" --timeout 900 "$@"
