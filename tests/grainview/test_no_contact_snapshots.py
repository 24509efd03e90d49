"""Every analysis of the accessor on real converted files whose first snapshot has no contact
(the LAMMPS fixture at t = 0) or that hold a single snapshot (the PeGS fixture), computed lazily
by dask: no floating-point warning reaches the user, and what is undefined there (q/p at p = 0,
an anisotropy of no forces, a rate from one snapshot) is NaN."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import grainview
from grainview.accessor import GrainAccessor, _Delegate

DATA = Path(__file__).parents[1] / "data"
ANALYSES = sorted(name for name, member in vars(GrainAccessor).items() if isinstance(member, _Delegate))


@pytest.fixture(scope="module")
def converted(tmp_path_factory):
    from grainview.formats.lammps import convert_lammps
    from grainview.formats.pegs import convert_pegs

    folder = tmp_path_factory.mktemp("converted")
    lammps = DATA / "lammps"
    convert_lammps(folder / "lammps.nc", lammps / "dump.particles", lammps / "dump.contacts", lammps / "dump.walls",
                   log=lammps / "log.lammps")
    pegs = DATA / "pegs"
    convert_pegs(folder / "pegs.nc", pegs / "Adjacency_list.txt", pegs / "particle_positions.txt",
                 metres_per_pixel=4.375e-5, force_unit_n=1.0)
    return folder


@pytest.mark.parametrize("name", ANALYSES)
@pytest.mark.parametrize("label", ["lammps", "pegs"])
def test_lazily_computed_analyses_raise_no_floating_point_warning(converted, label, name):
    with grainview.open_dataset(converted / f"{label}.nc") as ds, warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        result = getattr(ds.grain, name)()
        if hasattr(result, "compute"):
            result.compute()


def test_undefined_values_are_nan(converted):
    with grainview.open_dataset(converted / "lammps.nc") as ds:
        assert int(ds.contact_count[0]) == 0 and int(ds.contact_count[1]) > 0
        stress = ds.grain.stress_invariants().compute()
        forces = ds.grain.force_anisotropies().compute()
    assert float(stress.p[0]) == 0 and np.isnan(stress.q_over_p[0]) and np.isfinite(stress.q_over_p[1:]).all()
    assert np.isnan(forces.a_n[0]) and np.isfinite(forces.a_n[1:]).all()
    with grainview.open_dataset(converted / "pegs.nc") as ds:
        assert ds.sizes["time"] == 1
        assert np.isnan(ds.grain.inertia_number().compute()).all()
