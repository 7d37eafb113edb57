"""The results report (``nmsm report RESULTS_DIR``): one self-contained HTML page.

* :mod:`nmsm.report.tables`  tables per kind of results folder (JMP, analysis, MTP, NCP,
  GCP, TO/VO/DO) and the example's known-answer comparison;
* :mod:`nmsm.report.html`    finds the stages of a results tree, draws their figures
  (:mod:`nmsm.plots`) and writes the page with the PNGs embedded.
"""
