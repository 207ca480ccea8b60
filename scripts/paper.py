"""Snakemake script: the manuscript's numbers (LaTeX macros) and its Markdown twin."""

from pathlib import Path

import pandas as pd

from alfa_bench.analysis.logs import log_to
from alfa_bench.analysis.paper import latex_keys, latex_macros, paper_numbers, render_markdown

sm = snakemake  # noqa: F821
log_to(sm.log[0])
numbers = paper_numbers(pd.read_csv(sm.input.comparison), pd.read_csv(sm.input.sweep))
unknown = latex_keys(Path(sm.input.tex).read_text()) - set(numbers)
if unknown:
    raise KeyError(f"{sm.input.tex} quotes results no run defines: {sorted(unknown)}")
Path(sm.output.macros).write_text(latex_macros(numbers))
Path(sm.output.markdown).write_text(
    render_markdown(Path(sm.input.markdown).read_text(), numbers, Path.cwd()))
