"""Past studies of the solver: their scripts, their results and this folder's README.md, an
index of what each found. Run a script with ``python -m benchmarks.archive.<name>``."""
