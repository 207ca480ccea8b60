"""Plain renderings of tables: cells, Markdown and LaTeX (booktabs).

A table is a list of :data:`Section`: a title (with `code` marked), a header and rows
of cells, each already text (:func:`fmt`)."""

from __future__ import annotations

import html
import math
import re

__all__ = ["Section", "fmt", "latex_escape", "latex_tables", "markdown", "markdown_html"]


def fmt(v, pct=False, digits=2) -> str:
    """A table cell: ``-`` for a missing value, a fraction as a percentage with ``pct``."""
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "-"
    if isinstance(v, float):
        return f"{100 * v:.{digits}f}" if pct else f"{v:.{digits}f}"
    return str(v)


Section = tuple[str, list[str], list[list[str]]]  # title (`code` marked), header, rows


def markdown(sections: list[Section]) -> str:
    """Markdown tables, one per section, each under its title."""
    out = []
    for title, header, rows in sections:
        lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
        lines += ["| " + " | ".join(r) + " |" for r in rows]
        out.append(f"### {title}\n\n" + "\n".join(lines) + "\n")
    return "\n".join(out)


_LATEX_ESCAPES = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$",
                  "#": r"\#", "_": r"\_", "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}",
                  "^": r"\textasciicircum{}"}


def latex_escape(text: str) -> str:
    """Escape ``text`` for LaTeX; `code` becomes \\texttt{code}."""
    parts = text.split("`")
    esc = ["".join(_LATEX_ESCAPES.get(ch, ch) for ch in part) for part in parts]
    return "".join(rf"\texttt{{{e}}}" if i % 2 else e for i, e in enumerate(esc))


_SHRINK = r"\resizebox{\ifdim\width>\linewidth\linewidth\else\width\fi}{!}{%"


def latex_tables(sections: list[Section], label: str) -> str:
    """One booktabs table float per section, labelled ``tab:<label>-<1, 2, ...>``, shrunk
    to the line width where wider (needs the graphicx and booktabs packages)."""
    out = []
    for i, (title, header, rows) in enumerate(sections, 1):
        spec = "l" * 3 + "r" * (len(header) - 3) if len(header) > 3 else "l" * len(header)
        lines = [r"\begin{table}[htbp]", r"\centering", r"\scriptsize",
                 rf"\caption{{{latex_escape(title)}}}\label{{tab:{label}-{i}}}", _SHRINK,
                 rf"\begin{{tabular}}{{{spec}}}", r"\toprule",
                 " & ".join(latex_escape(h) for h in header) + r" \\", r"\midrule"]
        lines += [" & ".join(latex_escape(c) for c in r) + r" \\" for r in rows]
        lines += [r"\bottomrule", r"\end{tabular}}", r"\end{table}"]
        out.append("\n".join(lines) + "\n")
    return "\n".join(out)


_INLINE = [(re.compile(r"\*\*(.+?)\*\*"), r"<strong>\1</strong>"),
           (re.compile(r"(?<![*\w])\*(?!\s)(.+?)\*(?!\w)"), r"<em>\1</em>"),
           (re.compile(r"`([^`]+)`"), r"<code>\1</code>")]


def _inline(text: str) -> str:
    text = html.escape(text, quote=False)
    for pattern, repl in _INLINE:
        text = pattern.sub(repl, text)
    return text


def _cells(row: list[str]) -> str:
    """A table row's cells; a row with only its first cell set (a block's title)
    spans the table."""
    if len(row) > 1 and not any(row[1:]):
        return f'<td colspan="{len(row)}">{_inline(row[0])}</td>'
    return "".join(f"<td>{_inline(c)}</td>" for c in row)


_STYLE = ("body{font-family:sans-serif;font-size:13px;margin:1em}"
          "table{border-collapse:collapse;margin-bottom:1.5em}"
          "td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}"
          "td:nth-child(-n+4),th{text-align:left}th{background:#f2f2f2}")


def markdown_html(text: str, title: str) -> str:
    """A standalone HTML page of ``text``, the Markdown this package writes (``###``
    titles, pipe tables, ``-`` lists, paragraphs, ``**``, ``*`` and backticks): what
    the Snakemake report shows inline, where it would offer a Markdown file only as a
    download."""
    out, para, items = [], [], []

    def flush():
        if para:
            out.append(f"<p>{_inline(' '.join(para))}</p>")
            para.clear()
        if items:
            out.append("<ul>" + "".join(f"<li>{_inline(i)}</li>" for i in items) + "</ul>")
            items.clear()

    lines = text.splitlines()
    k = 0
    while k < len(lines):
        line = lines[k].strip()
        if line.startswith("|"):
            flush()
            rows = []
            while k < len(lines) and lines[k].strip().startswith("|"):
                rows.append([c.strip() for c in lines[k].strip().strip("|").split("|")])
                k += 1
            body = rows[2:]
            out.append("<table><tr>" + "".join(f"<th>{_inline(c)}</th>" for c in rows[0])
                       + "</tr>" + "".join(f"<tr>{_cells(r)}</tr>" for r in body)
                       + "</table>")
            continue
        if line.startswith("#"):
            flush()
            level = min(len(line) - len(line.lstrip("#")), 6)
            out.append(f"<h{level}>{_inline(line.lstrip('#').strip())}</h{level}>")
        elif line.startswith("- "):
            if para:
                flush()
            items.append(line[2:])
        elif not line:
            flush()
        elif items:
            items[-1] += " " + line
        else:
            para.append(line)
        k += 1
    flush()
    return (f"<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>"
            f"{html.escape(title)}</title><style>{_STYLE}</style></head><body>\n"
            + "\n".join(out) + "\n</body></html>\n")
