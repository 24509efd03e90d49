"""The simulations of the fidelity study, built once and cached.

A :class:`Run` names one sample and test: shape, size, preparation, seed, wall speed and
strain. :func:`ensure` simulates the runs whose files are missing, several at a time in
separate processes, and returns their paths. Each run keeps two files of the data contract in
the cache folder: the compacted sample (``*_sample.nc``, reused by every test of the same
sample) and the biaxial test (``*.nc``), written with near contacts so that every counting
convention can be applied afterwards.
"""

from __future__ import annotations

import os
import time
import warnings
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, replace

HERE = os.path.dirname(os.path.abspath(__file__))
CACHE = os.path.join(os.path.dirname(HERE), "_data", "fidelity")


@dataclass(frozen=True)
class Run:
    """One simulation of the study (see the module docstring)."""

    shape: str = "pentagon"
    particles: int = 1000
    preparation: str = "paper"
    seed: int = 0
    velocity: float = 0.01  # m s-1, top wall
    strain: float = 0.2  # eps_1 of the biaxial test (eps_q ~0.6)
    every: int = 400  # steps between snapshots
    scene: str = "biaxial"  # or "shear": the sample in its biperiodic cell, strain = gamma

    @property
    def sample_name(self) -> str:
        return f"{self.shape}_{self.particles}_{self.preparation}_s{self.seed}"

    @property
    def name(self) -> str:
        every = "" if self.every == Run.every else f"_k{self.every}"
        if self.scene == "shear":
            return f"{self.sample_name}_shear_v{self.velocity * 100:g}cm_g{self.strain:g}{every}"
        return f"{self.sample_name}_v{self.velocity * 100:g}cm_e{self.strain:g}{every}"

    def sample_path(self, cache=None) -> str:
        return os.path.join(cache or CACHE, "samples", self.sample_name + ".nc")

    def path(self, cache=None) -> str:
        return os.path.join(cache or CACHE, "runs", self.name + ".nc")

    def with_(self, **changes) -> "Run":
        return replace(self, **changes)


LADDER = {"mu0.1": dict(compaction_friction=0.1), "mu0.2": dict(compaction_friction=0.2)}
"""Preparations of the study beyond solver.preparation.PRESETS: compaction friction between the
'frictionless' (0) and 'paper' (0.4) presets."""


def preparation_of(run: Run):
    """The :class:`solver.preparation.Preparation` of ``run`` (a preset, or one of LADDER)."""
    from solver.preparation import preparation

    base, changes = (run.preparation, {}) if run.preparation not in LADDER else ("paper", LADDER[run.preparation])
    return preparation(base, particles=run.particles, shape=run.shape, seed=run.seed, **changes)


def _log(message):
    print(f"[{time.strftime('%H:%M:%S')}] {message}", flush=True)


def make_sample(run: Run, cache=None) -> str:
    """The compacted sample of ``run`` (built and written unless cached; a compaction stopped
    part-way goes on from its checkpoint, ``<sample>.nc.checkpoint``); returns its path."""
    from solver.output import Recorder
    from solver.preparation import prepare_sample, record

    path = run.sample_path(cache)
    if os.path.exists(path):
        return path
    os.makedirs(os.path.dirname(path), exist_ok=True)
    prep = preparation_of(run)
    start = time.perf_counter()
    checkpoint = path + ".checkpoint"  # the compaction's state every ten minutes: a killed one goes on
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sim = prepare_sample(prep, progress=False, checkpoint=checkpoint)
    # the study's own preparation names (the LADDER's are not presets)
    attrs = {"scene": "isotropic", **record(sim), "preparation_name": run.preparation,
             "compaction_seconds": time.perf_counter() - start}
    with Recorder(path + ".part", sim, attrs=attrs, near_contacts=True, overwrite=True) as rec:
        rec.write()
    os.replace(path + ".part", path)
    if os.path.exists(checkpoint):
        os.remove(checkpoint)
    _log(f"{run.sample_name}: compacted in {sim.compaction_steps} steps, {time.perf_counter() - start:.0f} s")
    return path


def simulate(run: Run, cache=None) -> str:
    """The test of ``run`` (simulated unless cached; a test stopped part-way is resumed from
    its file, bit for bit); returns its path. A biaxial test compresses the sample at the top
    wall's ``velocity``; a shear test shears it in the biperiodic cell of its box to gamma =
    ``strain`` at the rate of the biaxial test at ``velocity``
    (:func:`solver.periodic_shear.matching_shear_rate`)."""
    import solver
    from solver.restart import file_state, resume

    path = run.path(cache)
    if os.path.exists(path):
        return path
    part = path + ".part"
    if os.path.exists(part) and file_state(part) in ("partial", "finished"):
        start = time.perf_counter()
        _log(f"{run.name}: resuming {part}")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            resume(part, progress=False)
        os.replace(part, path)
        _log(f"{run.name}: resumed and finished in {time.perf_counter() - start:.0f} s")
        return path
    sample = make_sample(run, cache)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    sim = solver.load_sample(sample)  # carries the sample's preparation_* and compaction_* attributes
    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if run.scene == "shear":
            from solver.periodic_shear import matching_shear_rate, periodic_sample, shear_test

            rate = matching_shear_rate(sim, run.velocity)
            steps = shear_test(periodic_sample(sim), part, strain=run.strain, shear_rate=rate, every=run.every,
                               overwrite=True, progress=False, near_contacts=True)
        else:
            steps = solver.biaxial_test(sim, part, strain=run.strain, velocity=run.velocity, every=run.every,
                                        overwrite=True, progress=False, near_contacts=True)
    os.replace(part, path)
    _log(f"{run.name}: {steps} steps in {time.perf_counter() - start:.0f} s")
    return path


def _simulate_sample_group(group, cache=None):
    """Compact one sample (unless cached) and run every test of it, one after the other."""
    return [simulate(run, cache) for run in group]


def ensure(runs, jobs=2, cache=None) -> dict:
    """Simulate the missing ``runs`` (``jobs`` processes) and return {run: path}. The runs of
    one sample go to one process, so that no sample is compacted twice; the longest groups
    start first."""
    runs = list(dict.fromkeys(runs))
    missing = [r for r in runs if not os.path.exists(r.path(cache))]
    if missing:
        groups = {}
        for r in missing:
            groups.setdefault(r.sample_name, []).append(r)
        order = sorted(groups.values(), key=lambda g: -sum(r.particles / r.velocity for r in g))
        _log(f"{len(missing)} runs to simulate ({len(groups)} samples), {jobs} at a time")
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            list(pool.map(_simulate_sample_group, order, [cache] * len(order)))
    return {r: r.path(cache) for r in runs}
