#!/usr/bin/env bash
# Installs, builds and runs every test (CPU tests and GL tests on an OSMesa context), then the
# GPU-portability matrix (scripts/portability.sh: the exactness tests again on zink over lavapipe at
# 4 and 8 lanes and without ARB_shader_ballot; docs/portability.md). The ctest run is the matrix's
# cell a: the matrix reads its results from ctest's JUnit report instead of running those tests
# again, and runs the portability tests itself (so ctest leaves them out). Arguments go to ctest;
# with any (a selection of tests) ctest runs what they select and the matrix is not run.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
if [ $# -gt 0 ]; then
    (cd build && ctest --output-on-failure -j"$(nproc)" "$@")
    echo "test: a selection of tests was asked for; the portability matrix (scripts/portability.sh) is not run"
    exit 0
fi
junit="$PWD/build/Testing/ctest-junit.xml"
rm -f "$junit"
(cd build && ctest --output-on-failure -j"$(nproc)" -E 'Portability' --output-junit "$junit")
scripts/portability.sh --a-from-ctest "$junit"
