"""The study at the paper's own size (Azéma et al. 2007, Sec. II.B: 14,400 pentagons and 10,000
disks): the top wall's speed that shears a larger sample at the strain rate of the study's 400
particles, the inertia numbers of a test, and the expected wall time of each stage from
measured costs.

Strain rate. The box's height grows as the square root of N at a fixed aspect ratio, so the
top wall of an N-particle sample moves at v(N) = 1 cm/s x sqrt(N / 400), rounded to 1 mm/s:
1.6 cm/s for 1000, 3.2 for 4000, 5 for 10,000, 6 for 14,400 (the rule of the fidelity runs,
docs/fidelity.md section 3, which shows that q/p and the anisotropies do not depend on the
speed between 0.5 and 8 cm/s at 400 particles).

Wall time. A stage's time is its steps x N x the measured microseconds per particle and step
(:data:`COSTS`, each with its source). The test's steps are
:meth:`solver.parameters.Preparation.test_steps` (the deposit's height: a slight
overestimate); the compaction's are the steps at the size of :data:`COSTS` scaled as sqrt(N)
(the 'fast' route's 14,400 pentagons took 6991 steps where sqrt(N) from 4000 predicted 7231).
The costs come from benchmarks on a shared 2-core VM, measured over part of a shear and
extrapolated for the compaction; the sweeps per step, and with them the cost, vary by a factor
of about 2 along a shear at 14,400 (docs/solver.md, "Known limits"): read an estimate as
within a factor of 2.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

PAPER_PARTICLES = {"pentagon": 14400, "disk": 10000}
"""The paper's sample sizes, by shape."""

REFERENCE_PARTICLES = 400
"""The study's default size, whose strain rate larger samples are sheared at."""

REFERENCE_VELOCITY = 0.01
"""The paper's top-wall speed, m s-1, at :data:`REFERENCE_PARTICLES`."""


def velocity_for(particles) -> float:
    """Top-wall speed (m s-1) that shears ``particles`` at the strain rate of
    :data:`REFERENCE_PARTICLES` at :data:`REFERENCE_VELOCITY`:
    v = 0.01 sqrt(N / 400), rounded to 1 mm/s (0.06 for 14,400, 0.05 for 10,000)."""
    return round(REFERENCE_VELOCITY * float(np.sqrt(particles / REFERENCE_PARTICLES)), 3)


def inertia_numbers(sim, velocity) -> tuple[float, float]:
    """The inertia numbers of a biaxial test of ``sim`` at its start, top wall at ``velocity``
    (m s-1): the paper's (Eq. 3) I = eps_dot sqrt(m / (sigma0 t)), m the particles' total mass
    (kg), t the slab thickness (m), and the grain-scale one of GDR MiDi (2004),
    I_d = eps_dot d sqrt(rho / sigma0), d the mean circumscribed diameter (m); eps_dot = v / h0
    with h0 the sample's height (m), sigma0 its confining stress (Pa)."""
    lo, hi = sim.walls.box_bounds()
    rate = float(velocity) / float(hi[1] - lo[1])
    sigma0 = float(sim.history.sigma0)
    p = sim.parameters
    paper = rate * np.sqrt(float(sim.mass.sum()) / (sigma0 * p.thickness))
    grain = rate * 2.0 * float(sim.radius.mean()) * np.sqrt(p.density / sigma0)
    return float(paper), float(grain)


@dataclass(frozen=True)
class Cost:
    """A measured cost: ``serial`` and ``two_domains`` microseconds per particle and step
    (wall time), at ``particles``, with ``steps`` the stage's measured steps there (None where
    the steps come from elsewhere), and ``source``, where the numbers come from."""

    particles: int
    serial: float
    two_domains: float
    steps: int | None
    source: str


COSTS = {
    # the 'paper' route with Anderson sweeps: 22,923 steps at 14,400 pentagons, 2.52 h serially, the time per
    # particle and step grown from the compactions measured at 1000 and 4000 (8.6 and 15.8 us) as N^0.43;
    # on 2 domains the 1.54x measured on the 4000-pentagon 'fast' route (benchmarks/results/compaction.md)
    ("pentagon", "compaction"): Cost(14400, 27.5, 27.5 / 1.54, 22923,
                                     "benchmarks/archive/time-to-strain.md, 14,400 pentagons, 'paper' route, "
                                     "extrapolated from 1000 and 4000"),
    # disks settle in far fewer steps: 2001 measured at 14,400; the time per step as the pentagons'
    ("disk", "compaction"): Cost(14400, 27.5, 27.5 / 1.54, 2001,
                                 "benchmarks/archive/time-to-strain.md, 14,400 disks: steps measured, time per "
                                 "step extrapolated"),
    # the first 0.01 of eps_q of a 14,400-pentagon shear, 6651 steps (2026-11-25, commit 80ed2db), where the
    # sweeps per step are the shear's highest (a 200-step window of benchmarks/RESULTS.md section a: 9.15 / 6.58)
    ("pentagon", "test"): Cost(14400, 14.9, 7.1, None,
                               "benchmarks/archive/time-to-strain.md, 14,400 pentagons sheared to eps_q = 0.01"),
    # 200 biaxial steps early in the shear of 14,400 dense disks
    ("disk", "test"): Cost(14400, 4.05, 2.02, None, "benchmarks/RESULTS.md section a, 14,400 dense disks"),
}
"""Measured microseconds per particle and step, by (shape, stage)."""


def shape_kind(shape) -> str:
    """The :data:`COSTS` shape a sample's shape is costed as: "disk" for disks, "pentagon" for
    every polygon."""
    return "disk" if shape == "disk" else "pentagon"


def estimate(preparation, test, time_step, domains=1) -> dict:
    """The expected steps, cost and wall time of each stage of one sample: ``{"compaction":
    (steps, microseconds per particle and step, seconds, source), "test": (...)}`` for the :class:`solver.parameters.Preparation`
    ``preparation`` sheared in the :class:`solver.parameters.BiaxialTest` ``test`` at
    ``time_step`` (s) on ``domains`` domains (the 2-domain cost for 2 or more), from
    :data:`COSTS` (module docstring)."""
    n = int(preparation.particles)
    kind = shape_kind(preparation.shape)
    out = {}
    compaction = COSTS[(kind, "compaction")]
    steps = min(compaction.steps * np.sqrt(n / compaction.particles), preparation.max_steps)
    cost = _per_particle(compaction, domains)
    out["compaction"] = (int(round(steps)), cost, float(steps * n * cost * 1e-6), compaction.source)
    shear = COSTS[(kind, "test")]
    steps = preparation.test_steps(time_step, test.velocity, test.strain)
    cost = _per_particle(shear, domains)
    out["test"] = (int(round(steps)), cost, float(steps * n * cost * 1e-6), shear.source)
    return out


def _per_particle(cost, domains) -> float:
    return cost.serial if domains <= 1 else cost.two_domains


def hours(seconds) -> str:
    """A duration in words: seconds below a minute, minutes below an hour, hours above."""
    if seconds < 60:
        return f"{seconds:.0f} s"
    return f"{seconds / 60:.0f} min" if seconds < 3600 else f"{seconds / 3600:.1f} h"
