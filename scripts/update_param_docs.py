#!/usr/bin/env python3
"""Rewrites the parameter table of every docs/algorithms/NAME.md from the algorithm's schema.

The table sits between the two marker lines below; `shadowlab list --markdown NAME` prints it, and
tests/ParamDocsTest.cpp fails when a doc differs from its schema. Usage:
    scripts/update_param_docs.py [path/to/shadowlab]   (default: build/shadowlab)
"""
import pathlib
import subprocess
import sys

BEGIN = "<!-- parameters: generated from the schema by scripts/update_param_docs.py; do not edit -->"
END = "<!-- end of parameters -->"

root = pathlib.Path(__file__).resolve().parent.parent
binary = sys.argv[1] if len(sys.argv) > 1 else str(root / "build" / "shadowlab")
for doc in sorted((root / "docs" / "algorithms").glob("*.md")):
    name = doc.stem
    table = subprocess.run([binary, "list", "--markdown", name], capture_output=True, text=True)
    if table.returncode != 0:
        print(f"{doc}: skipped ({table.stderr.strip()})")
        continue
    text = doc.read_text()
    if BEGIN not in text or END not in text:
        sys.exit(f"{doc}: no parameter markers; add the two marker lines where the table goes")
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    doc.write_text(head + BEGIN + "\n" + table.stdout + END + tail)
    print(f"{doc}: updated")
