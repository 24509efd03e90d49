"""The project's benchmarks: speed and accuracy of the solver and of the analysis.

A package, run with ``python -m`` from the repository root: ``python -m benchmarks`` measures
every current benchmark into its section file under ``benchmarks/results/`` and assembles
``benchmarks/RESULTS.md`` from them; ``python -m benchmarks.<name>`` runs one benchmark alone.
benchmarks/README.md lists the current benchmarks; ``benchmarks/archive/`` holds the past
studies, each with its results and an index.
"""
