"""benchmarks/fidelity/samples: the paper-size study's compacted samples kept in the repository
(14,400 pentagons, 10,000 disks; ``samples/README.md`` says how they were made).

Each is a complete file of the contract holding one settled snapshot under the paper's isotropic
stress, checked by two independent computations: the contacts' Love-Weber stress tensor and the
forces on the walls over their lengths. A reshear starts from each on a fresh clone: its first snapshot
is the sample bit for bit, and its top wall then moves at the speed asked for, exactly."""

from __future__ import annotations

import math
from pathlib import Path

import netCDF4
import numpy as np
import pytest

import grainview

from .conftest import load_benchmark

REPOSITORY = Path(__file__).resolve().parents[2]
SAMPLES = REPOSITORY / load_benchmark("fidelity.reshear").PAPER_SAMPLES
PARTICLES = {"pentagons": (14400, 5), "disks": (10000, 0)}  # the paper's S1 and S2: count, vertices
SIGMA0 = 1e4  # the paper's isotropic stress (Pa)


def _sample(label):
    return grainview.open_dataset(SAMPLES / f"{label}.nc", validate=True)


@pytest.mark.parametrize("label", sorted(PARTICLES))
def test_a_committed_sample_is_settled_under_the_papers_stress(label):
    count, vertices = PARTICLES[label]
    with _sample(label) as ds:
        assert ds.sizes["particle"] == count and ds.sizes["time"] == 1
        assert np.all(ds.n_vertices.values == vertices)
        assert ds.attrs["scene"] == "isotropic" and ds.attrs["compaction_settled"] == 1
        assert ds.attrs["preparation_name"] == "paper" and ds.attrs["preparation_sigma0"] == SIGMA0
        sigma = ds.grain.stress_tensor().isel(time=0).values
        walls = dict(zip(ds.wall.values, ds.wall_force.values[0]))
        lower, upper = ds.box_min.values[0], ds.box_max.values[0]
        width, height = upper - lower
    # the compaction stops once the pushed walls' stress, averaged over its last steps, is sigma0:
    # one snapshot's contact stress is near it and nearly isotropic, not equal to it
    p = (sigma[0, 0] + sigma[1, 1]) / 2
    assert p == pytest.approx(SIGMA0, rel=0.2)
    assert abs(sigma[0, 0] - sigma[1, 1]) < 0.15 * p and abs(sigma[0, 1]) < 0.05 * p
    # the same stress from the boundary: the forces on each pair of opposite walls over their
    # length (pushed right and top, fixed left and bottom), against the contacts' Love-Weber sum
    assert (walls["right"][0] - walls["left"][0]) / (2 * height) == pytest.approx(sigma[0, 0], rel=0.03)
    assert (walls["top"][1] - walls["bottom"][1]) / (2 * width) == pytest.approx(sigma[1, 1], rel=0.03)


@pytest.mark.parametrize("label", sorted(PARTICLES))
def test_a_reshear_starts_from_a_committed_sample(tmp_path, label):
    """Two steps at the paper's 1 cm/s with the right wall a tenth of the sample's mass."""
    reshear = load_benchmark("fidelity.reshear")
    velocity, steps = 0.01, 2
    with netCDF4.Dataset(SAMPLES / f"{label}.nc") as nc:
        time_step = float(nc.getncattr("solver_time_step"))
        height = float(nc["box_max"][0, 1] - nc["box_min"][0, 1])
        top = float(nc["wall_position"][0, 2, 1])
        mass = float(nc["mass"][:].sum())
        position = nc["position"][0]
    strain = math.log(1 + (steps - 0.5) * velocity * time_step / height)  # the test's steps: rounded up
    assert reshear.reshear(SAMPLES, tmp_path, label, velocity=velocity, every=1, domains=1, strain=strain,
                           wall_mass=0.1) == "started"
    with netCDF4.Dataset(tmp_path / f"{label}.nc") as nc:
        assert nc.getncattr("resheared_from") == str(SAMPLES / f"{label}.nc")
        assert nc.getncattr("wall_velocity_m_s") == velocity and nc.getncattr("biaxial_steps") == steps
        assert nc.getncattr("wall_mass_kg")[1] == pytest.approx(0.1 * mass, rel=1e-12)
        assert np.array_equal(nc["position"][0], position)
        assert list(nc["step"][:] - nc["step"][0]) == list(range(steps + 1))
        top_after = nc["wall_position"][-1, 2, 1]
    assert top_after == pytest.approx(top - steps * velocity * time_step, abs=1e-12)
