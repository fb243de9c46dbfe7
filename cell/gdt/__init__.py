"""Datums, alignment and GD&T evaluation (issue 19; docs/gdt.md).

``datums.py`` (the cell file's datums and tolerances, validated), ``align.py`` (datum reference
frames and best-fit alignments from measured holes, vectorised over Monte Carlo draws),
``montecarlo.py`` (the draws of the measured centres and the GUM Supplement 1 coverage),
``decide.py`` (ISO 14253-1 decisions against a zone or a pair of limits), ``evaluate.py`` (a
run's results into the report's ``datum_reference_frames``, ``placement`` and
``characteristics``) and ``html.py`` (their part of ``report.html``).
"""
