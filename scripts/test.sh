#!/usr/bin/env bash
# README command (2): build everything, then run the whole test suite with ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
cd "${FROSTMPM_BUILD_DIR:-build}"
ctest --output-on-failure -j "$(nproc)" --timeout 900
