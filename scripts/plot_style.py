"""One visual style for every plot of shadowlab (run plots and sweep plots): each algorithm id
keeps one colour everywhere, and each second grouping (the other axes of a sweep) one line style
and marker. Stacked stage bars colour by stage instead (stage_styles): one colour and hatch per
stage name, the same in every algorithm's bar, and no two stages alike.

Text drawn from user text (ids, names, labels, stages, units) is drawn as written: importing this
module turns off matplotlib's math parser (plain_text()), so that a '$' in a name neither renders
as math nor fails the plot ("Expected \\frac{num}{den}").
"""
import math

import matplotlib
import matplotlib.colors as mcolors
import matplotlib.scale
import matplotlib.ticker

_SUPERSCRIPT = str.maketrans("-0123456789", "\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078\u2079")


def plain_number(x):
    """A log axis's tick as plain text: 10 to a power as 10³, 10⁻², others as %g."""
    if x > 0:
        k = round(math.log10(x))
        if abs(math.log10(x) - k) < 1e-9:
            return {0: "1", 1: "10"}.get(k, "10" + str(k).translate(_SUPERSCRIPT))
    return f"{x:g}"


class PlainLogFormatter(matplotlib.ticker.LogFormatter):
    """Matplotlib's log tick labels are mathtext ($\\mathdefault{10^{2}}$), which plain_text()
    turns off, so they were drawn as that source (thirteenth probe): these are plain text. Which
    ticks get a label is LogFormatter's choice; only the text differs."""

    def _num_to_string(self, x, vmin, vmax):
        return plain_number(x)

    def __call__(self, x, pos=None):
        text = super().__call__(x, pos)  # of |x|: LogFormatter drops the sign a symlog axis has
        return "\u2212" + text if x < 0 and text else text


class PlainLogScale(matplotlib.scale.LogScale):
    """The log scale ("log"), its tick labels plain text."""

    def set_default_locators_and_formatters(self, axis):
        super().set_default_locators_and_formatters(axis)
        axis.set_major_formatter(PlainLogFormatter(self.base))
        axis.set_minor_formatter(PlainLogFormatter(self.base, labelOnlyBase=(self.subs is not None)))


class PlainSymlogScale(matplotlib.scale.SymmetricalLogScale):
    """The symmetrical log scale ("symlog"), its tick labels plain text (fourteenth probe: history's
    accuracy plot still showed the mathtext source)."""

    def set_default_locators_and_formatters(self, axis):
        super().set_default_locators_and_formatters(axis)
        axis.set_major_formatter(PlainLogFormatter(self.base))


def plain_text():
    """Every text made from now on is plain text: '$...$' is not mathtext (matplotlib >= 3.5), and
    log and symlog axes label their ticks in plain text too."""
    matplotlib.rcParams["text.parse_math"] = False
    matplotlib.scale.register_scale(PlainLogScale)
    matplotlib.scale.register_scale(PlainSymlogScale)


plain_text()

# Matplotlib's tab10 (colour-blind friendly, distinct in grey) then tab20's lighter set.
COLOURS = list(mcolors.TABLEAU_COLORS.values()) + ["#aec7e8", "#ffbb78", "#98df8a", "#ff9896", "#c5b0d5", "#c49c94"]
LINESTYLES = ["-", "--", ":", "-."]
MARKERS = ["o", "s", "^", "D", "v", "P", "X", "*"]

# Stage colours: tab20's dark half, then its light half, so that the first ten stages differ
# strongly and the next ten still differ from every other in hue or lightness.
_TAB20 = list(matplotlib.colormaps["tab20"].colors)
STAGE_COLOURS = _TAB20[0::2] + _TAB20[1::2]
# A second cue for grey print. 7 hatches against 20 colours: a (colour, hatch) pair repeats only
# after 140 stages.
STAGE_HATCHES = ["", "//", "..", "xx", "\\\\", "++", "oo"]


def colours(ids):
    """Colour per algorithm id, in first-seen order."""
    return {i: COLOURS[k % len(COLOURS)] for k, i in enumerate(dict.fromkeys(ids))}


def variants(keys):
    """Line style and marker per grouping, in first-seen order; the first gets a solid line."""
    return {key: {"linestyle": LINESTYLES[k % len(LINESTYLES)], "marker": MARKERS[k % len(MARKERS)]}
            for k, key in enumerate(dict.fromkeys(keys))}


def stage_styles(stages):
    """Face colour and hatch per stage name, in first-seen order: one look per stage."""
    return {st: {"color": STAGE_COLOURS[k % len(STAGE_COLOURS)], "hatch": STAGE_HATCHES[k % len(STAGE_HATCHES)]}
            for k, st in enumerate(dict.fromkeys(stages))}


def text_colour(face):
    """Black or white, whichever reads better on a face colour (labels drawn on bar segments)."""
    r, g, b = mcolors.to_rgb(face)
    return "black" if 0.299 * r + 0.587 * g + 0.114 * b > 0.5 else "white"
