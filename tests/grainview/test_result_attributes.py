"""Every result carries exactly its own metadata: units and long_name, nothing inherited from
the inputs it was computed from (a time axis flag, an input's comment, a sentinel note)."""

import numpy as np
import pytest
import xarray as xr

from grainview.datasets import harmonic_series

CALLS = [
    ("stress_tensor", {}), ("stress_invariants", {}), ("strains", {}), ("friction_and_dilatancy", {}),
    ("inertia_number", {}), ("solid_fraction", {}), ("fabric_tensor", {}), ("fabric_anisotropy", {}),
    ("orientation_pdf", {}), ("contact_numbers", {}), ("coordination", {}), ("connectivity_pdf", {}),
    ("joint_connectivity_pdf", {}), ("angular_force_averages", {}), ("force_tensors", {}),
    ("force_anisotropies", {}), ("harmonic_prediction", {}), ("force_pdf", {}), ("force_class", {}),
    ("contact_proportions", {}), ("xi_network", {"xi": [0.5, 1.0]}), ("persistence", {}),
    ("type_transitions", {}),
]
INHERITED = ("axis", "flag_values_of_kind")


def _arrays(result):
    if isinstance(result, xr.Dataset):
        return [result[name] for name in result.data_vars]
    return [result]


@pytest.fixture(scope="module")
def series():
    ds = harmonic_series(n_snapshots=3, n_contacts=200, seed=1)
    ds["time"].attrs["axis"] = "T"  # an input attribute that no result may carry
    return ds


@pytest.mark.parametrize("name, kwargs", CALLS, ids=[c[0] for c in CALLS])
def test_results_carry_their_own_attributes_only(series, name, kwargs):
    for da in _arrays(getattr(series.grain, name)(**kwargs)):
        assert {"units", "long_name"} <= set(da.attrs), (name, da.name, da.attrs)
        assert "axis" not in da.attrs, (name, da.name)
        comment = str(da.attrs.get("comment", ""))
        assert "empty slots" not in comment, (name, da.name, comment)
        if da.name not in ("stress", "sigma_1", "sigma_2") and not name.startswith("stress"):
            assert "sigma = (1/V)" not in comment, (name, da.name, comment)


def test_a_result_does_not_inherit_the_attributes_of_its_input(series):
    z = series.grain.coordination()["z"]
    assert z.attrs == {"units": "1", "long_name": "coordination number z (rattlers excluded)"}
    q_over_p = series.grain.stress_invariants()["q_over_p"]
    assert q_over_p.attrs == {"units": "1", "long_name": "normalised shear stress q/p"}
    assert np.isfinite(q_over_p.values).all()


def test_time_series_carry_the_strains_as_coordinates():
    from grainview.datasets import harmonic_series

    ds = harmonic_series(n_snapshots=30, n_contacts=200)
    eps = ds.grain.strains()
    for result in (ds.grain.coordination()["z"], ds.grain.stress_invariants(), ds.grain.fabric_anisotropy()):
        for name in ("eps_1", "eps_p", "eps_q"):
            assert result[name].dims == ("time",)
            np.testing.assert_allclose(result[name].values, eps[name].values)
    assert "eps_q" not in ds.grain.strains().coords  # the strains themselves stay variables
    z = ds.grain.coordination()["z"].swap_dims(time="eps_q")
    assert z.dims == ("eps_q",)
    assert ds.grain.orientation_pdf(bins=8).isel(time=0).coords["eps_q"].ndim == 0


def test_long_series_open_in_several_chunks(tmp_path):
    import os

    import grainview
    from grainview.contract.dataset import netcdf_encoding
    from grainview.contract.io import MIN_CHUNK_SNAPSHOTS
    from grainview.datasets import harmonic_series

    ds = harmonic_series(n_snapshots=200, n_contacts=50)
    path = tmp_path / "long.nc"
    ds.to_netcdf(path, encoding=netcdf_encoding(ds), format="NETCDF4_CLASSIC")
    chunks = grainview.open_dataset(path)["fn"].chunks[0]
    assert sum(chunks) == 200 and len(chunks) >= 2
    assert max(chunks) >= min(MIN_CHUNK_SNAPSHOTS, 200)
    assert len(chunks) >= min(4 * (os.cpu_count() or 1), 200 // MIN_CHUNK_SNAPSHOTS) - 1
