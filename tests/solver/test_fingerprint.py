"""Trajectories bit for bit: a few short runs of the stepper, each reduced to one SHA-256 digest
of its state after a fixed number of steps.

The digests were recorded with this machine's build (x86-64, numba's default floating point, no
fast-math), before the solver's kernels were reorganised; a change of layout, argument passing
or module boundaries must leave them unchanged. A digest that changes means the arithmetic or
its order changed: that is a change of physics output and has to be argued for, then the digest
re-recorded with ``python tests/solver/test_fingerprint.py --record``.
"""

from __future__ import annotations

import hashlib
import json
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from grainview.contract.errors import ConvergenceWarning

DIGESTS = Path(__file__).with_name("fingerprints.json")

RUNS = {
    # name: (shape, particles, steps, solver parameters)
    "pentagons_anderson": ("pentagon", 60, 1000, dict()),
    "pentagons_plain_shuffled": ("pentagon", 60, 1000, dict(acceleration="off", shuffle=True)),
    "pentagons_plain_domains": ("pentagon", 60, 1000, dict(acceleration="off", domains=2)),
    "disks_anderson_domains": ("disk", 60, 1000, dict(domains=2)),
    "irregular_anderson": ("irregular", 40, 800, dict()),
}


def state_digest(sim) -> str:
    """SHA-256 of the raw bytes of everything a step carries to the next."""
    h = hashlib.sha256()
    arrays = [sim.position, sim.angle, sim.velocity, sim.angular_velocity, sim.impulse,
              sim.walls.point, sim.walls.velocity, np.array([sim.time])]
    if sim.points is not None:
        arrays += [sim.points.body_i, sim.points.body_j, sim.points.normal, sim.points.point, sim.points.gap]
    for a in arrays:
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def run(name) -> str:
    from solver import compaction_sample

    shape, n, steps, parameters = RUNS[name]
    sim = compaction_sample(n, shape, seed=3, **parameters)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        for _ in range(steps):
            sim.step()
    return state_digest(sim)


@pytest.mark.parametrize("name", sorted(RUNS))
def test_trajectory_unchanged_bit_for_bit(name):
    recorded = json.loads(DIGESTS.read_text())
    assert run(name) == recorded[name], (
        f"{name}: the trajectory changed (module docstring says when re-recording is right)")


def test_digest_sees_a_one_ulp_change():
    from solver import compaction_sample

    sim = compaction_sample(20, "pentagon", seed=3)
    before = state_digest(sim)
    sim.position[0, 0] = np.nextafter(sim.position[0, 0], np.inf)
    assert state_digest(sim) != before


if __name__ == "__main__" and "--record" in sys.argv:
    DIGESTS.write_text(json.dumps({name: run(name) for name in sorted(RUNS)}, indent=1) + "\n")
    print(DIGESTS.read_text())
