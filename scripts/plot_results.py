#!/usr/bin/env python3
"""Plots and figures of an experiment directory, drawn after the runner wrote report.md:

  plot_frame_time.png   frame time along the fly-through per algorithm (the metric-tree paper's Figure 11)
  plot_stages.png       mean time per frame of each stage, stacked per algorithm; a colour per stage
  plot_accuracy.png     mismatch against the reference along the fly-through
  images/*_heat_*_labelled.png, contact_fNNNN.png   see frame_figures.py
  report.md             gains a "## Figures" section showing all of the above
  report.html           report.md as one self-contained page (see report_html.py)

Usage: plot_results.py DIR [gpu|wall]   ("wall": stage times from the cpu_ms column, as summary.json's
       stage_time_source says for CPU rasterisers)
"""
import csv
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")  # headless: no display on CI or servers
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import frame_figures  # noqa: E402
import plot_style  # noqa: E402
import report_html  # noqa: E402
from report_html import link_target, literal  # noqa: E402
from safe_files import open_regular, save_figure, write_text  # noqa: E402

PLOTS = [("plot_frame_time.png", "Frame time along the fly-through"), ("plot_stages.png", "Mean time per frame of each stage"),
         ("plot_accuracy.png", "Accuracy against the reference along the fly-through")]
FIGURES_HEADING = "## Figures"


def load(path, wall):
    total = defaultdict(dict)     # id -> frame -> row of the "total" stage
    stages = defaultdict(lambda: defaultdict(float))  # id -> stage -> sum of ms over frames
    with open_regular(path, newline="") as f:
        for row in csv.DictReader(f):
            if row["stage"] == "total":
                total[row["id"]][int(row["frame"])] = row
            else:
                # "wall": a CPU rasteriser's timer queries are unreliable, its stages' wall clocks are not
                ms = row["cpu_ms"] if wall else (row["gpu_ms"] or row["cpu_ms"])
                stages[row["id"]][row["stage"]] += float(ms)
    return total, stages


def plot_frame_time(directory, ids, total, colour):
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for i in ids:
        frames = sorted(total[i])
        ax.plot(frames, [float(total[i][f]["cpu_ms"]) for f in frames], label=i, color=colour[i])
    ax.set_xlabel("frame")
    ax.set_ylabel("visibility time per frame (ms, wall clock)")
    ax.set_yscale("log")
    ax.set_title("Frame time along the fly-through (timed pass: statistics compiled out)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    save_figure(fig, f"{directory}/plot_frame_time.png", dpi=120)
    plt.close(fig)


def plot_stages(directory, ids, total, stages, wall):
    """Stacked bars, one per algorithm id (named under it). A segment's colour and hatch are its
    stage's, the same in every bar, so that e.g. ptsv's and psv's `traverse` read alike and no two
    stages look the same; segments tall enough carry their stage's name and the bar its total."""
    style = plot_style.stage_styles(s for i in ids for s in stages[i])
    fig, ax = plt.subplots(figsize=(max(8, 1.1 * len(ids) + 3), 5))
    means = {i: {st: ms / max(1, len(total[i])) for st, ms in stages[i].items()} for i in ids}
    top = max((sum(m.values()) for m in means.values()), default=0) or 1
    for x, i in enumerate(ids):
        bottom = 0.0
        for stage, mean in means[i].items():
            st = style[stage]
            ax.bar(x, mean, bottom=bottom, width=0.7, color=st["color"], hatch=st["hatch"], edgecolor="black", linewidth=0.6)
            if mean > 0.045 * top:
                ax.text(x, bottom + mean / 2, stage, ha="center", va="center", fontsize=7,
                        color=plot_style.text_colour(st["color"]),
                        bbox={"facecolor": st["color"], "edgecolor": "none", "pad": 0.6})
            bottom += mean
        ax.text(x, bottom + 0.01 * top, f"{bottom:.3g} ms", ha="center", va="bottom", fontsize=7)
    handles = [Patch(facecolor=st["color"], edgecolor="black", hatch=st["hatch"], label=name) for name, st in style.items()]
    if handles:
        ax.legend(handles=handles, title="stage", fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax.set_xticks(range(len(ids)))
    ax.set_xticklabels(ids, rotation=20, ha="right")
    ax.set_xlim(-0.6, len(ids) - 0.4)
    ax.set_ylim(0, top * 1.08)
    source = "wall clock of each stage run to completion" if wall else "GL timer queries; CPU stages wall clock"
    ax.set_ylabel(f"mean ms per frame ({source})", fontsize=8)
    ax.set_title("Mean time per frame of each stage (timed pass: statistics compiled out)")
    ax.grid(True, axis="y", alpha=0.3)
    fig.tight_layout()
    save_figure(fig, f"{directory}/plot_stages.png", dpi=120)
    plt.close(fig)


def plot_accuracy(directory, ids, total, colour):
    fig, ax = plt.subplots(figsize=(8, 4.5))
    plotted = False
    for i in ids:
        frames = [f for f in sorted(total[i]) if total[i][f]["mismatch_ratio"] != ""]
        if not frames or total[i][frames[0]]["algorithm"] == "reference":
            continue
        ax.plot(frames, [100.0 * float(total[i][f]["mismatch_ratio"]) for f in frames], label=i, color=colour[i])
        plotted = True
    ax.set_xlabel("frame")
    ax.set_ylabel("mismatch against the reference (% of lit pixels)")
    ax.set_title("Accuracy along the fly-through")
    ax.grid(True, alpha=0.3)
    if plotted:
        ax.legend()
    fig.tight_layout()
    save_figure(fig, f"{directory}/plot_accuracy.png", dpi=120)
    plt.close(fig)


def figures_section(directory, sheets, heats):
    """The markdown that shows every figure (paths relative to DIR, where report.md lies)."""
    lines = [FIGURES_HEADING, ""]
    for name, title in PLOTS:
        if os.path.exists(os.path.join(directory, name)):
            lines += [f"![{title}]({link_target(name)})", ""]
    for frame, sheet in sheets.items():
        lines += [f"### Frame {frame}", "",
                  "The reference's shaded image, then per algorithm: shaded image, difference against the reference "
                  "(red = false lit, blue = false shadowed, grey = agrees, black = not lit) and heat maps, each with "
                  "its colour bar, unit and scale (p99: the 99th percentile of the non-zero pixels; brighter pixels are "
                  "clipped to the top colour).", "",
                  f"![Frame {frame}: every algorithm's images]({link_target(sheet)})", ""]
        if heats.get(frame):
            # Ids and heat map names are user text: literal in the link text, %-encoded in the path.
            links = ", ".join(f"[{literal(aid)} {literal(name)}]({link_target(path)})" for aid, name, path in heats[frame])
            lines += [f"Heat maps one by one: {links}.", ""]
    return lines


def append_figures(directory, sheets, heats):
    """Replaces report.md's figures section (running this script again does not repeat it)."""
    path = os.path.join(directory, "report.md")
    if not os.path.exists(path):
        return None
    with open_regular(path) as f:
        text = f.read()
    cut = text.find("\n" + FIGURES_HEADING + "\n")
    if cut >= 0:
        text = text[:cut + 1]
    text = text.rstrip("\n") + "\n\n" + "\n".join(figures_section(directory, sheets, heats)).rstrip("\n") + "\n"
    write_text(path, text)
    return path


def main(directory, time_source="gpu"):
    wall = time_source == "wall"
    total, stages = load(f"{directory}/frames.csv", wall)
    ids = list(total)
    colour = plot_style.colours(ids)
    plot_frame_time(directory, ids, total, colour)
    plot_stages(directory, ids, total, stages, wall)
    plot_accuracy(directory, ids, total, colour)
    sheets, heats = frame_figures.main(directory)
    report = append_figures(directory, sheets, heats)
    if report:
        report_html.convert(report, os.path.join(directory, "report.html"))


if __name__ == "__main__":
    if len(sys.argv) not in (2, 3) or (len(sys.argv) == 3 and sys.argv[2] not in ("gpu", "wall")):
        sys.exit(__doc__)
    main(*sys.argv[1:])
