"""The application: what a user runs on whole files and studies, built on the analysis and the
figures — the report of a run (:mod:`~grainview.app.report`) and of an ensemble
(:mod:`~grainview.app.ensemble_report`), a file's summary from netCDF4 alone
(:mod:`~grainview.app.file_summary`, ``grainview info``), the solver's convergence counts in words
(:mod:`~grainview.app.convergence`) and the numba cache's warm-up (:mod:`~grainview.app.warmup`).
"""
