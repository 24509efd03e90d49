"""Shared constants of the solver's dynamics tests."""

import warnings

import numpy as np

from grainview.contract.errors import ConvergenceWarning

G = 9.81  # m s-2
R = 0.0125  # m, circumscribed radius of the paper's smallest particles
PENTAGON_ON_EDGE = np.radians(-54.0)  # vertices at -54 + 72 k degrees: an edge at the bottom
EXACT = dict(tolerance=1e-12, max_tolerance=1e-12, max_iterations=100_000)
"""NLGS settings for analytic checks: converge to round-off."""


def compacted_problem(seed):
    """The contact problem of the next step of 120 pentagons compacted under 10 kPa (seed
    ``seed``; a stress-driven right wall) with plain NLGS sweeps, so that the problem is fixed
    whatever the solver's default: (sim, problem, warm-start impulses (P, 2), free velocities
    (B, 2), free angular velocities (B,)). A few compaction steps hit the sweep cap: not what
    the tests using it check."""
    from solver import compaction_sample, isotropic_compaction

    sim = compaction_sample(120, "pentagon", seed=seed, acceleration="off")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        isotropic_compaction(sim)
    posed = sim.contact_problem()
    pn, pt, vx, vy, w = posed.state
    return sim, posed.problem, np.stack([pn, pt], -1), np.stack([vx, vy], -1), w
