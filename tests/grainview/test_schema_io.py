"""The data contract on disk: writing, reading back, laziness of open_dataset, bad files."""

import hashlib

import numpy as np
import pytest
import xarray as xr

import grainview
from grainview.contract.errors import FileFormatError, SchemaError
from grainview.contract.schema import TIME_ATTRS, contact_slots
from grainview.contract.writer import SnapshotWriter

from . import builders


def _write(ds, path, **kw):
    n = ds.sizes["particle"]
    with SnapshotWriter.create(path, radius=ds.radius.values, n_vertices=ds.n_vertices.values,
                               mass=ds.mass.values, inertia=ds.inertia.values,
                               n_walls=ds.sizes.get("wall", 0), n_contact_slots=ds.sizes["contact"],
                               attrs={"mu": 0.4, "scene": "test"}, **kw) as w:
        for k in range(ds.sizes["time"]):
            snap = ds.isel(time=k)
            m = int(snap.contact_count)
            contacts = {name: snap[name].values[:m] for name in ("i", "j", "kind", "normal", "fn", "ft", "point", "branch")}
            w.append(time=float(snap.time), position=snap.position.values, angle=snap.angle.values,
                     contacts=contacts, box_min=snap.box_min.values, box_max=snap.box_max.values)
    return path


def _sha(path):
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


def test_contact_slots_is_planar_graph_bound():
    assert contact_slots(100, 4) == 3 * 104 - 6
    assert contact_slots(2, 0) == 2


def test_round_trip_keeps_values_and_integer_types(tmp_path):
    ds = builders.mixed_contacts()
    path = _write(ds, tmp_path / "run.nc")
    back = grainview.open_dataset(path, chunks=None)
    for name in ("i", "j", "kind", "contact_count"):
        assert back[name].dtype.kind == "i", name
        np.testing.assert_array_equal(back[name].values, ds[name].values)
    for name in ("fn", "ft", "normal", "branch", "point", "position", "radius"):
        np.testing.assert_array_equal(back[name].values, ds[name].values)
    assert list(back.xy.values) == ["x", "y"]
    assert list(back.wall.values) == ["bottom", "right", "top", "left"]
    assert back.attrs["grainview_schema_version"] == "1.0"  # disks and regular polygons: the first version
    assert back.attrs["mu"] == 0.4
    assert back.fn.attrs["units"] == "N" and back.kind.attrs["flag_meanings"] == "empty simple double"
    grainview.validate(back)


def test_time_is_a_cf_coordinate_in_seconds_that_no_reader_turns_into_dates(tmp_path):
    ds = builders.mixed_contacts(t=3)
    path = _write(ds, tmp_path / "run.nc")
    import netCDF4
    with netCDF4.Dataset(path) as nc:
        attrs = {k: nc["time"].getncattr(k) for k in nc["time"].ncattrs() if not k.startswith("_")}
        assert nc.Conventions == "CF-1.8"
        for name in nc.variables:  # CF 4.4: a time axis needs units "<unit> since <date>"
            var = nc[name]
            if getattr(var, "axis", None) == "T" or getattr(var, "standard_name", None) == "time":
                assert " since " in var.units, name
            assert hasattr(var, "long_name"), name
    assert attrs == TIME_ATTRS
    plain = xr.open_dataset(path)  # decode_times=True, as any user would open it
    assert plain["time"].dtype == np.float64
    np.testing.assert_array_equal(plain["time"].values, ds["time"].values)
    plain.close()
    assert builders.mixed_contacts(t=1)["time"].attrs == TIME_ATTRS  # in-memory datasets alike


def test_open_dataset_is_lazy_and_chunked_along_time_only(tmp_path):
    path = _write(builders.mixed_contacts(t=3), tmp_path / "run.nc")
    ds = grainview.open_dataset(path, chunks=2)
    assert ds.fn.chunks == ((2, 1), (ds.sizes["contact"],))
    assert ds.position.chunks[1:] == ((ds.sizes["particle"],), (2,))
    with pytest.raises(ValueError, match="only 'time'"):
        grainview.open_dataset(path, chunks={"contact": 5})


def test_trailing_incomplete_snapshot_is_dropped(tmp_path):
    path = _write(builders.mixed_contacts(t=2), tmp_path / "run.nc")
    import netCDF4
    with netCDF4.Dataset(path, "a") as nc:  # a writer killed after the forces, before time
        nc.variables["fn"][2] = np.ones(nc.dimensions["contact"].size)
    assert netCDF4.Dataset(path).dimensions["time"].size == 3
    ds = grainview.open_dataset(path, chunks=None)
    assert ds.sizes["time"] == 2
    w = SnapshotWriter.open_append(path)
    assert w.n_snapshots == 2
    w.close()


def test_reading_never_modifies_the_file(tmp_path):
    path = _write(builders.mixed_contacts(), tmp_path / "run.nc")
    before = _sha(path)
    ds = grainview.open_dataset(path, validate=True)
    ds.grain.stress_invariants().compute()
    ds.close()
    assert _sha(path) == before


def test_writer_refuses_to_overwrite(tmp_path):
    path = tmp_path / "run.nc"
    path.write_bytes(b"precious")
    ds = builders.two_disks()
    with pytest.raises(FileExistsError, match="overwrite"):
        _write(ds, path)
    assert path.read_bytes() == b"precious"


def test_writer_names_a_missing_folder_not_its_temporary_file(tmp_path):
    ds = builders.two_disks()
    with pytest.raises(FileNotFoundError, match=r"cannot write .*run.nc: the folder .*missing does not exist") as info:
        _write(ds, tmp_path / "missing" / "run.nc")
    assert ".part" not in str(info.value) and not (tmp_path / "missing").exists()


def test_not_netcdf_and_missing_files_give_clear_errors(tmp_path):
    bad = tmp_path / "notes.nc"
    bad.write_text("this is not netCDF")
    with pytest.raises(FileFormatError, match="not a readable netCDF"):
        grainview.open_dataset(bad)
    with pytest.raises(FileFormatError, match="no such file"):
        grainview.open_dataset(tmp_path / "missing.nc")


def test_newer_schema_version_is_refused(tmp_path):
    ds = builders.two_disks()
    ds.attrs["grainview_schema_version"] = "99.0"
    path = tmp_path / "future.nc"
    ds.to_netcdf(path, **grainview.contract.dataset.netcdf_options(ds))
    with pytest.raises(SchemaError, match="newer than this grainview"):
        grainview.open_dataset(path)


def test_to_netcdf_with_contract_encoding_round_trips(tmp_path):
    ds = builders.mixed_contacts()
    path = tmp_path / "x.nc"
    ds.to_netcdf(path, **grainview.contract.dataset.netcdf_options(ds, compress=False))
    back = grainview.open_dataset(path, chunks=None)
    xr.testing.assert_equal(back[["i", "j", "kind", "fn"]], ds[["i", "j", "kind", "fn"]])


def test_a_zlib_copy_is_smaller_and_opens_and_validates_unchanged(tmp_path):
    from grainview.datasets import harmonic_series
    ds = harmonic_series(n_snapshots=4, n_contacts=2000)
    plain, packed = tmp_path / "plain.nc", tmp_path / "zlib.nc"
    ds.to_netcdf(plain, format="NETCDF4_CLASSIC", encoding=grainview.contract.dataset.netcdf_encoding(ds))
    ds.to_netcdf(packed, format="NETCDF4_CLASSIC", encoding=grainview.contract.dataset.netcdf_encoding(ds, zlib=True))
    assert packed.stat().st_size < plain.stat().st_size
    back = grainview.open_dataset(packed, chunks=None)  # eager: no dask thread touches HDF5
    assert back["i"].encoding.get("zlib") is True  # contact ids shrink; random forces are stored as they are
    assert back["fn"].encoding.get("zlib") is False
    xr.testing.assert_identical(back[list(ds.data_vars)].reset_coords(drop=True),
                                grainview.open_dataset(plain, chunks=None)[list(ds.data_vars)].reset_coords(drop=True))
    grainview.validate(back)
    from grainview.contract.errors import ParameterError
    for bad in (0, 10, 4.5):
        with pytest.raises(ParameterError, match="complevel"):
            grainview.contract.dataset.netcdf_encoding(ds, zlib=True, complevel=bad)


@pytest.mark.parametrize("fraction", [0.1, 0.5, 0.9, 0.999])
def test_truncated_files_are_refused(tmp_path, fraction):
    path = _write(builders.mixed_contacts(t=3), tmp_path / "run.nc")
    data = path.read_bytes()
    cut = tmp_path / "cut.nc"
    cut.write_bytes(data[: int(len(data) * fraction)])
    assert data[:3] == b"CDF"  # the project's writer: netCDF-3
    with pytest.raises(FileFormatError, match=f"truncated.*{cut.stat().st_size} bytes"):
        grainview.open_dataset(cut)


def test_record_cut_short_is_dropped_by_its_flag(tmp_path):
    path = _write(builders.mixed_contacts(t=3), tmp_path / "run.nc")
    import netCDF4
    with netCDF4.Dataset(path, "a") as nc:  # the last record lost its final bytes
        nc.variables["complete"][2] = 0
    assert grainview.open_dataset(path, chunks=None).sizes["time"] == 2
    with netCDF4.Dataset(path, "a") as nc:
        nc.variables["complete"][0] = 0
    with pytest.raises(FileFormatError, match="snapshot 0 is incomplete"):
        grainview.open_dataset(path)


class _FailingWrite:
    """A netCDF4 Dataset whose variable ``name`` refuses writes, as a full disk would refuse
    one variable of a snapshot after the ones before it were written; all else is the file's."""

    def __init__(self, nc, name):
        self._real = nc
        self.variables = {**nc.variables, name: _Refusing(nc.variables[name])}

    def __getattr__(self, attr):
        return getattr(self._real, attr)


class _Refusing:
    def __init__(self, var):
        self._var = var

    def __getitem__(self, key):
        return self._var[key]

    def __setitem__(self, key, value):
        raise RuntimeError("NetCDF: HDF error (No space left on device)")


def _snapshot_args(ds, k):
    snap = ds.isel(time=k)
    m = int(snap.contact_count)
    contacts = {name: snap[name].values[:m] for name in ("i", "j", "kind", "normal", "fn", "ft", "point", "branch")}
    return dict(time=float(snap.time), position=snap.position.values, angle=snap.angle.values,
                contacts=contacts, box_min=snap.box_min.values, box_max=snap.box_max.values)


@pytest.mark.parametrize("failing", ["position", "fn", "contact_count"])
def test_an_append_failing_part_way_leaves_that_snapshot_incomplete(tmp_path, failing):
    """A write that fails in the middle of a snapshot (the first variable, a contact variable,
    the contact count) leaves it incomplete: the file reopens with the snapshots before it
    only, its ``complete`` flags 1 then not 1, and the next append writes that snapshot whole."""
    import netCDF4

    from grainview.contract.errors import OutputError
    ds = builders.mixed_contacts(t=3)
    path = tmp_path / "run.nc"
    w = SnapshotWriter.create(path, radius=ds.radius.values, n_vertices=ds.n_vertices.values, mass=ds.mass.values,
                              inertia=ds.inertia.values, n_walls=ds.sizes["wall"], n_contact_slots=ds.sizes["contact"])
    w.append(**_snapshot_args(ds, 0))
    real = w._nc
    w._nc = _FailingWrite(real, failing)
    with pytest.raises(OutputError, match="could not write snapshot 1 .*keeps its 1 complete snapshots") as info:
        w.append(**_snapshot_args(ds, 1))
    assert "\n" not in str(info.value)
    assert w.n_snapshots == 1
    w._nc = real
    w.close()

    with netCDF4.Dataset(path) as nc:
        nc.set_auto_mask(False)
        complete, time = nc.variables["complete"][:], nc.variables["time"][:]
    assert complete[0] == 1 and time[0] == float(ds.time[0])
    assert all(flag != 1 for flag in complete[1:]), complete
    back = grainview.open_dataset(path, chunks=None)
    assert back.sizes["time"] == 1
    np.testing.assert_array_equal(back.fn.values, ds.fn.values[:1])
    back.close()

    w = SnapshotWriter.open_append(path)
    assert w.n_snapshots == 1
    w.append(**_snapshot_args(ds, 1))
    w.close()
    back = grainview.open_dataset(path, chunks=None, validate=True)
    assert back.sizes["time"] == 2
    for name in ("time", "position", "fn", "i", "contact_count"):
        np.testing.assert_array_equal(back[name].values, ds[name].values[:2], err_msg=name)
    back.close()
