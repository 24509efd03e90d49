"""Shared constants of the solver's dynamics tests."""

import numpy as np

G = 9.81  # m s-2
R = 0.0125  # m, circumscribed radius of the paper's smallest particles
PENTAGON_ON_EDGE = np.radians(-54.0)  # vertices at -54 + 72 k degrees: an edge at the bottom
EXACT = dict(tolerance=1e-12, max_tolerance=1e-12, max_iterations=100_000)
"""NLGS settings for analytic checks: converge to round-off."""
