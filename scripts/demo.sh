#!/usr/bin/env bash
# The main job: install, build, then run the default experiment headless on OSMesa.
# Extra arguments go to `shadowlab run` (e.g. --out DIR).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
exec build/shadowlab run configs/demo.json --force "$@"
