"""The contract's plain reader (netCDF4 alone) against xarray's view of the same files."""

import os

import numpy as np
import pytest

import grainview
from grainview.contract.errors import FileFormatError, ParameterError, SchemaError
from grainview.contract.reader import ContractFile
from grainview.contract.writer import compress_file

from . import builders
from .test_schema_io import _write


@pytest.mark.parametrize("compressed", [False, True])
def test_every_variable_reads_as_xarray_reads_it(tmp_path, compressed):
    path = _write(builders.mixed_contacts(t=3), tmp_path / "run.nc")
    if compressed:
        compress_file(path)
    with grainview.open_dataset(path, chunks=None) as ds, ContractFile(path) as f:
        assert f.n_snapshots == ds.sizes["time"] == 3
        assert f.wall_names == tuple(ds["wall"].values) == ("bottom", "right", "top", "left")
        assert f.attrs["scene"] == "test" and f.attrs["mu"] == 0.4
        for name in ("radius", "n_vertices", "mass", "inertia"):
            np.testing.assert_array_equal(f.static(name), ds[name].values)
            assert f.static(name).dtype == ds[name].dtype
        for name in ("position", "angle", "i", "j", "kind", "fn", "normal", "contact_count", "time"):
            for k in (0, 1, -1):
                np.testing.assert_array_equal(f.snapshot(name, k), ds[name].values[k])  # NaN in empty slots too
            np.testing.assert_array_equal(f.series(name), ds[name].values)


def test_an_incomplete_last_snapshot_is_not_counted(tmp_path):
    import netCDF4

    path = _write(builders.mixed_contacts(t=3), tmp_path / "run.nc")
    with netCDF4.Dataset(path, "a") as nc:  # as a writer killed in its last snapshot leaves it
        nc["complete"][2] = 0
    with ContractFile(path) as f:
        assert f.n_snapshots == 2
        np.testing.assert_array_equal(f.snapshot("time", -1), f.series("time")[1])
        with pytest.raises(FileFormatError, match=r"index=2 is outside its 2 complete snapshots"):
            f.snapshot("time", 2)


def test_faults_are_one_line_each(tmp_path):
    path = _write(builders.mixed_contacts(t=2), tmp_path / "run.nc")
    with pytest.raises(FileFormatError, match="no such file"):
        ContractFile(tmp_path / "absent.nc")
    (tmp_path / "text.nc").write_text("not netCDF")
    with pytest.raises(FileFormatError, match="not a readable netCDF file"):
        ContractFile(tmp_path / "text.nc")
    cut = tmp_path / "cut.nc"
    cut.write_bytes(path.read_bytes()[:-100])
    with pytest.raises(FileFormatError, match="truncated"):
        ContractFile(cut)
    with ContractFile(path) as f:
        with pytest.raises(FileFormatError, match="has no variable 'gap'"):
            f.snapshot("gap")
        with pytest.raises(ParameterError, match="varies with time"):
            f.static("position")
        with pytest.raises(ParameterError, match="does not vary with time"):
            f.snapshot("radius")


def test_a_newer_schema_version_is_refused(tmp_path):
    import netCDF4

    path = _write(builders.mixed_contacts(t=1), tmp_path / "run.nc")
    with netCDF4.Dataset(path, "a") as nc:
        nc.grainview_schema_version = "4.0"
    with pytest.raises(SchemaError, match="newer than this grainview"):
        ContractFile(path)


def test_a_file_replaced_while_it_is_opened_is_opened_again(tmp_path, monkeypatch):
    """As :func:`grainview.contract.io.open_dataset`: a finished run compressed under its name
    between netCDF-C's two opens is opened again; a failure on an unchanged file is not."""
    import netCDF4

    path = _write(builders.mixed_contacts(t=3), tmp_path / "run.nc")
    packed = tmp_path / "packed.nc"
    packed.write_bytes(path.read_bytes())
    compress_file(packed)
    real, calls = netCDF4.Dataset, []

    def compressed_meanwhile(*args, **kwargs):
        calls.append(args[0])
        if len(calls) == 1:
            os.replace(packed, path)
            raise OSError(-51, "NetCDF: Unknown file format")
        return real(*args, **kwargs)

    monkeypatch.setattr(netCDF4, "Dataset", compressed_meanwhile)
    with ContractFile(path) as f:
        assert f.n_snapshots == 3
    assert len(calls) == 2
