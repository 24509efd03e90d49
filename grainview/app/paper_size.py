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
(:data:`COSTS`, each with its source), measured at the study's 400 particles and at the paper's
14,400: the cost per particle and step changes with N (the pentagons' grows: more sweeps per
step), so a size between is costed on the power law through the two, and a size outside at the
nearer one's cost. The test's steps are
:meth:`solver.parameters.Preparation.test_steps` (the deposit's height: a slight
overestimate); the compaction's are interpolated the same way between the measured sizes and
scaled as sqrt(N) outside them (the 'fast' route's 14,400 pentagons took 6991 steps where
sqrt(N) from 4000 predicted 7231). The costs are of one core with nothing else on it; the sweeps
per step, and with them the cost, vary by a factor of about 2 along a shear at 14,400
(docs/solver.md, "Known limits"): read an estimate as within a factor of 2.

The whole command (:func:`study_estimate`) adds what is not a step: compiling the kernels on a
cold cache (:data:`COMPILE_SECONDS`, the share of the kernels not in the cache) and writing the
report (:data:`REPORT_SECONDS`, in proportion to the particles), and it scales every stage by the
machine's load (:func:`load_factor`): on cores shared with other work a process gets its share
of them, not a whole one.
"""

from __future__ import annotations

import math
import os
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
    (wall time, on cores with nothing else on them), at ``particles``, with ``steps`` the
    stage's measured steps there (None where the steps come from elsewhere), and ``source``,
    where the numbers come from."""

    particles: int
    serial: float
    two_domains: float
    steps: int | None
    source: str


STUDY_TIME = "benchmarks/results/study-time.md"
"""Where the 400-particle costs and the study's overheads were measured (``python -m
benchmarks.study_time``): each stage's processor time, which is its wall time on a core with
nothing else on it."""
_AT_400 = f"{STUDY_TIME}, calibration"
"""The 400-particle costs' source: the calibration run there, a ``--jobs 1`` study with the
kernels compiled, each stage's processor time."""

COSTS = {
    ("pentagon", "compaction"): (
        # 2 domains not measured at 400: costed as serial
        Cost(400, 5.7, 5.7, 4091, _AT_400),
        # the 'paper' route with Anderson sweeps: 22,923 steps at 14,400 pentagons, 2.52 h serially, the time per
        # particle and step grown from the compactions measured at 1000 and 4000 (8.6 and 15.8 us) as N^0.43;
        # on 2 domains the 1.54x measured on the 4000-pentagon 'fast' route (benchmarks/results/compaction.md)
        Cost(14400, 27.5, 27.5 / 1.54, 22923,
             "benchmarks/archive/time-to-strain.md, 14,400 pentagons, 'paper' route, extrapolated from 1000 and 4000")),
    ("disk", "compaction"): (
        Cost(400, 7.4, 7.4, 711, _AT_400),
        # disks settle in far fewer steps: 2001 measured at 14,400; the time per step as the pentagons'
        Cost(14400, 27.5, 27.5 / 1.54, 2001,
             "benchmarks/archive/time-to-strain.md, 14,400 disks: steps measured, time per step extrapolated")),
    ("pentagon", "test"): (
        Cost(400, 10.4, 10.4, None, _AT_400),
        # the first 0.01 of eps_q of a 14,400-pentagon shear, 6651 steps (2026-11-25, commit 80ed2db), where the
        # sweeps per step are the shear's highest (a 200-step window of benchmarks/RESULTS.md section a: 9.15 / 6.58)
        Cost(14400, 14.9, 7.1, None, "benchmarks/archive/time-to-strain.md, 14,400 pentagons sheared to eps_q = 0.01")),
    ("disk", "test"): (
        Cost(400, 6.1, 6.1, None, _AT_400),
        # 200 biaxial steps early in the shear of 14,400 dense disks
        Cost(14400, 4.05, 2.02, None, "benchmarks/RESULTS.md section a, 14,400 dense disks")),
}
"""Measured microseconds per particle and step, by (shape, stage): a :class:`Cost` per measured
size, smallest first."""

COMPILE_SECONDS = {"solver": 60.0, "analysis": 15.0}
"""Seconds that compiling every kernel takes on an empty cache, in one process on a core with
nothing else on it, by group (:data:`grainview.app.warmup.GROUPS`: the solver's kernels, what
``grainview run`` needs; the analysis's, what the report adds): the processor time of
the study's compiling stages on an empty NUMBA_CACHE_DIR (:data:`STUDY_TIME`, study-cold)."""

REPORT_SECONDS = (34.0, 800)
"""(seconds, particles): the study's report of two 400-particle runs, its kernels compiled, on a
core with nothing else on it: the processor time from the last sample's 'wrote' line to the end
(:data:`STUDY_TIME`, calibration); costed in proportion to the particles of both runs, and
never below it (its figures cost the same for fewer particles)."""


def shape_kind(shape) -> str:
    """The :data:`COSTS` shape a sample's shape is costed as: "disk" for disks, "pentagon" for
    every polygon."""
    return "disk" if shape == "disk" else "pentagon"


def _between(costs, n, value, outside=None) -> float:
    """``value(cost)`` at ``n`` particles: on the power law through the two measured sizes around
    ``n``; outside them, the nearer size's value, times ``outside(ratio of sizes)`` when given."""
    sizes = [c.particles for c in costs]
    if n <= sizes[0] or n >= sizes[-1]:
        nearest = costs[0] if n <= sizes[0] else costs[-1]
        return value(nearest) * (outside(n / nearest.particles) if outside else 1.0)
    k = next(i for i in range(len(sizes) - 1) if sizes[i] <= n <= sizes[i + 1])
    a, b = costs[k], costs[k + 1]
    # portable: Python floats (the math module), an estimate printed to the user, written into no file
    exponent = math.log(value(b) / value(a)) / math.log(b.particles / a.particles)
    return value(a) * (n / a.particles) ** exponent  # portable: as above


def estimate(preparation, test, time_step, domains=1) -> dict:
    """The expected steps, cost and wall time of each stage of one sample, on cores with
    nothing else on them.

    Parameters
    ----------
    preparation : solver.parameters.Preparation
        The sample and how it is compacted.
    test : solver.parameters.BiaxialTest or None
        The biaxial test it is sheared in; None for a sample compacted only.
    time_step : float
        The time step, s.
    domains : int, default 1
        Domains of the sweeps (the 2-domain cost for 2 or more).

    Returns
    -------
    dict
        ``{"compaction": (steps, microseconds per particle and step, seconds, source), "test":
        (...)}`` (no ``"test"`` when ``test`` is None), from :data:`COSTS` (module docstring).
    """
    n = int(preparation.particles)
    kind = shape_kind(preparation.shape)
    field = (lambda c: c.serial) if domains <= 1 else (lambda c: c.two_domains)
    out = {}
    costs = COSTS[(kind, "compaction")]
    steps = min(_between(costs, n, lambda c: c.steps, outside=math.sqrt), preparation.max_steps)
    cost = _between(costs, n, field)
    out["compaction"] = (int(round(steps)), cost, float(steps * n * cost * 1e-6), _sources(costs, n))
    if test is None:
        return out
    costs = COSTS[(kind, "test")]
    steps = preparation.test_steps(time_step, test.velocity, test.strain)
    cost = _between(costs, n, field)
    out["test"] = (int(round(steps)), cost, float(steps * n * cost * 1e-6), _sources(costs, n))
    return out


def _sources(costs, n) -> str:
    """Where the cost at ``n`` comes from: the measured size's source, or both's for a size between."""
    exact = [c for c in costs if c.particles == n]
    if exact or n <= costs[0].particles or n >= costs[-1].particles:
        c = exact[0] if exact else (costs[0] if n <= costs[0].particles else costs[-1])
        return c.source if c.particles == n else f"{c.source}, at {c.particles}"
    below = max((c for c in costs if c.particles < n), key=lambda c: c.particles)
    above = min((c for c in costs if c.particles > n), key=lambda c: c.particles)
    return f"between {below.particles} ({below.source}) and {above.particles} ({above.source})"


def machine_load() -> tuple[float, int]:
    """This machine's load: (the mean of its 1- and 5-minute load averages, the number of
    cores); the load is 0 where the system does not give it. The 1-minute average alone swings
    with every short job, the 5-minute one lags a machine that has just become busy; a study
    lasts minutes to hours."""
    try:
        one, five, _ = os.getloadavg()
    except (AttributeError, OSError):
        one = five = 0.0
    return float(one + five) / 2, int(os.cpu_count() or 1)


def load_factor(processes, load, cores) -> float:
    """How many times longer ``processes`` busy processes take on ``cores`` cores where the
    others keep ``load`` of them busy (a load average) than on idle cores: each gets a fair
    share of the cores, ``cores / (load + processes)`` of one when that is below one, so the
    factor is max(1, (load + processes) / cores)."""
    return max(1.0, (float(load) + processes) / cores)


def study_estimate(samples, time_step, domains=1, jobs=2, compile_share=None, report=True, load=0.0,
                   cores=None) -> dict:
    """The expected wall time of a whole ``grainview study``: compiling (on a cold cache), each
    sample's stages, the report, on a machine of ``cores`` cores under ``load``.

    Parameters
    ----------
    samples : dict
        ``{label: (preparation, test)}`` of the samples still to run
        (:class:`solver.parameters.Preparation`, :class:`solver.parameters.BiaxialTest`).
    time_step : float
        The time step, s.
    domains : int, default 1
        Domains of each sample's sweeps.
    jobs : int, default 2
        Samples run side by side (1: one after the other).
    compile_share : dict, optional
        ``{package: share of its kernels not in the cache}``, packages of
        :data:`COMPILE_SECONDS` ("solver", "analysis"); None or all zero: a warm cache.
    report : bool, default True
        Whether the report is written at the end.
    load : float, default 0
        The load average of the other work (:func:`machine_load`).
    cores : int, optional
        The machine's cores (default: this one's).

    Returns
    -------
    dict
        ``{"samples": {label: estimate(...)}, "idle": {"compile", "simulation", "report":
        seconds on idle cores}, "factor": {same keys: load factors}, "seconds": {same keys:
        idle x factor}, "total": seconds, "load": load, "cores": cores, "processes": the
        simulation's busy processes}``.
    """
    cores = int(cores or os.cpu_count() or 1)
    stages = {label: estimate(prep, test, time_step, domains) for label, (prep, test) in samples.items()}
    per_sample = {label: sum(stage[2] for stage in s.values()) for label, s in stages.items()}
    side_by_side = jobs > 1 and len(samples) > 1
    simulation = (max(per_sample.values()) if side_by_side else sum(per_sample.values())) if per_sample else 0.0
    processes = (min(jobs, len(samples)) if side_by_side else 1) * max(1, domains)
    particles = sum(int(prep.particles) for prep, _ in samples.values())
    idle = {"compile": sum(COMPILE_SECONDS[package] * share for package, share in (compile_share or {}).items()),
            "simulation": simulation,
            "report": REPORT_SECONDS[0] * max(1.0, particles / REPORT_SECONDS[1]) if report else 0.0}
    factor = {"compile": load_factor(1, load, cores), "simulation": load_factor(processes, load, cores),
              "report": load_factor(1, load, cores)}
    seconds = {key: idle[key] * factor[key] for key in idle}
    return {"samples": stages, "idle": idle, "factor": factor, "seconds": seconds, "total": sum(seconds.values()),
            "load": float(load), "cores": cores, "processes": processes}


def hours(seconds) -> str:
    """A duration in words: seconds below a minute, minutes below an hour, hours above."""
    if seconds < 60:
        return f"{seconds:.0f} s"
    return f"{seconds / 60:.0f} min" if seconds < 3600 else f"{seconds / 3600:.1f} h"
