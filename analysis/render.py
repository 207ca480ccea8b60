"""Plain renderings of tables: cells, Markdown and LaTeX (booktabs).

A table is a list of :data:`Section`: a title (with `code` marked), a header and rows
of cells, each already text (:func:`fmt`)."""

from __future__ import annotations

import math

__all__ = ["Section", "fmt", "latex_escape", "latex_tables", "markdown"]


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
