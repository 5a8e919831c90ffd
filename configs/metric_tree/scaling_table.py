#!/usr/bin/python3
"""Tabulates and plots a metric_tree scaling study: one `shadowlab run` output folder per scene size.

For each folder (summary.json), prints the paper's Table 1 columns for metric_tree (clusters,
capsule %, tree build, traversal, total), psv's build / traversal / total, the reference's total,
the psv / metric_tree total-time ratio and accuracy, as a Markdown table; writes a log-log plot of
total frame time against the triangle count (matplotlib, Debian's python3-matplotlib).

Usage: scaling_table.py --plot OUT.png DIR [DIR ...]
"""
import argparse
import json
import os
import sys


def stage(a, name):
    t = a.get("time_ms", {}).get(name)
    return t["mean"] if t else float("nan")


def counter(a, name):
    c = a.get("counters", {}).get(name)
    return c["mean"] if c else float("nan")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--plot", help="PNG to write")
    ap.add_argument("--title", default="metric_tree scaling")
    ap.add_argument("dirs", nargs="+")
    args = ap.parse_args()
    rows = []
    for d in args.dirs:
        path = os.path.join(d, "summary.json")
        if not os.path.exists(path):
            print(f"scaling_table: no {path}; skipped", file=sys.stderr)
            continue
        s = json.load(open(path))
        rows.append((s["triangles"], os.path.basename(os.path.normpath(d)), s))
    rows.sort(key=lambda r: r[0])
    print("| scene | triangles | clusters | capsules | tris/cluster | MT build | MT traverse | MT total | "
          "PSV build | PSV traverse | PSV total | reference total | PSV / MT | MT mismatch (worst) | MT overflow | MT bytes/cluster |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    series = {"metric_tree": [], "psv": [], "reference": []}
    for n, name, s in rows:
        algos = s["algorithms"]
        mt = algos.get("metric_tree", {})
        psv = algos.get("psv", {})
        ref = algos.get("reference", {})
        mtTotal, psvTotal = stage(mt, "total"), stage(psv, "total")
        worst = max(mt.get("accuracy", {}).get("per_frame_mismatch", [float("nan")]))
        print(f"| {name} | {n:,} | {counter(mt, 'clusters'):,.0f} | {counter(mt, 'capsule_percent'):.1f} % | "
              f"{counter(mt, 'triangles_per_cluster'):.1f} | {stage(mt, 'build'):.1f} | {stage(mt, 'traverse'):.1f} | "
              f"{mtTotal:.1f} | {stage(psv, 'build'):.1f} | {stage(psv, 'traverse'):.1f} | {psvTotal:.1f} | "
              f"{stage(ref, 'total'):.1f} | {psvTotal / mtTotal:.2f} | {100 * worst:.4f} % | {mt.get('overflow', 'n/a')} | "
              f"{counter(mt, 'bytes_per_cluster'):.0f} |")
        for key, a in (("metric_tree", mt), ("psv", psv), ("reference", ref)):
            if a and "time_ms" in a:
                series[key].append((n, stage(a, "total")))
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 4))
        for key, pts in series.items():
            if pts:
                ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", label=key)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("triangles")
        ax.set_ylabel("total frame time (ms, llvmpipe)")
        ax.set_title(args.title)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
        print(f"\nscaling_table: wrote {args.plot}", file=sys.stderr)


if __name__ == "__main__":
    main()
