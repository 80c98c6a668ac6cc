"""The thesis reproduction page: the thesis's claims and numbers beside ours, with computed verdicts.

``albot1 report results/thesis`` writes ``reports/thesis/README.md`` through
:func:`albot1.report.thesis.page.write_thesis_page` (docs/thesis-reproduction.md).
"""
