#!/usr/bin/env python3
"""Scaling study: runs one experiment config per scene size and tabulates / plots stage times
against the triangle count.

A config holds one scene, so a scaling study is a list of configs that differ in their scene
(e.g. configs/psv/scaling_*.json). Each is run with `shadowlab run CONFIG --out OUT/<name>`
(skipped with --reuse when OUT/<name>/summary.json exists); then OUT gets:

  scaling.csv    one row per (algorithm id, scene): triangles, mean time per stage, memory, ...
  scaling.md     the same as a table, plus a power-law fit  time = c * n^k  per (id, stage)
  scaling.png    log-log plot of each stage's mean time against n, one panel per stage

Usage: scaling.py --out DIR [--binary build/shadowlab] [--reuse] [--stages build,traverse,total]
                  [--counters nodes_visited_mean] [--ratio psv/metric_tree] CONFIG...

--ratio A/B adds, per scene, the total frame time of id A over that of id B in the same run (the
metric-tree paper's "who wins at which size" comparison).
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys


def run(binary, config, out_dir, reuse):
    if reuse and os.path.exists(os.path.join(out_dir, "summary.json")):
        return
    cmd = [binary, "run", config, "--out", out_dir, "--force", "--no-progress"]
    print("scaling:", " ".join(cmd), flush=True)
    rc = subprocess.call(cmd)
    if rc != 0:
        sys.exit(f"scaling: {config}: shadowlab exited with {rc}")


def power_fit(ns, ts):
    """Least-squares fit of log t = log c + k log n; returns (k, c) or None."""
    pts = [(math.log(n), math.log(t)) for n, t in zip(ns, ts) if n > 0 and t > 0]
    if len(pts) < 2:
        return None
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    if sxx == 0:
        return None
    k = sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx
    return k, math.exp(my - k * mx)


def nlogn_ratio(ns, ts):
    """t / (n log2 n), normalised to the smallest n: flat when the growth is n log n."""
    base = None
    out = []
    for n, t in zip(ns, ts):
        r = t / (n * math.log2(n)) if n > 1 and t > 0 else float("nan")
        base = base or r
        out.append(r / base if base else float("nan"))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True)
    ap.add_argument("--binary", default=os.path.join(os.path.dirname(__file__), "..", "build", "shadowlab"))
    ap.add_argument("--reuse", action="store_true", help="keep runs whose summary.json exists")
    ap.add_argument("--stages", default="", help="comma-separated stages to tabulate (default: all)")
    ap.add_argument("--counters", default="", help="comma-separated counters to tabulate (mean)")
    ap.add_argument("--ratio", action="append", default=[], help="A/B: total time of id A over id B, per scene")
    ap.add_argument("configs", nargs="+")
    a = ap.parse_args()

    os.makedirs(a.out, exist_ok=True)
    rows = []  # (id, algorithm, triangles, stage -> mean ms, memory, mismatch worst, counters, renderer)
    for cfg in a.configs:
        with open(cfg) as f:
            name = json.load(f).get("name") or os.path.splitext(os.path.basename(cfg))[0]
        out_dir = os.path.join(a.out, name)
        run(a.binary, cfg, out_dir, a.reuse)
        with open(os.path.join(out_dir, "summary.json")) as f:
            s = json.load(f)
        for aid, alg in s["algorithms"].items():
            acc = alg.get("accuracy") or {}
            rows.append({
                "id": aid, "algorithm": alg["algorithm"], "scene": name, "triangles": s["triangles"],
                "times": {k: v["mean"] for k, v in alg["time_ms"].items()},
                "preprocess": alg.get("preprocess_ms", 0.0),
                "memory": alg.get("memory_bytes", 0),
                "mismatch_max": acc.get("mismatch_ratio_max"),
                "overflow": alg.get("overflow", 0),
                "counters": {k: v["mean"] for k, v in alg.get("counters", {}).items()},
                "time_source": s.get("stage_time_source", "gpu"), "renderer": s.get("renderer", ""),
            })
    rows.sort(key=lambda r: (r["id"], r["triangles"]))

    stages = [x for x in a.stages.split(",") if x] or sorted({k for r in rows for k in r["times"]},
                                                             key=lambda k: (k == "total", k))
    counters = [x for x in a.counters.split(",") if x]
    ids = list(dict.fromkeys(r["id"] for r in rows))

    with open(os.path.join(a.out, "scaling.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["id", "algorithm", "scene", "triangles", "preprocess_ms"] + [f"{st}_ms" for st in stages] +
                   counters + ["memory_bytes", "mismatch_ratio_max", "overflow"])
        for r in rows:
            w.writerow([r["id"], r["algorithm"], r["scene"], r["triangles"], r["preprocess"]] +
                       [r["times"].get(st, "") for st in stages] + [r["counters"].get(c, "") for c in counters] +
                       [r["memory"], r["mismatch_max"], r["overflow"]])

    src = rows[0]["time_source"] if rows else "gpu"
    lines = [f"# Scaling ({rows[0]['renderer'] if rows else ''}; stage times: "
             f"{'GPU timer queries' if src == 'gpu' else 'wall clock per stage'}, mean ms per frame)", ""]
    head = ["id", "triangles"] + stages + counters + ["memory (MiB)", "mismatch (worst frame)", "overflow"]
    lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        mm = "" if r["mismatch_max"] is None else f"{100 * r['mismatch_max']:.4f} %"
        lines.append("| " + " | ".join([r["id"], f"{r['triangles']:,}"] +
                                       [f"{r['times'][st]:.2f}" if st in r["times"] else "" for st in stages] +
                                       [f"{r['counters'][c]:.2f}" if c in r["counters"] else "" for c in counters] +
                                       [f"{r['memory'] / 2**20:.1f}", mm, str(r["overflow"])]) + " |")
    lines += ["", "## Power-law fits: time = c · n^k (least squares in log-log)", "",
              "| id | stage | k | t / (n log n), normalised to the smallest n |", "|---|---|---:|---|"]
    for aid in ids:
        rs = [r for r in rows if r["id"] == aid]
        for st in stages:
            pts = [(r["triangles"], r["times"][st]) for r in rs if st in r["times"]]
            fit = power_fit([p[0] for p in pts], [p[1] for p in pts])
            if fit:
                ratios = nlogn_ratio([p[0] for p in pts], [p[1] for p in pts])
                lines.append(f"| {aid} | {st} | {fit[0]:.2f} | " + ", ".join(f"{x:.2f}" for x in ratios) + " |")
    for ratio in a.ratio:
        num, _, den = ratio.partition("/")
        lines += ["", f"## {num} / {den}: total time per frame, same run", "", "| scene | triangles | ratio |",
                  "|---|---:|---:|"]
        for scene in dict.fromkeys(r["scene"] for r in rows):
            t = {r["id"]: r for r in rows if r["scene"] == scene}
            if num in t and den in t and t[den]["times"].get("total"):
                lines.append(f"| {scene} | {t[num]['triangles']:,} | "
                             f"{t[num]['times']['total'] / t[den]['times']['total']:.2f} |")
    with open(os.path.join(a.out, "scaling.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))

    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("scaling: matplotlib missing, no plot", file=sys.stderr)
        return
    fig, axes = plt.subplots(1, len(stages), figsize=(4.2 * len(stages), 3.8), squeeze=False)
    for ax, st in zip(axes[0], stages):
        for aid in ids:
            pts = [(r["triangles"], r["times"][st]) for r in rows if r["id"] == aid and st in r["times"]]
            if not pts:
                continue
            fit = power_fit([p[0] for p in pts], [p[1] for p in pts])
            label = aid + (f" (k={fit[0]:.2f})" if fit else "")
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], marker="o", label=label)
        ax.set_title(st)
        ax.set_xlabel("triangles")
        ax.set_ylabel("ms per frame")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "scaling.png"), dpi=110)


if __name__ == "__main__":
    main()
