#!/usr/bin/env python3
"""Writes the portability matrix's report (scripts/portability.sh): the cells, what each context
was, and the table cell x algorithm x light x variant (worst mismatch over the shots, overflow,
frame time), then what differs between the cells.

Usage: portability_report.py WORK OUT.md OUT.csv TOTAL_SECONDS CELL...
WORK/CELL/ holds label, env, context, counts, seconds, status and table.csv (PortabilityGLTest's rows).
"""
import csv
import datetime
import os
import platform
import subprocess
import sys


def read(path, default=""):
    try:
        with open(path, encoding="utf-8") as f:
            return f.read().strip()
    except OSError:
        return default


def context_fields(line):
    """'[portability-context] cell=a; backend=OSMesa; ...; renderer=...' -> dict (renderer is last)."""
    out = {}
    body = line.split("]", 1)[1].strip() if "]" in line else ""
    head, sep, renderer = body.partition("; renderer=")
    for part in head.split("; "):
        k, _, v = part.partition("=")
        if k:
            out[k.strip()] = v.strip()
    if sep:
        out["renderer"] = renderer.strip()
    return out


def md(text):
    return str(text).replace("|", "\\|")


def main():
    work, out_md, out_csv, total = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4]
    cells = sys.argv[5:]
    info, rows = {}, []
    for c in cells:
        d = os.path.join(work, c)
        status = read(os.path.join(d, "status"), "failed\nnot run").split("\n")
        counts = read(os.path.join(d, "counts")).split()
        info[c] = {
            "label": read(os.path.join(d, "label"), c),
            "env": read(os.path.join(d, "env")).split("\n"),
            "context": context_fields(read(os.path.join(d, "context"))),
            "counts": counts,
            "seconds": read(os.path.join(d, "seconds"), "?"),
            "verdict": status[0],
            "why": status[1] if len(status) > 1 else "",
            "from_ctest": read(os.path.join(d, "from-ctest")),
        }
        path = os.path.join(d, "table.csv")
        if os.path.exists(path):
            with open(path, encoding="utf-8", newline="") as f:
                rows += list(csv.DictReader(f))

    fields = ["cell", "algorithm", "light", "variant", "scene", "outcome", "path", "lit_pixels", "mismatched_pixels",
              "mismatch", "overflow", "frame_ms", "case_ms"]
    os.makedirs(os.path.dirname(out_md) or ".", exist_ok=True)
    with open(out_csv, "w", encoding="utf-8", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)

    # One table row per algorithm x light x variant, in the order the cases ran; per cell the worst
    # over the shots.
    keys, seen = [], set()
    for r in rows:
        k = (r["algorithm"], r["light"], r["variant"])
        if k not in seen:
            seen.add(k)
            keys.append(k)
    by = {}
    for r in rows:
        by.setdefault((r["algorithm"], r["light"], r["variant"], r["cell"]), []).append(r)

    def summary(k, c):
        rs = by.get(k + (c,), [])
        if not rs:
            return "—", None, ""
        if all(r["outcome"] == "refused" for r in rs):
            return "refused", None, "refused"
        ran = [r for r in rs if r["outcome"] != "refused"]
        worst = max(ran, key=lambda r: (int(r["mismatched_pixels"] or 0), float(r["mismatch"] or 0)))
        overflow = max(int(r["overflow"] or 0) for r in ran)
        ms = sum(float(r["frame_ms"] or 0) for r in ran) / len(ran)
        bad = any(r["outcome"] != "exact" for r in ran)
        text = "%s%s px, %s, %.1f ms" % ("**FAIL** " if bad else "", worst["mismatched_pixels"], overflow, ms)
        paths = sorted({r["path"] for r in ran if r["path"]})
        return text, (int(worst["mismatched_pixels"]), overflow), "; ".join(paths)

    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], capture_output=True,
                               text=True).stdout.strip()
        commit += " (with uncommitted changes)" if dirty else ""
    except OSError:
        commit = "?"
    cpu = ""
    for line in read("/proc/cpuinfo").split("\n"):
        if line.startswith("model name"):
            cpu = line.split(":", 1)[1].strip()
            break

    L = []
    L.append("# GPU-portability matrix")
    L.append("")
    L.append("- date: %s UTC, commit %s" % (datetime.datetime.utcnow().strftime("%Y-%m-%d %H:%M"), commit))
    L.append("- machine: %s, %d CPU threads, %s" % (cpu or platform.machine(), os.cpu_count() or 0, platform.platform()))
    L.append("- wall time: %s s for %d cells (scripts/portability.sh; what each cell is and proves: docs/portability.md)"
             % (total, len(cells)))
    L.append("")
    L.append("## Cells")
    L.append("")
    L.append("| cell | implementation | GL_RENDERER | GL_VERSION | back end | subgroup | ballot | tests passed / listed | wall s | verdict |")
    L.append("|---|---|---|---|---|---:|---:|---:|---:|---|")
    for c in cells:
        i, ctx = info[c], info[c]["context"]
        n = i["counts"]
        tests = "%s / %s" % (n[2], n[0]) if len(n) >= 3 else "—"
        verdict = i["verdict"] + (": " + i["why"] if i["why"] else "")
        if i["from_ctest"]:
            verdict += " (its suites' results read from the ctest run just before, %s)" % os.path.basename(i["from_ctest"])
        L.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            c, md(i["label"]), md(ctx.get("renderer", "—")), md(ctx.get("version", "—")), ctx.get("backend", "—"),
            ctx.get("subgroup", "—"), ctx.get("ballot", "—"), tests, i["seconds"], md(verdict)))
    L.append("")
    L.append("Environments (each cell also has a private `XDG_RUNTIME_DIR` and an empty private Mesa shader cache):")
    L.append("")
    for c in cells:
        env = [e for e in info[c]["env"] if e.startswith(("LIBGL", "MESA_LOADER", "LP_", "MESA_EXTENSION"))]
        L.append("- %s: `%s`" % (c, " ".join(env) if env else "(none)"))
    L.append("")
    L.append("## Portability table")
    L.append("")
    L.append("PortabilityGLTest at 48², on the shots `intersecting_triangles` and `thousands_of_triangles`: per cell the "
             "worst mismatched lit pixels of the two (bound: 1e-4 of the lit pixels, i.e. none), the overflow, and the "
             "measured frame's time (mean of the two; CPU rasterisers, so only a rough cost). *refused*: the algorithm "
             "refused the path, as the test requires without ARB_shader_ballot.")
    L.append("")
    L.append("| algorithm | light | variant | " + " | ".join(cells) + " |")
    L.append("|---|---|---|" + "---|" * len(cells))
    differing = []
    for k in keys:
        cols, values, paths = [], set(), {}
        for c in cells:
            text, value, path = summary(k, c)
            cols.append(text)
            if value is not None:
                values.add(value)
            paths[c] = path
        L.append("| %s | %s | %s | %s |" % (k[0], k[1], k[2], " | ".join(md(x) for x in cols)))
        if len(set(paths.values()) - {""}) > 1 or len(values) > 1:
            differing.append((k, paths, cols))
    L.append("")
    L.append("## What differs between the cells")
    L.append("")
    if not differing:
        L.append("Nothing: every cell took the same paths and gave the same counts.")
    else:
        L.append("Cases whose path (as the algorithm reports it) or result is not the same in every cell:")
        L.append("")
        L.append("| algorithm | light | variant | " + " | ".join(cells) + " |")
        L.append("|---|---|---|" + "---|" * len(cells))
        for k, paths, cols in differing:
            L.append("| %s | %s | %s | %s |" % (k[0], k[1], k[2], " | ".join(
                md(paths[c] or cols[i]) for i, c in enumerate(cells))))
    L.append("")
    with open(out_md, "w", encoding="utf-8") as f:
        f.write("\n".join(L))


if __name__ == "__main__":
    main()
