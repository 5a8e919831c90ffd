#!/usr/bin/env python3
"""User text in reports (experiment and sweep names, algorithm ids, axis labels, merge.stages,
merge.counters, merge.ratios, merge.paper.source) shows as exactly that text in report.md,
sweep.md and their HTML pages, and the HTML converter is safe whatever markdown it is handed:

  - literal() round trip: for hostile strings, a heading, a paragraph, a list item and table cells
    made of literal(s) show s as text (parsed back from the HTML), and tables keep their columns;
  - the converter (scripts/report_html.py) keeps only relative links inside the report's folder and
    #fragments, embeds only regular PNG files inside it, under the size cap, and never blocks;
  - sweep_report.py on a small fake sweep folder with hostile names, labels, stages, ratios and
    paper source; plot_results.py on a small fake run with hostile ids (matplotlib: '$' stays text);
  - headless chromium's DOM of a hostile page has no scheme link and no foreign data: image.

Run: python3 tests/python/test_report_text.py   (ctest runs it; exits non-zero on a failure)
"""
import base64
import csv
import html.parser
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import unittest
import urllib.parse
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SCRIPTS = os.path.join(ROOT, "scripts")
sys.path.insert(0, SCRIPTS)
import report_html  # noqa: E402
from report_html import literal  # noqa: E402

SCHEME = re.compile(r"^[\s\x00-\x20]*[A-Za-z][A-Za-z0-9+.\-]*:")

HOSTILE = [
    "[click me](javascript:alert`1`)",
    "![x](/etc/hostname)",
    "![x](/proc/self/environ)",
    "![x](/dev/zero)",
    "[x](data:text/html,<script>alert(1)</script>)",
    "|", "a|b", "a | b | c", "\\|", "a\\|b", "x\\", "\\", "\\\\", "\\*",
    "*x*", "**x**", "_x_", "__init__", "psv_stack", "a_", "_a", "x*y*z",
    "`code`", "``", "`", "<script>alert(1)</script>", "<b>bold</b>", "&lt;", "&amp;", "&#106;",
    "![x](y)", "[a](b)", "[a]: b", "<http://evil.example/>", "http://evil.example/",
    "Ünïcødé 日本語 🙂", "$x$", "$\\frac{a}{b}$", "# not a heading", "<!-- comment", "-->",
    "- not a list", "+ x", "1. x", "1) x", "> quote", "~~s~~", "{}", "a:b", "=", "---", ":---:",
    "a\tb", "line\nbreak", "cr\rx", "nul\x00x", "del\x7fx", "c1\x85x", "sep\u2028x",
    "tab\t|\tpipe", "100 %", "x^2", "\"quoted\" 'single'", "a.b-c+d=e",
]


def shown(s):
    """What literal(s) shows: control characters as U+FFFD, blanks at the ends trimmed."""
    return re.sub(r"[\x00-\x1f\x7f-\x9f\u2028\u2029]", "\ufffd", s).strip()


def png_bytes(w=4, h=3, rgb=(200, 30, 30)):
    """A small valid RGB PNG."""
    raw = b"".join(b"\x00" + bytes(rgb) * w for _ in range(h))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


class Page(html.parser.HTMLParser):
    """An HTML page as the tests read it: the text of each block (heading, paragraph, list item,
    table cell) in order, the cells of each table row, and every element with its attributes."""
    BLOCKS = {"h1", "h2", "h3", "h4", "h5", "h6", "p", "li", "th", "td", "title"}

    def __init__(self, text):
        super().__init__(convert_charrefs=True)
        self.blocks, self.tables, self.tags, self.open = [], [], [], []
        self.feed(text)
        self.close()

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))
        if tag == "table":
            self.tables.append([])
        elif tag == "tr" and self.tables:
            self.tables[-1].append([])
        if tag in self.BLOCKS:
            self.open.append([tag, ""])

    def handle_endtag(self, tag):
        if tag in self.BLOCKS and self.open and self.open[-1][0] == tag:
            t, text = self.open.pop()
            self.blocks.append((t, text))
            if t in ("th", "td") and self.tables and self.tables[-1]:
                self.tables[-1][-1].append(text)

    def handle_data(self, data):
        if self.open:
            self.open[-1][1] += data

    def texts(self, tag):
        return [text for t, text in self.blocks if t == tag]

    def attrs(self, tag, name):
        return [a.get(name) for t, a in self.tags if t == tag]


def convert(markdown, base, timeout=30):
    """report_html.py run as the reports run it (a child process: a hang fails, not blocks, the test)."""
    md = os.path.join(base, "report.md")
    out = os.path.join(base, "report.html")
    with open(md, "w", encoding="utf-8") as f:
        f.write(markdown)
    start = time.monotonic()
    r = subprocess.run([sys.executable, os.path.join(SCRIPTS, "report_html.py"), md, out],
                       capture_output=True, text=True, timeout=timeout)
    if r.returncode != 0:
        raise AssertionError(f"report_html.py failed: {r.stderr[-2000:]}")
    with open(out, encoding="utf-8") as f:
        return f.read(), time.monotonic() - start


def python_with_matplotlib():
    """An interpreter that has matplotlib (this one, else Debian's), or None."""
    for exe in (sys.executable, "/usr/bin/python3"):
        if exe and os.path.exists(exe) and subprocess.run([exe, "-c", "import matplotlib"], capture_output=True).returncode == 0:
            return exe
    return None


def assert_safe_page(test, page, own_images):
    """No link with a scheme, to another host or out of the folder; no image but the run's own."""
    for href in page.attrs("a", "href"):
        test.assertIsNotNone(href)
        test.assertFalse(SCHEME.match(href), href)
        test.assertFalse(href.startswith(("/", "\\")), href)
        test.assertNotIn("..", urllib.parse.unquote(href).split("/"), href)
    srcs = page.attrs("img", "src")
    test.assertEqual(len(srcs), len(own_images), srcs and [s[:40] for s in srcs])
    for src, data in zip(srcs, own_images):
        test.assertTrue(src.startswith("data:image/png;base64,"), src[:60])
        test.assertEqual(base64.b64decode(src[len("data:image/png;base64,"):]), data)
    for tag in ("script", "iframe", "object", "embed", "link", "meta http-equiv"):
        test.assertNotIn(tag, [t for t, _ in page.tags if t != "meta"])


class LiteralTest(unittest.TestCase):
    def test_escape_rule(self):
        self.assertEqual(literal("psv_stack"), "psv_stack")          # intraword '_' kept
        self.assertEqual(literal("_x_"), "\\_x\\_")
        self.assertEqual(literal("a__b"), "a\\_\\_b")
        self.assertEqual(literal("a|b"), "a\\|b")
        self.assertEqual(literal("![x](y)"), "\\!\\[x\\]\\(y\\)")
        self.assertEqual(literal("a\nb\x00"), "a\ufffdb\ufffd")
        self.assertEqual(literal("日本_語"), "日本\\_語")                # only ASCII letters and digits count
        for c in "\\`*[]()!|<>#~&{}+-.=$:":
            self.assertEqual(literal(c), "\\" + c)
        for c in "abcXYZ019 ,;?@%^\"'/é":
            self.assertEqual(literal(c), c)

    def test_same_rule_as_the_cpp_side(self):
        """framework/core/Text.cpp's markdownLiteral() escapes the same characters (where the file is)."""
        path = os.path.join(ROOT, "framework", "core", "Text.cpp")
        text = open(path, encoding="utf-8").read() if os.path.exists(path) else ""
        m = re.search(r'kMarkup\s*=\s*"((?:[^"\\]|\\.)*)"', text)
        if not m:
            self.skipTest("framework/core/Text.cpp has no kMarkup")
        cpp = re.sub(r"\\(.)", r"\1", m[1])
        self.assertEqual(sorted(cpp), sorted(report_html.MARKUP))

    def test_round_trip_in_heading_paragraph_list_and_table(self):
        with tempfile.TemporaryDirectory() as base:
            for s in HOSTILE:
                with self.subTest(s=s):
                    lit = literal(s)
                    self.assertNotIn("\n", lit)
                    self.assertNotIn("\r", lit)
                    self.assertNotIn("![", lit)
                    md = (f"# {lit}\n\nSome {lit} text\n\n- item {lit}\n\n"
                          f"| {lit} | b | c |\n|---|---:|---|\n| x | {lit} | y |\n| {lit} | {lit} | {lit} |\n")
                    page = Page(report_html.to_html(md, base, "t"))
                    want = shown(s)
                    self.assertEqual(page.texts("h1"), [want])
                    self.assertEqual(page.texts("p"), [f"Some {want} text".strip()])
                    self.assertEqual(page.texts("li"), [f"item {want}".strip()])
                    self.assertEqual(page.tables, [[[want, "b", "c"], ["x", want, "y"], [want, want, want]]])
                    self.assertEqual(page.attrs("a", "href") + page.attrs("img", "src"), [])

    def test_whole_hostile_line_in_every_cell_keeps_columns(self):
        row = [literal(s) for s in HOSTILE]
        md = "| " + " | ".join(row) + " |\n|" + "---|" * len(row) + "\n| " + " | ".join(row) + " |\n"
        page = Page(report_html.to_html(md, None, "t"))
        self.assertEqual(page.tables, [[[shown(s) for s in HOSTILE]] * 2])


class ConverterTest(unittest.TestCase):
    """What the C++ side writes and the reports hold renders as before."""

    def test_escaped_text_in_cells(self):
        md = ("| id | value | note |\n|---|---:|---|\n"
              "| psv\\_x | 1.5 | a\\|b |\n"
              "| a\\\\| 2 | `c\\|d` |\n"          # an escaped backslash, then the cell ends
              "| **total** | 3 | *em* |\n")
        page = Page(report_html.to_html(md, None, "t"))
        self.assertEqual(page.tables, [[["id", "value", "note"], ["psv_x", "1.5", "a|b"], ["a\\", "2", "c|d"],
                                        ["total", "3", "em"]]])
        out = report_html.to_html(md, None, "t")
        self.assertIn("<td class=r>1.5</td>", out)
        self.assertIn("<strong>total</strong>", out)
        self.assertIn("<code>c|d</code>", out)

    def test_report_markup_unchanged(self):
        md = ("# demo\n\n<!-- a comment\nover lines -->\n- renderer: x (y)\n- b\n\n## Time\n\n"
              "Text with **bold**, *italic*, `code` and \\*stars\\*.\n\n"
              "[psv nodes](images/psv_f0000_heat_nodes_labelled.png), [top](#demo)\n")
        out = report_html.to_html(md, "/nonexistent-base", "demo")
        self.assertIn("<h1>demo</h1>", out)
        self.assertNotIn("comment", out)
        self.assertIn("<ul>\n<li>renderer: x (y)</li>\n<li>b</li>\n</ul>", out)
        self.assertIn("<p>Text with <strong>bold</strong>, <em>italic</em>, <code>code</code> and *stars*.</p>", out)
        self.assertIn('<a href="images/psv_f0000_heat_nodes_labelled.png">psv nodes</a>', out)
        self.assertIn('<a href="#demo">top</a>', out)

    def test_local_path_rules(self):
        with tempfile.TemporaryDirectory() as base:
            for ref in ("a.png", "images/b.png", "a%20b.png", "x/./y.png", "a.png?x=1", "c.html#f"):
                self.assertIsNotNone(report_html.local_path(ref, base), ref)
            for ref in ("javascript:alert(1)", "JaVaScRiPt:x", " javascript:x", "java\tscript:x", "java%0ascript:x",
                        "javascript%3Aalert(1)", "data:text/html,x", "file:///etc/passwd", "vbscript:x", "http://e.x/",
                        "//evil.example/", "/etc/hostname", "%2Fetc%2Fhostname", "../x.png", "a/../../x.png",
                        "a/%2e%2e/%2e%2e/x.png", "..", ".", "", "a\\b.png", "\\\\evil\\x", "C:x.png", "a%00.png",
                        "%ff%fe.png", "a b.png", "x\u2028.png"):
                self.assertIsNone(report_html.local_path(ref, base), ref)


class HostileMarkdownTest(unittest.TestCase):
    """Markdown handed to the converter directly, as a hostile report.md would be."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="report-text-")
        cls.base = os.path.join(cls.tmp, "run")
        os.makedirs(os.path.join(cls.base, "images"))
        os.mkdir(os.path.join(cls.base, "dir.png"))
        cls.ok, cls.ok2, outside = png_bytes(4, 3), png_bytes(5, 2, (0, 90, 200)), png_bytes(6, 6, (9, 9, 9))
        files = {"ok.png": cls.ok, "images/ok 2.png": cls.ok2, "../outside.png": outside,
                 "fake.png": b"secret-content-XYZ", "secret.txt": b"secret-content-XYZ"}
        for name, data in files.items():
            with open(os.path.join(cls.base, name), "wb") as f:
                f.write(data)
        os.symlink(os.path.join(cls.tmp, "outside.png"), os.path.join(cls.base, "link.png"))
        os.symlink(cls.tmp, os.path.join(cls.base, "up"))
        os.symlink("/etc/hostname", os.path.join(cls.base, "host.png"))
        os.symlink("secret.txt", os.path.join(cls.base, "inside_link.png"))
        os.mkfifo(os.path.join(cls.base, "fifo.png"))
        with open(os.path.join(cls.base, "big.png"), "wb") as f:
            f.write(b"\x89PNG\r\n\x1a\n")
            f.truncate(report_html.MAX_IMAGE_BYTES + 1)  # sparse: nothing is written but the signature
        refused = ["/etc/hostname", "/proc/self/environ", "/dev/zero", "../outside.png", "link.png", "up/outside.png",
                   "host.png", "fifo.png", "big.png", "fake.png", "secret.txt", "inside_link.png", "dir.png",
                   "file:///etc/hostname", "%2Fetc%2Fhostname", "ok%2F..%2F..%2Foutside.png", "images/..%2F..%2Foutside.png",
                   "data:image/png;base64,iVBORw0KGgo=", "http://evil.example/x.png", "//evil.example/x.png", "\\etc\\x.png"]
        links = ["javascript:alert(1)", "JaVaScRiPt:alert(1)", "java&#115;cript:alert(1)", "&#106;avascript:x",
                 "javascript%3Aalert(1)", "%6Aavascript:alert(1)", "data:text/html,<script>alert(1)</script>",
                 "file:///etc/passwd", "vbscript:msgbox(1)", "http://evil.example/", "HTTPS://evil.example/",
                 "//evil.example/", "/etc/passwd", "\\\\evil\\share", "../outside.png", "link.png", "up/outside.png",
                 "images/%2e%2e/%2e%2e/outside.png", "java\\tscript:x"]
        cls.refused = refused
        md = ["# [click me](javascript:alert`1`) ![x](/etc/hostname)", "",
              '<a href="javascript:alert(1)">raw</a> <script>alert(1)</script> <img src=x onerror=alert(1)>', ""]
        md += [f"![refused {k}]({src})" for k, src in enumerate(refused)] + [""]
        md += ["Links: " + ", ".join(f"[link {k}]({href})" for k, href in enumerate(links)), ""]
        md += ["| a | b |", "|---|---:|", "| ![x](/etc/hostname) | [y](javascript:alert(1)) |", ""]
        md += ["![own](ok.png)", "", "Inline ![own 2](images/ok%202.png) and [a link](images/ok%202.png) and [top](#top).", ""]
        md += ["![" + "A" * 5000 + "](ok.png)"]
        cls.md = "\n".join(md) + "\n"
        cls.html, cls.seconds = convert(cls.md, cls.base)
        cls.page = Page(cls.html)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_terminates_promptly(self):
        self.assertLess(self.seconds, 20)

    def test_only_own_images_and_local_links(self):
        assert_safe_page(self, self.page, [self.ok, self.ok2, self.ok])
        self.assertEqual(sorted(self.page.attrs("a", "href")), ["#top", "images/ok%202.png"])
        self.assertEqual(self.html.count('src="data:'), 3)
        self.assertNotIn("secret-content-XYZ", self.html)
        self.assertNotIn(base64.b64encode(b"secret-content-XYZ").decode()[:16], self.html)

    def test_refused_images_are_named_as_text(self):
        # The refused list, and the heading's and the table's ![x](/etc/hostname).
        self.assertEqual(self.html.count("[image not embedded: "), len(self.refused) + 2)
        self.assertIn("[image not embedded: /etc/hostname]", self.page.texts("p") + self.page.texts("td") + [
            t for _, t in self.page.blocks])

    def test_alt_text_bounded(self):
        alts = self.page.attrs("img", "alt")
        self.assertEqual(len(alts), 3)
        self.assertLessEqual(max(len(a) for a in alts), report_html.MAX_ALT_CHARS + 1)

    def test_raw_html_is_text(self):
        self.assertNotIn("<script", self.html.lower().replace("&lt;script", ""))
        self.assertIn("&lt;script&gt;alert(1)&lt;/script&gt;", self.html)

    def test_missing_image_in_folder(self):
        out, _ = convert("![gone](gone.png)\n", self.base)
        self.assertIn("[image missing: gone.png]", out)

    def test_deep_nesting_does_not_crash(self):
        md = "**[" * 300 + "x" + "](y)**" * 300 + "\n" + "*" * 10000 + "\n" + "[" * 5000 + "\n"
        report_html.to_html(md, self.base, "t")

    @unittest.skipUnless(shutil.which("chromium"), "chromium is not installed (scripts/setup.sh installs it)")
    def test_headless_chromium_dom(self):
        profile = tempfile.mkdtemp(prefix="chromium-profile-")
        try:
            r = subprocess.run(["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
                                "--disable-background-networking", "--disable-component-update", "--disable-sync",
                                f"--user-data-dir={profile}", "--dump-dom",
                                "file://" + os.path.join(self.base, "report.html")],
                               capture_output=True, text=True, timeout=60)
        finally:
            shutil.rmtree(profile, ignore_errors=True)
        self.assertEqual(r.returncode, 0, r.stderr[-2000:])
        dom = Page(r.stdout)
        self.assertGreater(len(dom.blocks), 3, r.stdout[:500])
        assert_safe_page(self, dom, [self.ok, self.ok2, self.ok])
        self.assertEqual(re.findall(r"<a\s[^>]*href=\"(?![#]|images/)", r.stdout), [])
        self.assertEqual(len(re.findall(r"<img\s[^>]*src=\"data:", r.stdout)), 3)


SWEEP_NAME = "[click me](javascript:alert`1`) ![x](/etc/hostname) | *b* <script>x</script> $x$"
SIZE_LABELS = ["1|0k", "![x](/etc/hostname)"]
MODE_LABELS = ["[c](javascript:alert(1))", "<b>$\\frac{a}$</b> | x"]
IDS = ["psv_x", "p[s](v)|x"]
STAGES = ["tra|verse", "b*u*i*l*d", "total"]
COUNTERS = ["c|1"]
SOURCE = "![x](/etc/hostname) [y](data:text/html,hi) | z <i>w</i> `q`"


def fake_sweep(directory):
    """plan.json and sweep.csv as `sweep merge` writes them: 2 × 2 runs of two ids, one more run failed."""
    plan = {"name": SWEEP_NAME,
            "merge": {"ratios": [f"{IDS[1]}/{IDS[0]}"], "stages": STAGES, "counters": COUNTERS,
                      "paper": {"source": SOURCE, "times_ms": {IDS[1]: 3, IDS[0]: 1.5}}},
            "axes": [{"name": "size", "scale": "triangles", "labels": SIZE_LABELS},
                     {"name": "mode", "scale": "category", "labels": MODE_LABELS}],
            "runs": []}
    rows, index = [], 0
    for k, size in enumerate(SIZE_LABELS):
        for mode in MODE_LABELS:
            run = f"r{index}"
            tris = 1000 * (k + 1) ** 2
            plan["runs"].append({"index": index, "id": run, "status": "complete", "renderer": "llvmpipe (LLVM | x)",
                                 "stage_time_source": "wall", "axes": {"size": size, "mode": mode}})
            for j, aid in enumerate(IDS):
                values = {"time_ms.tra|verse": 1 + tris * 1e-3 * (j + 1), "time_ms.b*u*i*l*d": 0.5 + j,
                          "time_ms.total": 1.5 + j + tris * 1e-3 * (j + 1), "counters.c|1": 7 + k,
                          "memory_bytes": 2 ** 20, "accuracy.mismatch_ratio_max": 0.001 * j, "overflow": 0}
                for measure, v in values.items():
                    rows.append([run, index, size, mode, tris, 4096, aid, "psv", measure, "time", v])
            index += 1
    plan["runs"].append({"index": index, "id": "r|4 *x*", "status": "failed", "axes": {"size": SIZE_LABELS[1], "mode": MODE_LABELS[1]}})
    with open(os.path.join(directory, "plan.json"), "w", encoding="utf-8") as f:
        json.dump(plan, f, indent=2)
    with open(os.path.join(directory, "sweep.csv"), "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(["run", "index", "size", "mode", "triangles", "pixels", "id", "algorithm", "measure", "kind", "value"])
        w.writerows(rows)


class SweepReportTest(unittest.TestCase):
    def sweep(self, python, plots):
        directory = tempfile.mkdtemp(prefix="sweep-text-")
        self.addCleanup(shutil.rmtree, directory, True)
        fake_sweep(directory)
        r = subprocess.run([python, os.path.join(SCRIPTS, "sweep_report.py"), directory] + ([] if plots else ["--no-plots"]),
                           capture_output=True, text=True, timeout=120)
        self.assertEqual(r.returncode, 0, r.stderr[-3000:])
        with open(os.path.join(directory, "sweep.md"), encoding="utf-8") as f:
            md = f.read()
        with open(os.path.join(directory, "sweep.html"), encoding="utf-8") as f:
            page = Page(f.read())
        return directory, md, page

    def check_text(self, md, page):
        self.assertEqual(page.texts("h1"), ["Sweep " + SWEEP_NAME])
        self.assertIn(f"{IDS[1]} / {IDS[0]}: total time per frame, same run", page.texts("h2"))
        self.assertIn("By size", page.texts("h2"))
        paper = [p for p in page.texts("p") if p.startswith("Paper: ")]
        self.assertEqual(paper, [f"Paper: {SOURCE}: {IDS[1]} 3 ms, {IDS[0]} 1.5 ms, ratio 2.00."])
        items = page.texts("li")
        self.assertIn("renderer: llvmpipe (LLVM | x)", items)
        self.assertIn("axes: size (triangles): " + ", ".join(SIZE_LABELS) + "; mode (category): " + ", ".join(MODE_LABELS), items)
        self.assertIn(f"run 4 r|4 *x* (size={SIZE_LABELS[1]} mode={MODE_LABELS[1]}): failed", items)
        # Every table keeps its header's columns, and the hostile texts are whole cells.
        self.assertEqual(len(page.tables), 2 + 1 + 1)  # by size, by mode, the ratio, the size fit
        for table in page.tables:
            self.assertTrue(all(len(row) == len(table[0]) for row in table), table)
        by_size = page.tables[0]
        self.assertEqual(by_size[0], ["mode", "id", "size", "triangles"] + STAGES + COUNTERS +
                         ["memory (MiB)", "mismatch (worst frame)", "overflow"])
        self.assertEqual(len(by_size), 1 + 2 * 2 * 2)
        first = by_size[1]
        self.assertEqual(first[:4], [MODE_LABELS[0], IDS[0], SIZE_LABELS[0], "1,000"])
        self.assertEqual(first[4:8], ["2.00", "0.50", "2.50", "7.00"])  # numbers under their own headers
        self.assertEqual(page.tables[2][0], ["size", "mode", "triangles", f"{IDS[1]} / {IDS[0]}", "paper", "ours / paper"])
        self.assertEqual({row[1] for row in page.tables[3][1:]}, set(IDS))
        self.assertEqual({row[2] for row in page.tables[3][1:]}, set(STAGES))
        # The markdown itself: no image or link syntax, one line per row.
        text = md.split("\n## Figures\n")[0]
        self.assertNotIn("![", text)
        self.assertNotIn("](", text)
        for table in re.findall(r"(?:^\|.*\n)+", md, flags=re.M):
            counts = {len(report_html.cells(line)) for line in table.splitlines()}
            self.assertEqual(len(counts), 1, table)

    def test_tables_only(self):
        _, md, page = self.sweep(sys.executable, plots=False)
        self.check_text(md, page)
        assert_safe_page(self, page, [])

    def test_with_plots(self):
        python = python_with_matplotlib()
        if python is None:
            self.skipTest("no python3 with matplotlib")
        directory, md, page = self.sweep(python, plots=True)
        self.check_text(md, page)
        shown_images = []
        for name in ("sweep_size.png", "sweep_mode.png", "sweep_stages.png"):
            with open(os.path.join(directory, name), "rb") as f:
                shown_images.append(f.read())
        assert_safe_page(self, page, shown_images)
        self.assertEqual(len(re.findall(r"^!\[", md, flags=re.M)), 3)


class PlantedTargetTest(unittest.TestCase):
    """A link, FIFO or directory planted at a report's name in the folder (sweep.md, sweep.html, a
    plot): the script refuses it in one line with status 2, promptly, and writes nothing through it."""

    def run_with(self, planted, make):
        directory = tempfile.mkdtemp(prefix="sweep-planted-")
        self.addCleanup(shutil.rmtree, directory, True)
        fake_sweep(directory)
        victim = os.path.join(directory + "-victim")
        with open(victim, "w", encoding="utf-8") as f:
            f.write("precious")
        self.addCleanup(lambda: os.path.exists(victim) and os.unlink(victim))
        make(os.path.join(directory, planted), victim)
        start = time.monotonic()
        r = subprocess.run([sys.executable, os.path.join(SCRIPTS, "sweep_report.py"), directory, "--no-plots"],
                           capture_output=True, text=True, timeout=60)
        self.assertLess(time.monotonic() - start, 30)
        with open(victim, encoding="utf-8") as f:
            self.assertEqual(f.read(), "precious")
        return r

    def test_link_at_sweep_md(self):
        r = self.run_with("sweep.md", lambda path, victim: os.symlink(victim, path))
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
        self.assertIn("not a regular file", r.stderr)

    def test_link_at_sweep_html(self):
        r = self.run_with("sweep.html", lambda path, victim: os.symlink(victim, path))
        self.assertEqual(r.returncode, 2, r.stderr)

    def test_fifo_at_sweep_md(self):
        r = self.run_with("sweep.md", lambda path, victim: os.mkfifo(path))
        self.assertEqual(r.returncode, 2, r.stderr)

    def test_writes_are_atomic_and_leave_no_temporary(self):
        r = self.run_with("unrelated.txt", lambda path, victim: None)
        self.assertEqual(r.returncode, 0, r.stderr)
        directory = os.path.dirname(os.path.abspath(r.args[2]) + "/x")
        self.assertEqual([n for n in os.listdir(directory) if n.endswith(".tmp")], [])


class RunReportTest(unittest.TestCase):
    """plot_results.py (and frame_figures.py) on a fake run whose ids, stages and heat map names are hostile."""

    def test_plot_results(self):
        python = python_with_matplotlib()
        if python is None:
            self.skipTest("no python3 with matplotlib")
        # "[1]" in the folder: read as a glob pattern, it lost the contact sheet and labelled heat maps (fifth probe).
        directory = tempfile.mkdtemp(prefix="run-text-[1]-")
        self.addCleanup(shutil.rmtree, directory, True)
        ids = ["reference", "$\\frac{1}$", "[click me](javascript:alert`1`)", "a|b _c_"]
        with open(os.path.join(directory, "frames.csv"), "w", newline="", encoding="utf-8") as f:
            w = csv.writer(f)
            w.writerow(["id", "algorithm", "frame", "stage", "gpu_ms", "cpu_ms", "mismatch_ratio"])
            for frame in range(3):
                for k, aid in enumerate(ids):
                    w.writerow([aid, "reference" if k == 0 else "psv", frame, "tra$ve|rse$", "", 1 + k, ""])
                    w.writerow([aid, "reference" if k == 0 else "psv", frame, "total", "", 2 + k, 0.001 * k])
        images = os.path.join(directory, "images")
        os.mkdir(images)
        heat_id, heat_name = "x$y$", "n$a|b$"
        for name in ("reference_f0000_shaded.png", f"{heat_id}_f0000_shaded.png", f"{heat_id}_f0000_heat_{heat_name}.png"):
            with open(os.path.join(images, name), "wb") as f:
                f.write(png_bytes(16, 12))
        legend = {"clipped_pixels": 0, "data_max": 3.0, "frame": 0, "height": 12, "width": 16, "id": heat_id,
                  "image": f"{heat_id}_f0000_heat_{heat_name}.png", "max": 3.0, "min": 0.0, "name": heat_name,
                  "nonzero_pixels": 10, "ramp": [[0, 0, 0], [1, 1, 1]], "scale": "p99", "unit": "$u^$ nodes", "view_index": 0}
        with open(os.path.join(images, f"{heat_id}_f0000_heat_{heat_name}.json"), "w", encoding="utf-8") as f:
            json.dump(legend, f)
        title = "[click me](javascript:alert`1`) ![x](/etc/hostname) $x$ | y"
        with open(os.path.join(directory, "report.md"), "w", encoding="utf-8") as f:
            f.write(f"# {literal(title)}\n\n| id | mean |\n|---|---:|\n" +
                    "".join(f"| {literal(i)} | 1.00 |\n" for i in ids))
        r = subprocess.run([python, os.path.join(SCRIPTS, "plot_results.py"), directory, "wall"],
                           capture_output=True, text=True, timeout=120)
        self.assertEqual(r.returncode, 0, r.stderr[-3000:])
        with open(os.path.join(directory, "report.md"), encoding="utf-8") as f:
            md = f.read()
        with open(os.path.join(directory, "report.html"), encoding="utf-8") as f:
            page = Page(f.read())
        self.assertEqual(page.texts("h1"), [title])
        self.assertEqual([row[0] for row in page.tables[0][1:]], ids)
        # The run's own figures embedded, and the labelled heat map linked by a relative link.
        own = []
        for name in ("plot_frame_time.png", "plot_stages.png", "plot_accuracy.png", "contact_f0000.png"):
            with open(os.path.join(directory, name), "rb") as f:
                own.append(f.read())
        assert_safe_page(self, page, own)
        labelled = f"images/{heat_id}_f0000_heat_{heat_name}_labelled.png"
        self.assertTrue(os.path.exists(os.path.join(directory, labelled)))
        self.assertEqual([urllib.parse.unquote(h) for h in page.attrs("a", "href")], [labelled])
        self.assertIn(f"Heat maps one by one: {heat_id} {heat_name}.", page.texts("p"))
        self.assertIn(f"[{literal(heat_id)} {literal(heat_name)}](", md)


class LogAxisTest(unittest.TestCase):
    """Thirteenth probe: with mathtext off for user text, matplotlib's log tick labels were drawn as
    their source, $\\mathdefault{10^{2}}$, on every sweep and history plot with a log axis; the
    fourteenth found history's symlog axis still did."""

    def test_log_ticks_are_plain_text(self):
        python = python_with_matplotlib()
        if python is None:
            self.skipTest("no python3 with matplotlib")
        code = ("import sys; sys.path.insert(0, sys.argv[1]); import matplotlib; matplotlib.use('Agg'); import plot_style; "
                "import matplotlib.pyplot as plt; fig, ax = plt.subplots(); ax.loglog([0.01, 3e5], [1, 2]); "
                "ax2 = fig.add_subplot(2, 1, 2); ax2.plot([0, 1], [-0.5, 2]); ax2.set_yscale('symlog', linthresh=1e-3); "
                "fig.canvas.draw(); print('|'.join(t.get_text() for t in ax.get_xticklabels() + ax.get_xticklabels(minor=True) + "
                "ax2.get_yticklabels()))")
        r = subprocess.run([python, "-c", code, SCRIPTS], capture_output=True, text=True, timeout=120)
        self.assertEqual(r.returncode, 0, r.stderr)
        labels = r.stdout.strip().split("|")
        self.assertNotIn("$", r.stdout)
        for want in ("10\u207b\u00b2", "1", "10", "10\u00b2", "10\u2075", "0", "\u221210\u207b\u00b9"):
            self.assertIn(want, labels)


def main():
    suite = unittest.defaultTestLoader.loadTestsFromModule(sys.modules[__name__])
    result = unittest.TextTestRunner(verbosity=2, stream=sys.stdout).run(suite)
    failed = len(result.failures) + len(result.errors) + len(result.unexpectedSuccesses)
    skipped = len(result.skipped)
    passed = result.testsRun - failed - skipped - len(result.expectedFailures)
    print(f"{passed} passed, {failed} failed, {skipped} skipped")
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
