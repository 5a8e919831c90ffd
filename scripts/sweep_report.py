#!/usr/bin/env python3
"""The report of a merged sweep: reads DIR/plan.json and DIR/sweep.csv (written by
`shadowlab sweep merge DIR`, which runs this script) and writes

  DIR/sweep.md         a table per axis, the ratios the sweep file asks for (merge.ratios), and
                       power-law fits  time = c * n^k  per (algorithm id, stage) along size axes
  DIR/sweep_AXIS.png   mean time per frame of each stage against the axis, one line per algorithm
                       id (and per value of the other axes); log-log where the axis is a size
  DIR/sweep_stages.png the stages of each run stacked, a panel per algorithm id, a colour per stage
  DIR/sweep.html       sweep.md with its figures (a "## Figures" section added to it), as one
                       self-contained page (report_html.py)

Usage: sweep_report.py DIR [--no-plots]
"""
import csv
import json
import math
import os
import re
import sys
from collections import defaultdict

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from report_html import link_target, literal  # noqa: E402
from safe_files import open_regular, save_figure, write_text  # noqa: E402

SIZE_SCALES = ("value", "triangles", "pixels")


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
    base, out = None, []
    for n, t in zip(ns, ts):
        r = t / (n * math.log2(n)) if n > 1 and t > 0 else float("nan")
        base = base or r
        out.append(r / base if base else float("nan"))
    return out


class Sweep:
    def __init__(self, directory):
        with open_regular(os.path.join(directory, "plan.json")) as f:
            self.plan = json.load(f)
        self.axes = self.plan["axes"]
        self.merge = self.plan.get("merge") or {}
        # run id -> {"axes": {name: label}, "triangles", "pixels", "values": {alg id: {measure: float}}}
        self.runs = {}
        self.algorithms = {}  # alg id -> algorithm name, in first-seen order
        with open_regular(os.path.join(directory, "sweep.csv"), newline="") as f:
            for row in csv.DictReader(f):
                r = self.runs.setdefault(row["run"], {"index": int(row["index"]), "triangles": int(row["triangles"]),
                                                      "pixels": int(row["pixels"]), "values": defaultdict(dict),
                                                      "axes": {a["name"]: row[a["name"]] for a in self.axes}})
                self.algorithms.setdefault(row["id"], row["algorithm"])
                r["values"][row["id"]][row["measure"]] = float(row["value"]) if row["value"] != "" else None
        measures = {m for r in self.runs.values() for v in r["values"].values() for m in v}
        found = sorted({m[len("time_ms."):] for m in measures if m.startswith("time_ms.")}, key=lambda s: (s == "total", s))
        self.stages = self.merge.get("stages") or found
        self.counters = self.merge.get("counters") or []

    def x(self, axis, run):
        """The x of a run along an axis: its size for size axes, else the label's position."""
        scale = axis["scale"]
        if scale == "triangles":
            return run["triangles"]
        if scale == "pixels":
            return run["pixels"]
        label = run["axes"][axis["name"]]
        return float(label) if scale == "value" else axis["labels"].index(label)

    def others(self, axis):
        return [a for a in self.axes if a["name"] != axis["name"]]

    def group_key(self, axis, run):
        """The labels of the other axes (what stays fixed along one line of this axis)."""
        return tuple(run["axes"][a["name"]] for a in self.others(axis))

    def ordered_runs(self, axis):
        """Runs sorted by the other axes, then along this axis."""
        def key(run):
            return ([a["labels"].index(run["axes"][a["name"]]) for a in self.others(axis)] +
                    [axis["labels"].index(run["axes"][axis["name"]])])
        return sorted(self.runs.values(), key=key)


def fmt(v, spec):
    return "" if v is None else format(v, spec)


# Every name, id, label, stage, counter, ratio and source below comes from the sweep file or the
# runs: it reaches sweep.md only through literal() (or code()), so that it shows as written and
# never as a link, an image, markup or a table cell's end.

def code(name):
    """An axis name as `code` (as the C++ side checks them: letters, digits and '_'); any other
    name as literal text, since a code span shows backslashes as they are."""
    name = str(name)
    return f"`{name}`" if re.fullmatch(r"[A-Za-z0-9_]+", name) else literal(name)


def plot_file(s, axis):
    """The file of an axis's plot: sweep_AXIS.png, AXIS being an identifier as the C++ side checks
    them; any other name (a plan.json not written by `sweep merge`) never becomes part of a path."""
    name = str(axis["name"])
    return f"sweep_{name}.png" if re.fullmatch(r"[A-Za-z0-9_]+", name) else f"sweep_axis{s.axes.index(axis)}.png"


def row_line(values):
    """One table row of already escaped cells."""
    return "| " + " | ".join(values) + " |"


def axis_table(s, axis):
    others = s.others(axis)
    head = [literal(a["name"]) for a in others] + ["id", literal(axis["name"]), "triangles"] + \
        [literal(st) for st in s.stages] + [literal(c) for c in s.counters] + ["memory (MiB)", "mismatch (worst frame)", "overflow"]
    lines = [row_line(head), "|" + "---|" * len(others) + "---|---|" + "---:|" * (len(head) - len(others) - 2)]
    for aid in s.algorithms:
        for run in s.ordered_runs(axis):
            v = run["values"].get(aid)
            if v is None:
                continue
            mm = v.get("accuracy.mismatch_ratio_max")
            cells = [literal(run["axes"][a["name"]]) for a in others] + \
                [literal(aid), literal(run["axes"][axis["name"]]), f"{run['triangles']:,}"]
            cells += [fmt(v.get(f"time_ms.{st}"), ".2f") for st in s.stages]
            cells += [fmt(v.get(f"counters.{c}"), ".2f") for c in s.counters]
            cells += [fmt(v["memory_bytes"] / 2 ** 20, ".1f"), "" if mm is None else f"{100 * mm:.4f} %",
                      fmt(v.get("overflow"), ".0f")]
            lines.append(row_line(cells))
    return lines


def ratio_table(s, ratio):
    num, _, den = ratio.partition("/")
    # merge.paper: the paper's own ratio beside each measured one, where it gives both times.
    paper = s.merge.get("paper", {})
    times = paper.get("times_ms", {})
    paper_ratio = times[num] / times[den] if num in times and den in times else None
    head = [literal(a["name"]) for a in s.axes] + ["triangles", f"{literal(num)} / {literal(den)}"]
    if paper_ratio is not None:
        head += ["paper", "ours / paper"]
    lines = [f"## {literal(num)} / {literal(den)}: total time per frame, same run", ""]
    if paper_ratio is not None:
        lines += [f"Paper: {literal(paper.get('source', ''))}: {literal(num)} {times[num]:g} ms, "
                  f"{literal(den)} {times[den]:g} ms, ratio {paper_ratio:.2f}.", ""]
    lines += [row_line(head), "|" + "---|" * len(s.axes) + "---:|" * (len(head) - len(s.axes))]
    for run in sorted(s.runs.values(), key=lambda r: r["index"]):
        a, b = run["values"].get(num, {}).get("time_ms.total"), run["values"].get(den, {}).get("time_ms.total")
        if a is not None and b:
            row = [literal(run["axes"][x["name"]]) for x in s.axes] + [f"{run['triangles']:,}", f"{a / b:.2f}"]
            if paper_ratio is not None:
                row += [f"{paper_ratio:.2f}", f"{a / b / paper_ratio:.2f}"]
            lines.append(row_line(row))
    return lines


def fit_table(s, axis):
    others = s.others(axis)
    xname = {"triangles": "n = triangles", "pixels": "n = pixels", "value": f"n = {literal(axis['name'])}"}[axis["scale"]]
    lines = [f"## Power-law fits along {code(axis['name'])}: time = c · n^k ({xname}; least squares in log-log)", "",
             row_line([literal(a["name"]) for a in others] + ["id", "stage", "k", "t / (n log n), normalised to the smallest n"]),
             "|" + "---|" * len(others) + "---|---|---:|---|"]
    header = len(lines)
    groups = defaultdict(list)
    for run in s.ordered_runs(axis):
        groups[s.group_key(axis, run)].append(run)
    for key, runs in groups.items():
        for aid in s.algorithms:
            for st in s.stages:
                pts = sorted((s.x(axis, r), r["values"][aid][f"time_ms.{st}"]) for r in runs
                             if aid in r["values"] and r["values"][aid].get(f"time_ms.{st}") is not None)
                fit = power_fit([p[0] for p in pts], [p[1] for p in pts])
                if fit:
                    ratios = ", ".join(f"{x:.2f}" for x in nlogn_ratio([p[0] for p in pts], [p[1] for p in pts]))
                    lines.append(row_line([literal(k) for k in key] + [literal(aid), literal(st), f"{fit[0]:.2f}", ratios]))
    if len(lines) == header:
        # A table of no row says nothing of why: a fit needs two points of different n with times
        # above 0 in one group of the other axes (probe 26: every point had one triangle count).
        lines += ["", "No fit: no group of runs holds two points of different n with times above 0 "
                      "(a fit needs at least two sizes)."]
    return lines


def report(s, directory):
    statuses = [r.get("status", "missing") for r in s.plan["runs"]]
    complete = [r for r in s.plan["runs"] if r.get("status") == "complete"]
    renderers = sorted({r.get("renderer", "") for r in complete})
    sources = sorted({r.get("stage_time_source", "") for r in complete})
    src = "; ".join("wall clock per stage" if x == "wall" else "GPU timer queries" for x in sources)
    lines = [f"# Sweep {literal(s.plan['name'])}", "",
             f"- runs: {len(statuses)}, merged {statuses.count('complete')}, failed {statuses.count('failed')}, "
             f"missing {statuses.count('missing')}",
             f"- renderer: {', '.join(literal(r) for r in renderers)}",
             f"- stage times: {src}, mean ms per frame",
             "- axes: " + ("; ".join(f"{code(a['name'])} ({literal(a['scale'])}): {', '.join(literal(x) for x in a['labels'])}"
                                     for a in s.axes) or "none"), ""]
    for r in s.plan["runs"]:
        if r.get("status") != "complete":
            labels = " ".join(f"{literal(k)}={literal(v)}" for k, v in r["axes"].items())
            lines.append(f"- **run {literal(r['index'])} {literal(r['id'])} ({labels}): {literal(r.get('status', 'missing'))}**")
    for axis in s.axes:
        lines += ["", f"## By {code(axis['name'])}", ""] + axis_table(s, axis)
    if not s.axes:
        lines += ["", "## Results", ""] + axis_table_flat(s)
    for ratio in s.merge.get("ratios", []):
        lines += [""] + ratio_table(s, ratio)
    for axis in s.axes:
        if axis["scale"] in SIZE_SCALES:
            lines += [""] + fit_table(s, axis)
    write_text(os.path.join(directory, "sweep.md"), "\n".join(lines) + "\n")


def axis_table_flat(s):
    """A sweep without axes is one run: its table has no axis column."""
    head = ["id", "triangles"] + [literal(st) for st in s.stages] + ["memory (MiB)", "mismatch (worst frame)"]
    lines = [row_line(head), "|---|" + "---:|" * (len(head) - 1)]
    for run in s.runs.values():
        for aid, v in run["values"].items():
            mm = v.get("accuracy.mismatch_ratio_max")
            lines.append(row_line([literal(aid), f"{run['triangles']:,}"] + [fmt(v.get(f"time_ms.{st}"), ".2f") for st in s.stages] +
                                  [fmt(v["memory_bytes"] / 2 ** 20, ".1f"), "" if mm is None else f"{100 * mm:.4f} %"]))
    return lines


def plots(s, directory):
    import matplotlib
    matplotlib.use("Agg")  # headless: no display on CI or servers
    import matplotlib.pyplot as plt
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import plot_style

    colour = plot_style.colours(s.algorithms)
    for axis in s.axes:
        size = axis["scale"] in SIZE_SCALES
        groups = defaultdict(list)
        for run in s.ordered_runs(axis):
            groups[s.group_key(axis, run)].append(run)
        style = plot_style.variants(groups)
        stages = [st for st in s.stages if any(f"time_ms.{st}" in v for r in s.runs.values() for v in r["values"].values())]
        if not stages:
            continue
        # At most four panels a row: a sweep with many stages stays readable at page width.
        ncols = min(4, len(stages))
        nrows = -(-len(stages) // ncols)
        fig, axes = plt.subplots(nrows, ncols, figsize=(4.4 * ncols, 3.9 * nrows), squeeze=False)
        for ax in axes.flat[len(stages):]:
            ax.set_axis_off()
        for ax, st in zip(axes.flat, stages):
            for aid in s.algorithms:
                for key, runs in groups.items():
                    pts = sorted((s.x(axis, r), r["values"][aid][f"time_ms.{st}"]) for r in runs
                                 if aid in r["values"] and r["values"][aid].get(f"time_ms.{st}"))
                    if not pts:
                        continue
                    # The other axes' values by name ("pcf=1"), not as bare labels.
                    label = aid + (" (" + ", ".join(f"{a['name']}={v}" for a, v in zip(s.others(axis), key)) + ")" if key else "")
                    if size:
                        fit = power_fit([p[0] for p in pts], [p[1] for p in pts])
                        label += f" k={fit[0]:.2f}" if fit else ""
                    ax.plot([p[0] for p in pts], [p[1] for p in pts], color=colour[aid], linestyle=style[key]["linestyle"],
                            marker=style[key]["marker"], label=label)
            if size:
                ax.set_xscale("log")
                ax.set_yscale("log")
            else:
                ax.set_xticks(range(len(axis["labels"])))
                ax.set_xticklabels(axis["labels"], rotation=20)
            ax.set_title(st)
            ax.set_xlabel({"triangles": "triangles", "pixels": "pixels"}.get(axis["scale"], axis["name"]))
            ax.set_ylabel("ms per frame")
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=7)
        fig.suptitle(f"{s.plan['name']}: time per frame against {axis['name']}")
        fig.tight_layout()
        save_figure(fig, os.path.join(directory, plot_file(s, axis)), dpi=110)
        plt.close(fig)


def stage_plot(s, directory):
    """Stacked bars of each run's stages, one panel per algorithm id: the run-level breakdown that
    the per-axis lines do not show. A stage has one colour and hatch in every panel (plot_style)."""
    import matplotlib
    matplotlib.use("Agg")  # headless: no display on CI or servers
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import plot_style

    runs = sorted(s.runs.values(), key=lambda r: r["index"])
    stages = list(dict.fromkeys(m[len("time_ms."):] for r in runs for v in r["values"].values() for m in v
                                if m.startswith("time_ms.") and m != "time_ms.total" and m != "time_ms.preprocess"))
    ids = [aid for aid in s.algorithms if any(aid in r["values"] for r in runs)]
    if not stages or not ids or not runs:
        return None
    style = plot_style.stage_styles(stages)
    labels = [", ".join(f"{k}={v}" for k, v in r["axes"].items()) or f"run {r['index']}" for r in runs]
    fig, axes = plt.subplots(len(ids), 1, squeeze=False, layout="constrained", figsize=(max(7, 0.55 * len(runs) + 3), 2.6 * len(ids) + 1.2))
    for ax, aid in zip(axes[:, 0], ids):
        for x, r in enumerate(runs):
            bottom = 0.0
            for st in stages:
                ms = r["values"].get(aid, {}).get(f"time_ms.{st}")
                if ms:
                    ax.bar(x, ms, bottom=bottom, width=0.7, color=style[st]["color"], hatch=style[st]["hatch"],
                           edgecolor="black", linewidth=0.5)
                    bottom += ms
        ax.set_title(aid, fontsize=9)
        ax.set_ylabel("ms per frame")
        ax.set_xticks(range(len(runs)))
        ax.set_xticklabels(labels if ax is axes[-1, 0] else [""] * len(runs), rotation=30, ha="right", fontsize=7)
        ax.grid(True, axis="y", alpha=0.3)
    axes[0, 0].legend(handles=[Patch(facecolor=st["color"], hatch=st["hatch"], edgecolor="black", label=name)
                               for name, st in style.items()], title="stage", loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7)
    fig.suptitle(f"{s.plan['name']}: mean time per frame of each stage, run by run")
    path = os.path.join(directory, "sweep_stages.png")
    save_figure(fig, path, dpi=110)
    plt.close(fig)
    return path


def figures(s, directory):
    """Appends a "## Figures" section to sweep.md showing every plot drawn (replacing an earlier one)."""
    names = [(plot_file(s, a), f"Time per frame of each stage against {a['name']}") for a in s.axes]
    names.append(("sweep_stages.png", "The stages of each run, per algorithm id"))
    shown = [(n, title) for n, title in names if os.path.exists(os.path.join(directory, n))]
    path = os.path.join(directory, "sweep.md")
    with open_regular(path) as f:
        text = f.read()
    cut = text.find("\n## Figures\n")
    if cut >= 0:
        text = text[:cut + 1]
    if shown:
        text = text.rstrip("\n") + "\n\n## Figures\n\n" + "\n\n".join(
            f"![{literal(title)}]({link_target(n)})" for n, title in shown) + "\n"
        write_text(path, text)


def html_report(directory):
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import report_html
    report_html.convert(os.path.join(directory, "sweep.md"), os.path.join(directory, "sweep.html"))


def plain_text():
    """Names, ids and labels are drawn as written: a '$' in a label must not start matplotlib's
    math parser, whose errors ("Expected \\frac{num}{den}") would fail the whole report."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import plot_style
    plot_style.plain_text()


def main():
    args = sys.argv[1:]
    if not args or len(args) > 2 or (len(args) == 2 and args[1] != "--no-plots"):
        sys.exit(__doc__)
    try:
        s = Sweep(args[0])
    except (OSError, ValueError, KeyError, TypeError) as e:
        # One line naming what could not be read, not a traceback (json and csv errors are ValueErrors).
        sys.exit(f"sweep_report.py: {args[0]}: cannot read plan.json and sweep.csv as `sweep merge` writes them: {e!r}"[:500])
    report(s, args[0])
    if len(args) == 1:
        plain_text()
        plots(s, args[0])
        stage_plot(s, args[0])
        figures(s, args[0])
    html_report(args[0])


if __name__ == "__main__":
    main()
