"""Markdown tables and a minimal Markdown -> self-contained HTML converter for the report."""

from __future__ import annotations

import base64
import html
import re
from pathlib import Path

import numpy as np

DIGITS = 4  # significant digits of every number in the report unless a column asks for more


def num(v, digits: int = DIGITS) -> str:
    """The one number formatter of walkerlab's printed text, report and tables.

    ``digits`` significant digits (scientific notation below 1e-3 and from 1e6); integers,
    and floats holding an integer (counts stored as floats), print as integers (``0``, not
    ``0.000``); booleans as yes/no; non-finite values as a dash.  Numpy scalars and 0-d
    arrays are accepted.
    """
    if isinstance(v, np.ndarray) and v.ndim == 0:
        v = v[()]
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    v = float(v)
    if not np.isfinite(v):
        return "—"
    if v.is_integer() and abs(v) < 1e6:
        return str(int(v))  # counts stored as floats (and 0, -0)
    if abs(v) < 1e-3 or abs(v) >= 1e6:
        return f"{v:.{max(1, digits - 1)}e}"
    return f"{v:#.{digits}g}".rstrip(".")


def printed(v) -> str:
    """A published number with the digits it was printed with (no padding; at most 10
    significant digits)."""
    return f"{float(v):.10g}" if np.isfinite(float(v)) else "—"


def sig_digits(text: str) -> int:
    """Significant digits of a number as written (``"-0.199473"`` -> 6, ``"0.0342"`` -> 3)."""
    mant = text.lower().split("e")[0].lstrip("+-").replace(".", "").lstrip("0")
    return max(1, len(mant))


def details(summary: str, body: str) -> list[str]:
    """A folded block (``<details>``) around Markdown ``body`` (works in HTML and on GitHub)."""
    return ["<details>", f"<summary>{summary}</summary>", "", body, "", "</details>", ""]


def table(header: list[str], rows: list[list], digits: int = DIGITS) -> str:
    """A Markdown table; floats with ``digits`` significant digits, non-finite as a dash."""
    def cell(v):
        if isinstance(v, (float, np.floating)):
            return num(v, digits)
        return str(v)
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(cell(v) for v in r) + " |" for r in rows]
    return "\n".join(lines)


def to_html(md: str, base: Path) -> str:
    """Minimal Markdown -> self-contained HTML (tables, headings, lists, images embedded)."""
    body = []
    in_table = in_code = False
    for line in md.splitlines():
        if line.startswith("```"):
            body.append("</pre>" if in_code else "<pre>")
            in_code = not in_code
            continue
        if in_code:
            body.append(html.escape(line))
            continue
        if line.startswith("|"):
            cells = [c.strip() for c in line.strip("|").split("|")]
            if set(line.replace("|", "").strip()) <= {"-"}:
                continue
            if not in_table:
                body.append("<table>")
                in_table = True
                body.append("<tr>" + "".join(f"<th>{inline(c)}</th>" for c in cells) + "</tr>")
            else:
                body.append("<tr>" + "".join(f"<td>{inline(c)}</td>" for c in cells) + "</tr>")
            continue
        if in_table:
            body.append("</table>")
            in_table = False
        if line.startswith(("<details", "</details", "<summary")):
            body.append(line)
        elif line.startswith("!["):
            cap = line[2:line.rindex("](")]
            src = line[line.rindex("](") + 2:-1]
            data = base64.b64encode((base / src).read_bytes()).decode()
            mime = "image/gif" if src.endswith(".gif") else "image/png"
            body.append(f'<img alt="{html.escape(cap)}" src="data:{mime};base64,{data}" '
                        'style="max-width:100%">')
        elif line.startswith("#"):
            lvl = len(line) - len(line.lstrip("#"))
            body.append(f"<h{lvl}>{inline(line[lvl:].strip())}</h{lvl}>")
        elif line.startswith("- "):
            body.append(f"<li>{inline(line[2:])}</li>")
        elif line.strip():
            body.append(f"<p>{inline(line)}</p>")
    if in_table:
        body.append("</table>")
    style = ("body{font-family:sans-serif;max-width:1100px;margin:auto;padding:1em}"
             "table{border-collapse:collapse;font-size:90%}td,th{border:1px solid #ccc;"
             "padding:3px 6px}pre{background:#f6f6f6;padding:.5em;font-size:80%}")
    return ("<!doctype html><html><head><meta charset='utf-8'><title>walkerlab report</title>"
            f"<style>{style}</style></head><body>" + "\n".join(body) + "</body></html>")


def text(s: str) -> str:
    """Free text from a scene (``source:``) as one line of Markdown: HTML characters escaped
    (``<script>`` is shown, never run, by a Markdown viewer), line breaks as spaces."""
    return html.escape(" ".join(str(s).split()), quote=False)


def inline(s: str) -> str:
    s = html.escape(html.unescape(s))  # entities of the Markdown (see text) shown as such
    s = re.sub(r"\*\*(.+?)\*\*", r"<b>\1</b>", s)
    s = re.sub(r"`(.+?)`", r"<code>\1</code>", s)
    s = re.sub(r"\*(.+?)\*", r"<i>\1</i>", s)
    return s
