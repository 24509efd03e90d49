"""Per-particle fields and their maps, on the hand-made series of test_lifetimes."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
import xarray as xr  # noqa: E402

from grainview.contract.errors import ParameterError  # noqa: E402

from .conftest import raise_if_dask_computes  # noqa: E402
from .test_lifetimes import SERIES  # noqa: E402
from .test_persistence import N, sequence_dataset  # noqa: E402


def test_fields_by_hand(prepare):
    ds = sequence_dataset(SERIES)
    particle = xr.DataArray(np.arange(N), dims="particle")
    ds["angle"] = ds["angle"] + ds["time"] * 0.1 * particle  # particle p turns 0.1 p rad per snapshot
    shift = ds["time"] * 0.01 * xr.DataArray([1.0, 2.0], dims="xy")  # all move by (0.01, 0.02) per snapshot
    ds["position"] = (ds["position"] + shift).transpose(*ds["position"].dims)
    ds = prepare(ds)
    f = ds.grain.particle_fields()
    # t2: (0,1) double 6 N, (1,2) simple 1 N, (2,3) simple 3 N, (4,wall) simple 1 N; mean f_n = 11/4
    at = f.isel(time=2)
    np.testing.assert_array_equal(at.c.values, [1, 2, 2, 1, 1])
    np.testing.assert_array_equal(at.m_s.values, [0, 1, 2, 1, 1])
    np.testing.assert_array_equal(at.m_d.values, [1, 1, 0, 0, 0])
    np.testing.assert_array_equal(at.strong.values, [1, 1, 1, 1, 0])  # 6 N and 3 N exceed 2.75 N
    np.testing.assert_array_equal(f.isel(time=4).rattler.values, [True, True, False, False, False])
    np.testing.assert_allclose(at.rotation.values, 0.2 * np.arange(N))
    np.testing.assert_allclose(at.displacement.values, np.hypot(0.02, 0.04))
    assert f.c.attrs["units"] == "1" and f.rotation.attrs["units"] == "rad" and f.displacement.attrs["units"] == "m"


def test_fields_stay_lazy():
    ds = sequence_dataset(SERIES).chunk({"time": 2})
    with raise_if_dask_computes():
        f = ds.grain.particle_fields()
    np.testing.assert_array_equal(f.c.values, sequence_dataset(SERIES).grain.particle_fields().c.values)


@pytest.mark.parametrize("name", ["particle_map", "connectivity_map", "rattler_map", "rotation_map"])
def test_maps_draw_with_a_colour_bar(name):
    ds = sequence_dataset(SERIES)
    fig, ax = plt.subplots()
    getattr(ds.grain.plot, name)(ax=ax, time=2)
    assert len(fig.axes) == 2 and fig.axes[1].get_ylabel()  # the colour bar, labelled
    colours = ax.collections[0].get_array()
    assert colours is not None and len(colours) == N
    plt.close(fig)


def test_unknown_field_is_named():
    with pytest.raises(ParameterError, match="field="):
        sequence_dataset(SERIES).grain.plot.particle_map(field="colour")


@pytest.mark.parametrize("kind", ["force_chains", "force_classes", "connectivity"])
def test_movie_frames(tmp_path, kind):
    from PIL import Image

    ds = sequence_dataset(SERIES)
    path = ds.grain.plot.animate(tmp_path / f"{kind}.gif", kind=kind, every=2, progress=False)
    with Image.open(path) as gif:
        assert gif.n_frames == 4  # snapshots 0, 2, 4 and the last
    assert not list(tmp_path.glob("*.part*"))
    with pytest.raises(ParameterError, match="exists"):
        ds.grain.plot.animate(path, kind=kind)


def test_movie_bad_arguments(tmp_path):
    ds = sequence_dataset(SERIES)
    with pytest.raises(ParameterError, match="kind="):
        ds.grain.plot.animate(tmp_path / "m.gif", kind="colour")
    with pytest.raises(ParameterError, match=".gif or .mp4"):
        ds.grain.plot.animate(tmp_path / "m.avi")
