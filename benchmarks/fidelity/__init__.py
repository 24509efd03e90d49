"""The fidelity study: which preparation and counting reproduce the paper's values
(``python -m benchmarks.fidelity``; docs/fidelity.md reads its RESULTS.md)."""
