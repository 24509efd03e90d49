"""``grainview info`` never says valid of a file that is not: damaged snapshots, a header that
hides records, negative or infinite forces; and every contract error is one line."""

import warnings

import netCDF4
import numpy as np
import pytest

import grainview
from grainview.app.cli import main
from grainview.contract.dataset import netcdf_options
from grainview.contract.errors import FileFormatError, SchemaError
from grainview.datasets import harmonic_series


def _netcdf3(path, n_snapshots=55, n_contacts=20, complete=True):
    """A netCDF-3 file of the harmonic series, with the writer's ``complete`` flags and ``time``
    unlimited (the snapshots are records), as the solver writes it."""
    ds = harmonic_series(n_snapshots=n_snapshots, n_contacts=n_contacts)
    if complete:
        ds["complete"] = ("time", np.ones(n_snapshots, "i1"))
    ds.to_netcdf(path, unlimited_dims=["time"], **netcdf_options(ds, compress=False))
    return path


def _refused(argv, capsys):
    """Exit code 2 and the one line of stderr; nothing said valid on stdout."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert main(argv) == 2
    out, err = capsys.readouterr()
    assert "valid" not in out and not caught, (out, [str(w.message) for w in caught])
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("grainview: error: "), err
    return lines[0]


@pytest.mark.parametrize("variable, value", [("time", np.nan), ("complete", 0)])
def test_a_damaged_snapshot_before_complete_ones_is_refused_as_open_dataset_does(tmp_path, capsys, variable, value):
    path = _netcdf3(tmp_path / "run.nc")
    with netCDF4.Dataset(path, "a") as nc:
        nc.variables[variable][10] = value
    line = _refused(["info", str(path)], capsys)
    assert line.endswith(f"{path}: snapshot 10 is incomplete but later ones are complete; the file is damaged")
    with pytest.raises(FileFormatError, match="snapshot 10 is incomplete but later ones are complete"):
        grainview.open_dataset(path)
    # an incomplete last snapshot is a killed writer's: dropped, the rest is valid
    with netCDF4.Dataset(path, "a") as nc:
        nc.variables[variable][10] = 1.0 if variable == "complete" else 10.0
        nc.variables[variable][54] = value
    assert main(["info", str(path)]) == 0
    assert "54 snapshots" in capsys.readouterr().out


def test_a_header_that_counts_fewer_records_than_the_file_holds_is_refused(tmp_path, capsys):
    path = _netcdf3(tmp_path / "run.nc")
    data = bytearray(path.read_bytes())
    assert data[:4] == b"CDF\x02" and int.from_bytes(data[4:8], "big") == 55
    data[4:8] = (10).to_bytes(4, "big")  # the header's record count, lowered
    path.write_bytes(bytes(data))
    line = _refused(["info", str(path)], capsys)
    assert line.endswith(f"{path}: its header counts 10 snapshots but its size holds 55: the header's record "
                         "count hides 45 snapshots (the file is damaged)")
    with pytest.raises(FileFormatError, match="its header counts 10 snapshots but its size holds 55"):
        grainview.open_dataset(path)
    # one whole record beyond the count is a writer killed before its header was updated: accepted
    data[4:8] = (54).to_bytes(4, "big")
    path.write_bytes(bytes(data))
    assert main(["info", str(path)]) == 0
    assert "54 snapshots" in capsys.readouterr().out


def test_a_negative_normal_force_is_refused_everywhere_with_its_contact(tmp_path, capsys):
    path = _netcdf3(tmp_path / "run.nc", n_snapshots=5)
    with netCDF4.Dataset(path, "a") as nc:
        nc.variables["fn"][3, 7] = -50.0
        i, j = int(nc.variables["i"][3, 7]), int(nc.variables["j"][3, 7])
    expected = (f"fn: 1 negative normal force(s) in occupied slots (first: snapshot 3, slot 7, bodies {i} and {j}, "
                "fn = -50 N); expected fn >= 0 (compression positive)")
    assert _refused(["info", str(path)], capsys) == f"grainview: error: {path}: {expected}"
    assert main(["info", str(path), "--check"]) == 2
    assert expected in capsys.readouterr().err
    with pytest.raises(SchemaError) as caught:
        grainview.open_dataset(path, validate=True)
    assert caught.value.problems == [expected]


@pytest.mark.parametrize("variable", ["fn", "ft"])
def test_an_infinite_force_is_refused_without_numpy_warnings(tmp_path, capsys, variable):
    path = _netcdf3(tmp_path / "run.nc", n_snapshots=5)
    with netCDF4.Dataset(path, "a") as nc:
        nc.variables[variable][2, 4] = np.inf
    line = _refused(["info", str(path)], capsys)
    assert line == f"grainview: error: {path}: {variable}: 1 NaN or infinite force(s) in occupied slots"


def test_info_refuses_times_that_do_not_increase(tmp_path, capsys):
    path = _netcdf3(tmp_path / "run.nc", n_snapshots=5)
    with netCDF4.Dataset(path, "a") as nc:
        nc.variables["time"][3] = nc.variables["time"][2]
    line = _refused(["info", str(path)], capsys)
    assert line.endswith("time: 1 snapshot(s) repeating the previous snapshot's time (first: snapshot 3, "
                         "time = 2 s); expected time to increase strictly (each snapshot written once)")


@pytest.mark.parametrize("compress, model", [(False, "netCDF-3"), (True, "netCDF-4, compressed")])
def test_info_prints_the_files_size(tmp_path, capsys, compress, model):
    ds = harmonic_series(n_snapshots=3, n_contacts=20)
    path = tmp_path / "run.nc"
    ds.to_netcdf(path, **netcdf_options(ds, compress=compress))
    assert main(["info", str(path)]) == 0
    size = path.stat().st_size
    assert f"file: {size / 1024:.1f} KiB ({size:,} bytes), {model}" in capsys.readouterr().out.splitlines()


def test_a_foreign_netcdf_file_is_one_line(tmp_path, capsys):
    import xarray as xr

    path = tmp_path / "foreign.nc"
    xr.Dataset({"temperature": ("x", np.arange(3.0))}).to_netcdf(path)
    expected = (f"grainview: error: {path}: not a grainview file: none of the contract's particle or contact "
                "variables (radius, position, i, j, fn...; docs/schema.md)")
    assert _refused(["info", str(path)], capsys) == expected
    assert _refused(["info", str(path), "--check"], capsys) == expected
    with pytest.raises(SchemaError) as caught:
        grainview.open_dataset(path, validate=True)
    assert len(caught.value.problems) == 1


def test_several_contract_problems_are_one_line_and_check_lists_them(tmp_path, capsys):
    ds = harmonic_series(n_snapshots=3, n_contacts=20).drop_vars(["fn", "ft", "branch"])
    path = tmp_path / "three.nc"
    ds.to_netcdf(path, **netcdf_options(ds, compress=False))
    first = "variable 'fn' is missing (expected dims ('time', 'contact'))"
    line = _refused(["info", str(path)], capsys)
    assert line == (f"grainview: error: {path}: 3 problems with the grainview data contract, first: {first}; "
                    f"'grainview info --check {path}' lists them")
    assert _refused(["export", str(path), "--to", "csv", "--out", str(tmp_path / "csv")], capsys) == line
    assert not (tmp_path / "csv").exists()
    assert main(["info", str(path), "--check"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 4 and err[1].endswith(first) and "'ft' is missing" in err[2] and "'branch'" in err[3]


def test_a_file_longer_by_the_writers_blocks_is_not_hiding_records(tmp_path, capsys):
    """The netCDF library grows a file it writes by blocks of a few kB: while a run is written
    (or after its writer is killed) a file with small records is longer than its counted
    records by several records' worth of zero bytes (seen: 16,296 bytes for a 9,116-byte header,
    84 fixed bytes and 4 records of 600 bytes). Those bytes hold no complete flag, so the file
    opens with its counted snapshots and `info` calls it valid; a lowered count over records
    whose flags are set is still refused (the test above)."""
    path = _netcdf3(tmp_path / "run.nc", n_snapshots=5)
    with netCDF4.Dataset(path) as nc:
        record = sum(v.dtype.itemsize * int(np.prod(v.shape[1:])) for v in nc.variables.values()
                     if v.dimensions and v.dimensions[0] == "time")
    path.write_bytes(path.read_bytes() + bytes(3 * record + record // 2))  # 3.5 records of zeros
    ds = grainview.open_dataset(path, chunks=None, validate=True)
    assert ds.sizes["time"] == 5
    assert main(["info", str(path), "--check"]) == 0
    out = capsys.readouterr().out
    assert "5 snapshots" in out and "valid" in out


def test_info_and_its_check_count_the_same_problems(tmp_path, capsys):
    """`info` names how many problems a file has and that --check lists them: --check lists all
    of them, the summary's structural ones (units) as well as the values'."""
    ds = harmonic_series(n_snapshots=5, n_contacts=20).drop_vars(["mass", "inertia"])
    ds["radius"].attrs["units"] = "mm"
    path = tmp_path / "bad.nc"
    ds.to_netcdf(path, **netcdf_options(ds, compress=False))
    line = _refused(["info", str(path)], capsys)
    assert "3 problems" in line and "--check" in line
    assert main(["info", str(path), "--check"]) == 2
    err = capsys.readouterr().err
    listed = [row for row in err.splitlines() if row.strip().startswith("- ")]
    assert len(listed) == 3 and any("'mm'" in row for row in listed), err
