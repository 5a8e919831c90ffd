#!/usr/bin/env bash
# Installs, builds and runs every test (CPU tests and GL tests on an OSMesa context).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
cd build
ctest --output-on-failure -j"$(nproc)" "$@"
