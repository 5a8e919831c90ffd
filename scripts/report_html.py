#!/usr/bin/env python3
"""A report's markdown (report.md, sweep.md) as one self-contained HTML page: every image embedded
as a data URI, tables as HTML tables, no script, no style sheet or font from elsewhere, so that it
opens from disk in any browser, moved or mailed alone. Links to other local files stay relative.

Handles the markdown these reports are written in: headings, paragraphs, "- " lists, pipe tables
(with "---:" alignment), images, links, **bold**, *italic*, `code`, backslash escapes and HTML
comments.

Usage: report_html.py REPORT.md [OUT.html]   (OUT defaults to REPORT.html)
"""
import base64
import html
import mimetypes
import os
import re
import sys

STYLE = """
body { font: 14px/1.45 system-ui, sans-serif; margin: 2em auto; max-width: 1400px; padding: 0 1em; color: #222; }
table { border-collapse: collapse; margin: 0.6em 0 1.2em; font-size: 12px; }
th, td { border: 1px solid #ccc; padding: 2px 6px; vertical-align: top; }
th { background: #f2f2f2; }
tr:nth-child(even) td { background: #fafafa; }
td.r, th.r { text-align: right; font-variant-numeric: tabular-nums; }
img { max-width: 100%; height: auto; display: block; margin: 0.4em 0 1em; border: 1px solid #ddd; }
code { background: #f4f4f4; padding: 0 3px; }
.missing { color: #b00; }
"""

INLINE = re.compile(r"\\(?P<esc>[\\`*_{}\[\]()#+\-.!|$<>])|!\[(?P<alt>[^\]]*)\]\((?P<src>[^)\s]+)\)|\[(?P<text>[^\]]+)\]\((?P<href>[^)\s]+)\)"
                    r"|`(?P<code>[^`]+)`|\*\*(?P<bold>.+?)\*\*|\*(?P<em>[^*\s][^*]*?)\*")


def data_uri(path):
    mime = mimetypes.guess_type(path)[0] or "application/octet-stream"
    with open(path, "rb") as f:
        return f"data:{mime};base64," + base64.b64encode(f.read()).decode("ascii")


def inline(text, base):
    """Markdown inline markup to HTML; everything else escaped."""
    out, pos = [], 0
    for m in INLINE.finditer(text):
        out.append(html.escape(text[pos:m.start()]))
        pos = m.end()
        if m["esc"] is not None:
            out.append(html.escape(m["esc"]))  # a backslash-escaped character stands for itself
        elif m["src"] is not None:
            path = os.path.join(base, m["src"])
            if os.path.exists(path):
                out.append(f'<img src="{data_uri(path)}" alt="{html.escape(m["alt"])}" title="{html.escape(m["alt"])}">')
            else:
                out.append(f'<span class="missing">[image missing: {html.escape(m["src"])}]</span>')
        elif m["href"] is not None:
            out.append(f'<a href="{html.escape(m["href"])}">{inline(m["text"], base)}</a>')
        elif m["code"] is not None:
            out.append(f"<code>{html.escape(m['code'])}</code>")
        elif m["bold"] is not None:
            out.append(f"<strong>{inline(m['bold'], base)}</strong>")
        else:
            out.append(f"<em>{inline(m['em'], base)}</em>")
    out.append(html.escape(text[pos:]))
    return "".join(out)


def cells(line):
    """A table row's cells; "\\|" is a pipe inside a cell, as in GitHub's markdown."""
    line = line.strip()
    if line.startswith("|"):
        line = line[1:]
    if line.endswith("|") and not line.endswith("\\|"):
        line = line[:-1]
    return [c.strip().replace("\\|", "|") for c in re.split(r"(?<!\\)\|", line)]


def table(lines, base):
    head, rule, body = cells(lines[0]), cells(lines[1]), [cells(l) for l in lines[2:]]
    right = [r.endswith(":") and not r.startswith(":") for r in rule]

    def row(tag, values):
        tds = "".join(f'<{tag}{" class=r" if k < len(right) and right[k] else ""}>{inline(v, base)}</{tag}>'
                      for k, v in enumerate(values))
        return f"<tr>{tds}</tr>"
    return ["<table>", "<thead>" + row("th", head) + "</thead>", "<tbody>"] + [row("td", r) for r in body] + ["</tbody></table>"]


def is_rule(line):
    return bool(re.fullmatch(r"\|?\s*:?-{3,}:?\s*(\|\s*:?-{3,}:?\s*)*\|?", line.strip()))


def to_html(markdown, base, title):
    lines = markdown.split("\n")
    out, para, k = [], [], 0

    def flush():
        if para:
            out.append("<p>" + inline(" ".join(para), base) + "</p>")
            para.clear()
    while k < len(lines):
        line = lines[k]
        stripped = line.strip()
        if stripped.startswith("<!--"):
            flush()
            while k < len(lines) and "-->" not in lines[k]:
                k += 1
            k += 1
            continue
        m = re.match(r"^(#{1,6})\s+(.*)$", line)
        if m:
            flush()
            n = len(m[1])
            out.append(f"<h{n}>{inline(m[2], base)}</h{n}>")
        elif stripped.startswith("|") and k + 1 < len(lines) and is_rule(lines[k + 1]):
            flush()
            block = [line, lines[k + 1]]
            k += 2
            while k < len(lines) and lines[k].strip().startswith("|"):
                block.append(lines[k])
                k += 1
            out += table(block, base)
            continue
        elif re.match(r"^\s*[-*] ", line):
            flush()
            out.append("<ul>")
            while k < len(lines) and re.match(r"^\s*[-*] ", lines[k]):
                out.append("<li>" + inline(re.sub(r"^\s*[-*] ", "", lines[k]), base) + "</li>")
                k += 1
            out.append("</ul>")
            continue
        elif not stripped:
            flush()
        elif re.fullmatch(r"!\[[^\]]*\]\([^)\s]+\)", stripped):
            flush()
            out.append(inline(stripped, base))  # an image on its own line is a block, not inside a paragraph
        else:
            para.append(stripped)
        k += 1
    flush()
    return ("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
            f"<title>{html.escape(title)}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n"
            + "\n".join(out) + "\n</body>\n</html>\n")


def convert(markdown_path, html_path):
    with open(markdown_path, encoding="utf-8") as f:
        text = f.read()
    first = next((l for l in text.split("\n") if l.startswith("# ")), "# report")
    page = to_html(text, os.path.dirname(os.path.abspath(markdown_path)), first[2:].strip())
    # Written beside and renamed: a reader never sees half a page.
    tmp = html_path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(page)
    os.replace(tmp, html_path)


if __name__ == "__main__":
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    convert(sys.argv[1], sys.argv[2] if len(sys.argv) == 3 else os.path.splitext(sys.argv[1])[0] + ".html")
