"""The Box2D and pymunk readers on what the engines wrote: tests/data/peers/ holds a 30-pentagon
sample of this project (sample.npz) and the raw snapshots of Box2D 2.3.10 and pymunk 7.3.1 driven
through the start of the biaxial test by the cross-check's engines (make_fixtures.py made them).
The checks are statics the engines must satisfy whatever their solver, and a plain re-reading of
the raw arrays."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import grainview
from grainview.contract.errors import FileFormatError, ParameterError
from grainview.formats.peers import convert_peer, open_peer

DATA = Path(__file__).resolve().parents[1] / "data" / "peers"
SAMPLE = DATA / "sample.npz"
ENGINES = ("box2d", "pymunk")


@pytest.fixture(scope="module", params=ENGINES)
def run(request):
    return request.param, open_peer(DATA / request.param, SAMPLE)


def test_the_fixtures_are_the_engines_own(run):
    engine, ds = run
    meta = json.loads((DATA / engine / "meta.json").read_text())
    assert ds.attrs["source"] == engine == meta["engine"]
    assert ds.attrs["engine_version"] == {"box2d": "2.3.10", "pymunk": "7.3.1"}[engine]
    assert ds.sizes["time"] == meta["snapshots"] and ds.sizes["particle"] == 30


def test_walls_balance_the_applied_stress(run):
    """The right wall is pushed by sigma0 h (per m of thickness): the particles push back on it
    by as much, in +x; the top and bottom walls carry equal and opposite forces; and the
    stress of the contact forces (walls included) is symmetric (torque balance) with
    sigma_xx = sigma0. From the third snapshot on: snapshot 0 is the engines' start, before any
    impulse, and in the next one (step 50) Box2D is still off by 0.5-0.7 % (its start-up)."""
    _, ds = run
    sigma0 = float(np.load(SAMPLE)["sigma0"])
    later = ds.isel(time=slice(2, None))
    height = later["wall_position"].sel(wall="top", xy="y") - later["wall_position"].sel(wall="bottom", xy="y")
    force = later["wall_force"]
    np.testing.assert_allclose(force.sel(wall="right", xy="x") / (sigma0 * height), 1.0, atol=1e-3)
    np.testing.assert_allclose(force.sel(wall="top", xy="y"), -force.sel(wall="bottom", xy="y"), rtol=1e-3)
    stress = later.grain.stress_tensor()
    np.testing.assert_allclose(stress.sel(xy_a="x", xy_b="x"), sigma0, rtol=1e-3)
    np.testing.assert_allclose(stress.sel(xy_a="x", xy_b="y"), stress.sel(xy_a="y", xy_b="x"), rtol=1e-3)


def test_contacts_reread_from_the_raw_arrays(run):
    """Pair by pair, a plain loop over the raw rows gives the same contacts: i < j, the force
    exerted by i on j in (fn, ft), kind 2 for two-point manifolds, loaded pairs only."""
    engine, ds = run
    n = ds.sizes["particle"]
    for k, path in enumerate(sorted((DATA / engine).glob("snap_*.npz"))):
        raw = dict(np.load(path))
        expected = {}
        for a, b, normal, force, points in zip(raw["a"], raw["b"], raw["normal"], raw["force"], raw["n_points"]):
            i, j, sign = (a, b, 1.0) if a < b else (b, a, -1.0)
            normal, force = sign * normal / np.hypot(*normal), sign * force
            fn, ft = force @ normal, force @ [-normal[1], normal[0]]
            if fn > 0:
                expected[(int(i), int(j))] = (fn, ft, 2 if points == 2 else 1)
        count = int(ds["contact_count"][k])
        got = {(int(i), int(j)): (fn, ft, int(kind)) for i, j, fn, ft, kind in
               zip(*(ds[v].values[k, :count] for v in ("i", "j", "fn", "ft", "kind")))}
        assert got.keys() == expected.keys()
        for key, (fn, ft, kind) in expected.items():
            assert got[key][2] == kind
            np.testing.assert_allclose(got[key][:2], (fn, ft), rtol=1e-12, atol=1e-9)
        assert all(j >= n for (_, j) in got if j >= n) and all(i < j for (i, j) in got)
    assert 2 in ds["kind"].values  # pentagons: the engines report edge-to-edge contacts


def test_file_backend_and_reader_agree(tmp_path):
    for engine in ENGINES:
        out = tmp_path / f"{engine}.nc"
        assert convert_peer(out, DATA / engine, SAMPLE, engine=engine) == 6
        on_file = grainview.open_dataset(out, chunks=None, validate=True)
        backend = xr.open_dataset(DATA / engine, engine=engine, sample=SAMPLE)
        through = grainview.open_dataset(DATA / engine, format=engine, sample=SAMPLE, chunks=None)
        reference = open_peer(DATA / engine, SAMPLE)
        for other in (on_file, backend, through):
            for name, var in reference.data_vars.items():
                np.testing.assert_array_equal(other[name].values, var.values, err_msg=f"{engine} {name}")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["box2d.nc", "pymunk.nc"]


def _copy(tmp_path, engine="box2d"):
    folder = tmp_path / engine
    shutil.copytree(DATA / engine, folder)
    return folder


@pytest.mark.parametrize("spoil,match", [
    (lambda f: [p.unlink() for p in f.glob("snap_*.npz")], "no raw snapshots"),
    (lambda f: (f / "meta.json").unlink(), "no readable meta.json"),
    (lambda f: np.savez(f / "snap_000003.npz", time=0.0), "lacks step"),
    (lambda f: (f / "snap_000004.npz").write_bytes(b"not numpy"), "cannot be read"),
])
def test_bad_input_gets_one_line_and_writes_nothing(tmp_path, spoil, match):
    folder = _copy(tmp_path)
    spoil(folder)
    out = tmp_path / "out.nc"
    with pytest.raises(FileFormatError, match=match) as info:
        convert_peer(out, folder, SAMPLE)
    assert "\n" not in str(info.value) and not out.exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def test_another_engines_folder_is_refused():
    with pytest.raises(ParameterError, match="written by 'box2d', not 'pymunk'"):
        grainview.open_dataset(DATA / "box2d", format="pymunk", sample=SAMPLE)


def test_a_sample_with_vertex_lists_passes_them_on(tmp_path):
    """A sample .npz holding ``vertices`` (here the pentagons turned by 0.1 rad in their own
    frames, a shape the contract accepts) gives them to the dataset and the file unchanged;
    without the key the file has no ``vertices`` (regular polygons)."""
    from grainview.contract.shapes import body_vertices

    data = dict(np.load(SAMPLE))
    radius, n = data["radius"], data["n_vertices"]
    turn = np.array([[np.cos(0.1), np.sin(0.1)], [-np.sin(0.1), np.cos(0.1)]])
    data["vertices"] = body_vertices(radius, n) @ turn
    sample = tmp_path / "sample.npz"
    np.savez(sample, **data)
    ds = open_peer(DATA / "box2d", sample)
    np.testing.assert_array_equal(ds["vertices"].values, data["vertices"])
    out = tmp_path / "box2d.nc"
    convert_peer(out, DATA / "box2d", sample, engine="box2d")
    with grainview.open_dataset(out, validate=True) as on_file:
        np.testing.assert_array_equal(on_file["vertices"].values, data["vertices"])
    assert "vertices" not in open_peer(DATA / "box2d", SAMPLE).variables
