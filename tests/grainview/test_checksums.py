"""A flipped bit in a finished file is an error, not a changed force: compressed files carry
HDF5's Fletcher-32 checksums, a chunk that fails its checksum is one line naming the file
wherever it is read, files without checksums still open, and ``info --check`` names a file
without its schema version."""

import warnings

import netCDF4
import numpy as np
import pytest

import grainview
import grainview.contract.writer as writer
from grainview.datasets import harmonic_series
from grainview.app.cli import main
from grainview.contract.dataset import netcdf_options
from grainview.contract.errors import FileFormatError
from grainview.contract.reader import ContractFile
from grainview.contract.writer import compress_file

SNAPSHOTS, CONTACTS, DAMAGED = 4, 10_000, 2


@pytest.fixture(scope="module")
def series():
    """Random forces in every slot: zlib saves too little on ``fn`` for it to be deflated, so
    its chunks hold its values' bytes as they are and can be found in the file."""
    return harmonic_series(n_snapshots=SNAPSHOTS, n_contacts=CONTACTS, seed=3)


def _finished(series, path):
    """``series`` as a finished run is kept: written as netCDF-3, then compress_file."""
    series.to_netcdf(path, **netcdf_options(series, compress=False))
    compress_file(path)
    return path


def _flip_a_byte_of_fn(path, series, snapshot=DAMAGED):
    """Flip one bit of one byte of ``fn`` at ``snapshot`` inside its stored chunk, found by its
    values' bytes (found once, in a chunk stored without deflation); returns the flipped slot."""
    with netCDF4.Dataset(path) as nc:
        assert not nc.variables["fn"].filters()["zlib"]  # stored as it is: its bytes are in the file
    data = bytearray(path.read_bytes())
    values = series["fn"].values[snapshot]
    marker = values[100:164].tobytes()  # 64 forces of the first chunk of the snapshot's slots
    assert data.count(marker) == 1
    slot = 100 + 20
    offset = data.find(marker) + 20 * 8 + 3  # the third byte of the 21st force: a mantissa byte
    data[offset] ^= 0x10
    path.write_bytes(bytes(data))
    return slot


def _one_line(argv, capsys):
    """Exit code 2 and one line of stderr, nothing said valid."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert main(argv) == 2
    out, err = capsys.readouterr()
    assert "valid" not in out and not caught, (out, [str(w.message) for w in caught])
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("grainview: error: "), err
    return lines[0]


def test_every_variable_of_a_finished_file_has_a_checksum(series, tmp_path):
    packed = _finished(series, tmp_path / "packed.nc")
    direct = tmp_path / "direct.nc"
    series.to_netcdf(direct, **netcdf_options(series))  # the same through xarray
    for path in (packed, direct):
        with netCDF4.Dataset(path) as nc:
            without = [name for name, var in nc.variables.items() if var.ndim and not var.filters()["fletcher32"]]
            assert without == [], (path.name, without)
    plain = tmp_path / "plain.nc"
    series.to_netcdf(plain, **netcdf_options(series, compress=False))
    with netCDF4.Dataset(plain) as nc:  # netCDF-3, as a run is written while it goes on: no filters at all
        assert nc.data_model.startswith("NETCDF3") and nc.variables["fn"].filters() is None


def test_a_flipped_byte_is_a_one_line_error_naming_the_file_not_another_force(series, tmp_path, capsys):
    path = _finished(series, tmp_path / "run.nc")
    slot = _flip_a_byte_of_fn(path, series)
    expected = f"{path}: fn: its stored data cannot be read"

    # eagerly, lazily through dask, and through an analysis
    with grainview.open_dataset(path, chunks=None) as ds:
        with pytest.raises(FileFormatError, match=expected) as caught:
            ds["fn"].values
        assert "\n" not in str(caught.value) and "checksum" in str(caught.value)
        np.testing.assert_array_equal(ds["fn"].isel(time=0).values, series["fn"].values[0])  # other chunks read
    with grainview.open_dataset(path) as ds:
        with pytest.raises(FileFormatError, match=expected):
            ds.grain.stress_invariants()["q_over_p"].compute()
    # the plain reader (the solver's, to resume)
    with ContractFile(path) as f:
        np.testing.assert_array_equal(f.snapshot("fn", 0), series["fn"].values[0])
        with pytest.raises(FileFormatError, match=expected):
            f.snapshot("fn", DAMAGED)
        with pytest.raises(FileFormatError, match=expected):
            f.series("fn")
    # the command line: info reads fn; --check reads every chunk of every variable
    for argv in (["info", str(path)], ["info", str(path), "--check"]):
        line = _one_line(argv, capsys)
        assert str(path) in line and "fn" in line and "checksum" in line, line
    line = _one_line(["info", str(path), "--check"], capsys)
    assert f"fn: 1 snapshot(s) whose stored data cannot be read (first: snapshot {DAMAGED};" in line, line

    # without the checksum the same flip is read as another force, silently
    unguarded = tmp_path / "unguarded.nc"
    original = writer.CHECKSUMS
    try:
        writer.CHECKSUMS = False
        _finished(series, unguarded)
    finally:
        writer.CHECKSUMS = original
    assert _flip_a_byte_of_fn(unguarded, series) == slot
    with grainview.open_dataset(unguarded, chunks=None) as ds:
        changed = np.flatnonzero(ds["fn"].values[DAMAGED] != series["fn"].values[DAMAGED])
        assert changed.tolist() == [slot]


def test_info_check_finds_a_damaged_chunk_that_plain_info_does_not_read(series, tmp_path, capsys):
    """``position`` is not read by the summary; ``--check`` reads every stored chunk."""
    path = _finished(series, tmp_path / "run.nc")
    with netCDF4.Dataset(path) as nc:
        assert not nc.variables["position"].filters()["zlib"]
    data = bytearray(path.read_bytes())
    marker = np.ascontiguousarray(series["position"].values[1, :64]).tobytes()
    assert data.count(marker) == 1
    data[data.find(marker) + 100] ^= 0x01
    path.write_bytes(bytes(data))
    assert main(["info", str(path)]) == 0
    capsys.readouterr()
    line = _one_line(["info", str(path), "--check"], capsys)
    assert line.startswith(f"grainview: error: {path}: position: 1 snapshot(s) whose stored data cannot be read "
                           "(first: snapshot 1;"), line


def test_a_file_without_checksums_still_opens_and_checks(series, tmp_path, capsys):
    old = tmp_path / "old.nc"
    original = writer.CHECKSUMS
    try:
        writer.CHECKSUMS = False  # as files were compressed before checksums
        _finished(series, old)
    finally:
        writer.CHECKSUMS = original
    with netCDF4.Dataset(old) as nc:
        assert not any(var.filters()["fletcher32"] for var in nc.variables.values() if var.ndim)
    with grainview.open_dataset(old, chunks=None, validate=True) as ds:
        np.testing.assert_array_equal(ds["fn"].values, series["fn"].values)
    with ContractFile(old) as f:
        np.testing.assert_array_equal(f.series("fn"), series["fn"].values)
    assert main(["info", str(old), "--check"]) == 0
    assert "valid: every value checked" in capsys.readouterr().out


@pytest.mark.parametrize("compress", [False, True])
def test_a_file_without_its_schema_version_is_named_by_info_check(series, tmp_path, capsys, compress):
    path = tmp_path / "unversioned.nc"
    series.to_netcdf(path, **netcdf_options(series, compress=False))
    with netCDF4.Dataset(path, "a") as nc:
        assert nc.getncattr("grainview_schema_version") == "1.0"
        nc.delncattr("grainview_schema_version")
    if compress:
        compress_file(path)
    line = _one_line(["info", str(path), "--check"], capsys)
    assert line == (f"grainview: error: {path}: global attribute grainview_schema_version is missing: which version "
                    "of the contract the file follows is unknown (every file grainview writes has it; "
                    "docs/schema.md, \"Global attributes\")")
    assert main(["info", str(path)]) == 0  # the summary, with a note
    out = capsys.readouterr().out
    assert "note: the file has no grainview_schema_version attribute" in out


def test_a_flipped_byte_in_an_attribute_is_refused_in_one_line(series, tmp_path, capsys):
    """HDF5's own headers (where the attributes are) carry checksums too: the file does not
    open, rather than giving the run another setting."""
    noted = series.copy()
    noted.attrs["solver_note"] = "friction 0.4000 and seed 123456"
    path = _finished(noted, tmp_path / "run.nc")
    with grainview.open_dataset(path, chunks=None) as ds:
        assert ds.attrs["solver_note"] == "friction 0.4000 and seed 123456"
    data = bytearray(path.read_bytes())
    marker = b"friction 0.4000 and seed 123456"
    assert data.count(marker) == 1
    data[data.find(marker) + len("friction 0.400")] ^= 0x01  # 0.4000 -> 0.4001
    path.write_bytes(bytes(data))
    with pytest.raises(FileFormatError, match=f"{path}: not a readable netCDF file") as caught:
        grainview.open_dataset(path)
    assert "\n" not in str(caught.value)
    line = _one_line(["info", str(path), "--check"], capsys)
    assert line.startswith(f"grainview: error: {path}: not a readable netCDF file"), line


def test_a_lazily_opened_dataset_pickles_and_still_names_a_damaged_chunk(series, tmp_path):
    """What dask.distributed or multiprocessing does with an opened file: pickle.dumps, then
    pickle.loads elsewhere; the values read back and a damaged chunk is still one line."""
    import pickle

    good = _finished(series, tmp_path / "good.nc")
    with grainview.open_dataset(good) as ds:
        copy = pickle.loads(pickle.dumps(ds))
    np.testing.assert_array_equal(copy["fn"].values, series["fn"].values)
    copy.close()
    bad = _finished(series, tmp_path / "bad.nc")
    _flip_a_byte_of_fn(bad, series)
    with grainview.open_dataset(bad) as ds:
        copy = pickle.loads(pickle.dumps(ds))
    with pytest.raises(FileFormatError, match=f"{bad}: fn: its stored data cannot be read"):
        copy["fn"].values
    copy.close()
