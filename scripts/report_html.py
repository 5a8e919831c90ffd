#!/usr/bin/env python3
"""A report's markdown (report.md, sweep.md) as one self-contained HTML page: every image embedded
as a data URI, tables as HTML tables, no script, no style sheet or font from elsewhere, so that it
opens from disk in any browser, moved or mailed alone. Links to other local files stay relative.

Handles the markdown these reports are written in: headings, paragraphs, "- " lists, pipe tables
(with "---:" alignment), images, links, **bold**, *italic*, `code`, backslash escapes and HTML
comments.

Safe whatever markdown it is handed (names in reports come from users, and pages are mailed):
  - every backslash-escaped ASCII punctuation character stands for itself (CommonMark); literal()
    below writes user text that way, and writers put every piece of it through literal();
  - an image is embedded only if its path is relative (no scheme, no leading "/", no ".."
    component, no backslash, blank or control character, checked after %-decoding), stays inside
    the report's folder once symbolic links are resolved, ends in .png, is a regular file (no
    device, FIFO or directory) that starts like a PNG and holds at most MAX_IMAGE_BYTES (32 MiB,
    never read further). Otherwise it shows as "[image not embedded: NAME]" (or "[image missing:
    NAME]" for a well-formed path with no file), NAME escaped and cut to MAX_NAME_CHARS;
  - a link stays a link only if it names a #fragment or passes the same path rules (the file need
    not exist); any other (javascript:, data:, file:, http:, //host, /abs, ../, in any spelling)
    is shown as its text alone;
  - all other text is HTML-escaped: no raw HTML, script or entity gets through.

Usage: report_html.py REPORT.md [OUT.html]   (OUT defaults to REPORT.html)
"""
import base64
import html
import os
import re
import stat
import sys
import urllib.parse

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from safe_files import read_text, write_text  # noqa: E402

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

# --- User text into Markdown ------------------------------------------------------------------

MARKUP = "\\`*[]()!|<>#~&{}+-.=$:"


def literal(text):
    """`text` (a name, id, label, stage, ratio, source: anything a user wrote) as Markdown that
    renders as exactly that text in a heading, a paragraph or a pipe-table cell.

    The rule, the same as framework/core/Text.cpp's markdownLiteral() writes report.md with:
      - each of these 22 characters gets a backslash before it:
            \\ ` * [ ] ( ) ! | < > # ~ & { } + - . = $ :
      - '_' gets one too, unless both its neighbours are ASCII letters or digits (CommonMark never
        makes emphasis of an intraword '_', so ids such as psv_stack stay as they are);
      - a control character (U+0000-U+001F, U+007F) becomes U+FFFD, so no line or cell can end
        inside; so do U+0080-U+009F, U+2028, U+2029 and lone surrogates, which the C++ side refuses
        before they get here (userTextProblem);
      - every other character is kept as it is.
    Leading or trailing blanks are not protected: Markdown trims them in headings and cells.
    """
    text = str(text)
    out = []
    last = len(text) - 1
    for i, c in enumerate(text):
        o = ord(c)
        if o < 0x20 or 0x7F <= o <= 0x9F or o in (0x2028, 0x2029) or 0xD800 <= o <= 0xDFFF:
            out.append("\ufffd")
        elif c in MARKUP:
            out.append("\\" + c)
        elif c == "_" and not (0 < i < last and _ascii_alnum(text[i - 1]) and _ascii_alnum(text[i + 1])):
            out.append("\\_")
        else:
            out.append(c)
    return "".join(out)


def _ascii_alnum(c):
    return c.isascii() and c.isalnum()


def link_target(path):
    """A relative file path (as os.path.relpath gives it) as a link or image destination: every
    byte but letters, digits, "/" and "_.-~" percent-encoded, so that no space, parenthesis or
    markup in a name built from user text can end or change the link."""
    return urllib.parse.quote(path, safe="/")


# --- Markdown to HTML ---------------------------------------------------------------------------

# What an image may be: a PNG (every figure these reports draw is one) inside the report's folder.
IMAGE_EXTENSIONS = {".png": "image/png"}
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
MAX_IMAGE_BYTES = 32 * 2 ** 20
MAX_ALT_CHARS = 300    # alt and title text of an image, the page title
MAX_NAME_CHARS = 200   # a path named in "[image not embedded: ...]"
MAX_DEPTH = 8          # nesting of bold, italic and link text

ESCAPE = re.compile(r"\\([!-/:-@\[-`{-~])")  # CommonMark: any ASCII punctuation may be escaped
_DEST = r"(?:\\.|[^)\s\\])+"
_LABEL = r"(?:\\.|[^\]\\])"
INLINE = re.compile(r"\\(?P<esc>[!-/:-@\[-`{-~])"
                    r"|!\[(?P<alt>" + _LABEL + r"*)\]\((?P<src>" + _DEST + r")\)"
                    r"|\[(?P<text>" + _LABEL + r"+)\]\((?P<href>" + _DEST + r")\)"
                    r"|`(?P<code>[^`]+)`"
                    r"|\*\*(?P<bold>(?:\\.|[^\\])+?)\*\*"
                    r"|\*(?P<em>(?:\\.|[^*\s\\])(?:\\.|[^*\\])*?)\*")
IMAGE_LINE = re.compile(r"!\[" + _LABEL + r"*\]\(" + _DEST + r"\)")


def unescape(text):
    """Markdown's backslash escapes undone: each escaped ASCII punctuation character stands for itself."""
    return ESCAPE.sub(r"\1", text)


def bounded(text, limit):
    return text if len(text) <= limit else text[:limit] + "…"


def _unsafe_char(c):
    o = ord(c)
    return o <= 0x20 or 0x7F <= o <= 0x9F or c in "\\\u2028\u2029" or c.isspace()


def local_path(ref, base):
    """The real path inside `base` that a link or image destination names, or None where it is not a
    plain relative path that stays inside: a scheme of any spelling (javascript:, JaVaScRiPt:,
    data:, file:, C:; any ":" at all), a leading "/" (absolute or //host), a ".." component, a
    backslash, a blank or a control character (also as %-escapes: the path is checked as decoded,
    where only %20, a space, is allowed), or a symbolic link
    anywhere on the way that leads out of `base`. A "?query" or "#fragment" after the path is
    allowed and not part of it."""
    if base is None or not ref or len(ref) > 2000 or ":" in ref or any(_unsafe_char(c) for c in ref):
        return None
    path = re.split(r"[?#]", ref, maxsplit=1)[0]
    try:
        decoded = urllib.parse.unquote(path, errors="strict") if "%" in path else path
    except UnicodeError:  # %-escapes that are not UTF-8
        return None
    # A blank in a file name is written %20 (link_target) and allowed; no other blank or control.
    if (not decoded or decoded.startswith("/") or ":" in decoded or any(_unsafe_char(c) and c != " " for c in decoded)
            or ".." in decoded.split("/")):
        return None
    root = os.path.realpath(base)
    full = os.path.realpath(os.path.join(root, decoded))
    if full == root or os.path.commonpath([root, full]) != root:
        return None
    return full


def safe_href(href, base):
    """`href` where it may stay a link: a #fragment of this page, or a relative path inside the
    report's folder (local_path); None otherwise."""
    if href.startswith("#"):
        return href if not any(_unsafe_char(c) for c in href) and len(href) <= 2000 else None
    try:
        return href if local_path(href, base) else None
    except (ValueError, UnicodeError, OSError):
        return None


def read_image(src, base):
    """The data URI of an image a report shows, or a reason it is not embedded: "missing" (a
    well-formed path with no file) or "refused" (anything else but a regular PNG file of at most
    MAX_IMAGE_BYTES inside the report's folder)."""
    try:
        path = local_path(src, base)
    except (ValueError, UnicodeError, OSError):
        path = None
    if path is None:
        return None, "refused"
    mime = IMAGE_EXTENSIONS.get(os.path.splitext(path)[1].lower())
    if mime is None:
        return None, "refused"
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return None, "missing"
    except OSError:
        return None, "refused"
    if not stat.S_ISREG(st.st_mode) or st.st_size > MAX_IMAGE_BYTES:
        return None, "refused"
    try:
        # realpath left no link on the way; O_NOFOLLOW and O_NONBLOCK keep a file swapped in since
        # (a link, a FIFO) from being followed or blocking, fstat from being read past its size.
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError:
        return None, "refused"
    with os.fdopen(fd, "rb") as f:
        st = os.fstat(f.fileno())
        if not stat.S_ISREG(st.st_mode) or st.st_size > MAX_IMAGE_BYTES:
            return None, "refused"
        data = f.read(MAX_IMAGE_BYTES + 1)
    if len(data) > MAX_IMAGE_BYTES or not data.startswith(PNG_SIGNATURE):
        return None, "refused"
    return f"data:{mime};base64," + base64.b64encode(data).decode("ascii"), None


def image(alt, src, base):
    name = html.escape(bounded(unescape(src), MAX_NAME_CHARS))
    uri, why = read_image(unescape(src), base)
    if uri is None:
        what = "image missing" if why == "missing" else "image not embedded"
        return f'<span class="missing">[{what}: {name}]</span>'
    alt = html.escape(bounded(unescape(alt), MAX_ALT_CHARS))
    return f'<img src="{uri}" alt="{alt}" title="{alt}">'


def inline(text, base, depth=0):
    """Markdown inline markup to HTML; everything else escaped. Images are embedded and links kept
    only where they name files inside the report's folder (local_path)."""
    if depth > MAX_DEPTH:
        return html.escape(unescape(text))
    out, pos = [], 0
    for m in INLINE.finditer(text):
        out.append(html.escape(text[pos:m.start()]))
        pos = m.end()
        if m["esc"] is not None:
            out.append(html.escape(m["esc"]))  # a backslash-escaped character stands for itself
        elif m["src"] is not None:
            out.append(image(m["alt"], m["src"], base))
        elif m["href"] is not None:
            label = inline(m["text"], base, depth + 1)
            href = safe_href(unescape(m["href"]), base)
            # Anything else (a scheme, an absolute path, a way out of the folder) is its text alone.
            out.append(f'<a href="{html.escape(href)}">{label}</a>' if href else label)
        elif m["code"] is not None:
            out.append(f"<code>{html.escape(m['code'])}</code>")
        elif m["bold"] is not None:
            out.append(f"<strong>{inline(m['bold'], base, depth + 1)}</strong>")
        else:
            out.append(f"<em>{inline(m['em'], base, depth + 1)}</em>")
    out.append(html.escape(text[pos:]))
    return "".join(out)


def cells(line):
    """A table row's cells, split at each "|" that is not backslash-escaped (a "\\\\" before a "|"
    is an escaped backslash, so that "|" does split); as in GitHub's markdown, "\\|" is then a pipe
    inside the cell (also inside `code`), and the cell's other escapes are undone by inline()."""
    line = line.strip()
    parts, cur, i, split_at_end = [], [], 0, False
    while i < len(line):
        c = line[i]
        if c == "\\" and i + 1 < len(line):
            cur.append(line[i:i + 2])
            i += 2
            continue
        if c == "|":
            parts.append("".join(cur))
            cur = []
            split_at_end = i == len(line) - 1
        else:
            cur.append(c)
        i += 1
    parts.append("".join(cur))
    if line.startswith("|"):
        parts = parts[1:]
    if split_at_end and len(parts) > 1:
        parts = parts[:-1]
    return [c.strip().replace("\\|", "|") for c in parts]


def table(lines, base):
    head, rule, body = cells(lines[0]), cells(lines[1]), [cells(l) for l in lines[2:]]
    right = [r.endswith(":") and not r.startswith(":") for r in rule]
    # As in GitHub's markdown, every row has the header's cells: missing ones empty, extra ones dropped.
    body = [(r + [""] * len(head))[:len(head)] for r in body]

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
        elif IMAGE_LINE.fullmatch(stripped):
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
    text = read_text(markdown_path)
    first = next((l for l in text.split("\n") if l.startswith("# ")), "# report")
    title = bounded(unescape(first[2:].strip()), MAX_ALT_CHARS)
    page = to_html(text, os.path.dirname(os.path.abspath(markdown_path)), title)
    write_text(html_path, page)  # atomic: a reader never sees half a page


if __name__ == "__main__":
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    convert(sys.argv[1], sys.argv[2] if len(sys.argv) == 3 else os.path.splitext(sys.argv[1])[0] + ".html")
