#!/usr/bin/env python3
"""Rewrites the parameter table of every docs/algorithms/NAME.md from the algorithm's schema.

The table sits between two marker lines; `shadowlab list --markdown NAME` prints it, and
tests/ParamDocsTest.cpp fails when a doc differs from its schema. The rewrite is that test run
with SHADOWLAB_UPDATE_DOCS=1 (it also covers the template plugin, which only the tests register).
Usage: scripts/update_param_docs.py [BUILD_DIR]   (default: build)
"""
import os
import pathlib
import subprocess
import sys

root = pathlib.Path(__file__).resolve().parent.parent
build = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else root / "build"
env = dict(os.environ, SHADOWLAB_UPDATE_DOCS="1")
run = subprocess.run([str(build / "tests" / "shadowlab_tests"), "--gtest_filter=ParamDocsTest.*"], env=env,
                     capture_output=True, text=True)
if run.returncode != 0:
    sys.exit(run.stdout + run.stderr)
print("docs/algorithms/*.md: parameter tables rewritten from the schemas")
