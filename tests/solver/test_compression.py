"""Finished runs are kept compressed: netCDF-3 while a run appends, NETCDF4_CLASSIC with zlib
once it has finished; read unchanged, rewritten atomically, resumable, and safe to open again
and again in one process with dask's threads."""

import os
import subprocess
import sys
import warnings
from pathlib import Path

import netCDF4
import numpy as np
import pytest
import xarray as xr

import grainview
from grainview.contract.errors import ParameterError
from grainview.contract.locks import FileLockedError
from grainview.contract.writer import SnapshotWriter, compress_file, copy_snapshots, decompress_file, is_compressed
from solver import compaction_sample, isotropic_compaction
from solver.output import Recorder

REPO = Path(__file__).resolve().parents[2]


def _raw(path):
    """Every variable's raw stored values (no masking, characters as characters), its dtype,
    dims and attributes, the global attributes, and which dimension is unlimited."""
    with netCDF4.Dataset(path) as nc:
        nc.set_auto_maskandscale(False)
        variables = {}
        for name, var in nc.variables.items():
            var.set_auto_chartostring(False)
            variables[name] = (var[...].copy(), var.dtype, var.dimensions, {k: var.getncattr(k) for k in var.ncattrs()})
        unlimited = [name for name, dim in nc.dimensions.items() if dim.isunlimited()]
        return variables, {k: nc.getncattr(k) for k in nc.ncattrs()}, unlimited


def _assert_same_content(a, b):
    va, ga, ua = _raw(a)
    vb, gb, ub = _raw(b)
    assert list(va) == list(vb)  # the same variables in the same order ("complete" last)
    for name in va:
        (xa, ta, da, aa), (xb, tb, db, ab) = va[name], vb[name]
        assert (ta, da) == (tb, db), name
        np.testing.assert_array_equal(xa, xb, err_msg=name)  # NaN == NaN here, bit patterns of fills kept
        assert aa.keys() == ab.keys(), name
        for key in aa:
            np.testing.assert_array_equal(aa[key], ab[key], err_msg=f"{name}.{key}")
    assert ga.keys() == gb.keys() and ua == ub == ["time"]
    for key in ga:
        np.testing.assert_array_equal(ga[key], gb[key], err_msg=key)


@pytest.fixture(scope="module")
def run_file(tmp_path_factory):
    """A netCDF-3 file of 25 snapshots of a compacting 60-pentagon sample, as the solver
    writes it while running (compress=False)."""
    path = tmp_path_factory.mktemp("run") / "plain.nc"
    sim = compaction_sample(60, "pentagon", seed=3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        isotropic_compaction(sim, max_steps=200, progress=False)
        with Recorder(path, sim, attrs={"scene": "isotropic"}, near_contacts=True, compress=False) as rec:
            for _ in range(25):
                for _ in range(4):
                    sim.step()
                rec.write()
    assert not is_compressed(path)
    return path


def test_compressing_keeps_every_value_and_attribute_and_decompressing_gives_them_back(run_file, tmp_path):
    packed = tmp_path / "packed.nc"
    packed.write_bytes(run_file.read_bytes())
    compress_file(packed)
    assert is_compressed(packed) and packed.stat().st_size < 0.8 * run_file.stat().st_size
    with netCDF4.Dataset(packed) as nc:
        assert nc.data_model == "NETCDF4_CLASSIC"
        assert nc.variables["fn"].filters()["zlib"] and nc.variables["fn"].filters()["shuffle"]
    _assert_same_content(run_file, packed)
    with grainview.open_dataset(run_file, chunks=None) as a, grainview.open_dataset(packed, chunks=None) as b:
        xr.testing.assert_identical(a, b)
        grainview.validate(b)
    compress_file(packed)  # already compressed: left alone
    unpacked = tmp_path / "unpacked.nc"
    unpacked.write_bytes(packed.read_bytes())
    decompress_file(unpacked)
    assert not is_compressed(unpacked)
    with netCDF4.Dataset(unpacked) as nc:
        assert nc.data_model == "NETCDF3_64BIT_OFFSET"
    _assert_same_content(run_file, unpacked)
    for bad in (0, 10, 2.5, True):
        with pytest.raises(ParameterError, match="complevel"):
            compress_file(packed, complevel=bad)


def test_a_failed_conversion_leaves_the_file_as_it_was(run_file, tmp_path, monkeypatch):
    path = tmp_path / "run.nc"
    path.write_bytes(run_file.read_bytes())

    def full_disk(*args):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", full_disk)
    with pytest.raises(OSError, match="No space"):
        compress_file(path)
    monkeypatch.undo()
    assert path.read_bytes() == run_file.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.nc"]  # no temporary file left


def test_a_file_being_written_is_not_converted(run_file, tmp_path):
    path = tmp_path / "run.nc"
    path.write_bytes(run_file.read_bytes())
    with SnapshotWriter.open_append(path):
        with pytest.raises(FileLockedError, match="being written"):
            compress_file(path)
    assert path.read_bytes() == run_file.read_bytes()


@pytest.mark.parametrize("packed", [False, True])
def test_a_copy_of_chosen_snapshots_holds_them_bit_for_bit(run_file, tmp_path, packed):
    """copy_snapshots against the whole file: each kept snapshot's every variable equal, the
    snapshot-free variables and attributes as they were, the source untouched, the copy
    compressed and, decompressed, a file the solver appends to."""
    source = tmp_path / "run.nc"
    source.write_bytes(run_file.read_bytes())
    if packed:
        compress_file(source)
    before = source.read_bytes()
    copy = tmp_path / "copy.nc"
    assert copy_snapshots(source, copy, [0, 7, -1, 7]) == 3  # duplicates once, in the file's order
    assert source.read_bytes() == before and is_compressed(copy)
    whole, attrs, _ = _raw(run_file)
    kept, copy_attrs, unlimited = _raw(copy)
    assert list(kept) == list(whole) and unlimited == ["time"] and copy_attrs.keys() == attrs.keys()
    for name, (values, dtype, dims, _) in whole.items():
        expected = values[[0, 7, 24]] if dims[:1] == ("time",) else values
        np.testing.assert_array_equal(kept[name][0], expected, err_msg=name)
    decompress_file(copy)
    with SnapshotWriter.open_append(copy) as writer:
        assert writer.n_snapshots == 3


def test_a_copy_refuses_missing_snapshots_its_own_source_and_a_file_being_written(run_file, tmp_path):
    source = tmp_path / "run.nc"
    source.write_bytes(run_file.read_bytes())
    with pytest.raises(ParameterError, match="snapshot 25 does not exist .*25 complete snapshots"):
        copy_snapshots(source, tmp_path / "copy.nc", [0, 25])
    with pytest.raises(ParameterError, match="would replace its source"):
        copy_snapshots(source, tmp_path / "." / "run.nc", [0])
    with SnapshotWriter.open_append(source):
        with pytest.raises(FileLockedError, match="being written"):
            copy_snapshots(source, tmp_path / "copy.nc", [0])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.nc"]  # nothing written, no temporary left
    assert source.read_bytes() == run_file.read_bytes()


def test_appending_to_a_compressed_file_makes_it_netcdf3_first(run_file, tmp_path):
    path = tmp_path / "run.nc"
    path.write_bytes(run_file.read_bytes())
    compress_file(path)
    with SnapshotWriter.open_append(path) as writer:
        assert writer.n_snapshots == 25
    assert not is_compressed(path)
    _assert_same_content(run_file, path)


def test_recorder_compresses_a_finished_run_only(tmp_path):
    sim = compaction_sample(12, "disk", seed=0)
    finished, stopped = tmp_path / "finished.nc", tmp_path / "stopped.nc"
    with Recorder(finished, sim) as rec:
        rec.write()
    assert is_compressed(finished)
    with pytest.raises(KeyboardInterrupt):
        with Recorder(stopped, sim) as rec:
            rec.write()
            raise KeyboardInterrupt  # Ctrl-C: the file stays netCDF-3, ready to resume
    assert not is_compressed(stopped)
    for bad in (-1, 10, 2.5):
        with pytest.raises(ParameterError, match="compress"):
            Recorder(tmp_path / "bad.nc", sim, compress=bad)
    assert not (tmp_path / "bad.nc").exists()


REOPEN = """
import sys, warnings
warnings.simplefilter("ignore")
import grainview
for k in range(int(sys.argv[2])):
    for path in sys.argv[3:]:
        ds = grainview.open_dataset(path, chunks={"time": 2})
        ds.grain.stress_invariants()["q_over_p"].mean().compute()
        ds.close()
print("ok", flush=True)
"""


def test_compressed_files_can_be_opened_again_and_again_with_dask_threads(tmp_path):
    """Variable-length strings in an HDF5 file made this machine's netCDF4 1.7 / HDF5 2.2 crash
    (a segmentation fault) when a file read by dask's threads was opened again in the same
    process; the classic data model stores strings as characters. Run in a subprocess, so
    that a crash fails this test instead of ending the test session."""
    from grainview.contract.dataset import netcdf_options
    from grainview.datasets import harmonic_series

    paths = []
    for seed in range(3):
        ds = harmonic_series(n_snapshots=12, n_contacts=1500, seed=seed)
        paths.append(tmp_path / f"s{seed}.nc")
        ds.to_netcdf(paths[-1], **netcdf_options(ds))
        assert is_compressed(paths[-1])
    done = subprocess.run([sys.executable, "-c", REOPEN, "-", "12", *map(str, paths)], cwd=REPO,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and done.stdout.strip() == "ok", (done.returncode, done.stderr[-2000:])


HOLD_OPEN = """
import sys, netCDF4
nc = netCDF4.Dataset(sys.argv[1])  # HDF5 holds a shared lock while the file is open
print("open", flush=True)
sys.stdin.readline()
"""


def test_a_compressed_file_open_in_a_reader_can_be_replaced(run_file, tmp_path):
    """A notebook that has a finished (compressed) run open does not block --overwrite: HDF5's
    own reader lock is not taken for a writer's."""
    path = tmp_path / "run.nc"
    path.write_bytes(run_file.read_bytes())
    compress_file(path)
    reader = subprocess.Popen([sys.executable, "-c", HOLD_OPEN, str(path)], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, text=True)
    try:
        assert reader.stdout.readline().strip() == "open"
        sim = compaction_sample(12, "disk", seed=0)
        with Recorder(path, sim, overwrite=True, compress=False) as rec:
            rec.write()
    finally:
        reader.communicate("\n", timeout=60)
    with grainview.open_dataset(path, chunks=None) as ds:
        assert ds.sizes["particle"] == 12


def test_copy_blocks_cover_every_row_once_in_whole_chunks_within_the_budget():
    from grainview.contract.writer import copy_blocks

    # 1000 rows of 100 bytes, chunks of 3 rows, 1 kB per block: 3 chunks (900 bytes) per block
    blocks = copy_blocks(1000, 100, rows_per_chunk=3, budget=1000)
    assert blocks[0] == slice(0, 9) and blocks[-1] == slice(999, 1000) and len(blocks) == 112
    assert [i for b in blocks for i in range(b.start, b.stop)] == list(range(1000))
    assert all(b.start % 3 == 0 for b in blocks)
    # the largest block does not grow with the number of rows (snapshots)
    for n_rows in (10, 1000, 100_000):
        assert max(b.stop - b.start for b in copy_blocks(n_rows, 100, 1, budget=1000)) == min(n_rows, 10)
    # a row larger than the budget: one row (one chunk) per block
    assert copy_blocks(4, 5000, budget=1000) == [slice(0, 1), slice(1, 2), slice(2, 3), slice(3, 4)]
    assert copy_blocks(0, 100) == []


def test_chunk_rows_one_snapshot_unless_a_snapshot_is_small():
    from grainview.contract.writer import CHUNK_BYTES, chunk_rows

    assert chunk_rows(1_600_000, 40) == 1  # 200,000 forces: one snapshot per chunk
    assert chunk_rows(CHUNK_BYTES, 40) == 1
    assert chunk_rows(CHUNK_BYTES // 4, 40) == 4
    assert chunk_rows(8, 100_000) == CHUNK_BYTES // 8  # time: many snapshots per chunk
    assert chunk_rows(8, 40) == 40  # never beyond the file's snapshots
    assert chunk_rows(8, 0) == 1


def test_deflate_saving_of_incompressible_and_of_empty_slots():
    from grainview.contract.writer import deflate_saving

    rng = np.random.default_rng(0)
    assert deflate_saving([rng.integers(0, 256, 10_000, dtype="u1")]) < 0.01  # random bytes do not shrink
    assert deflate_saving([np.full(10_000, np.nan)]) > 0.99  # empty slots all but vanish
    # half the slots empty, half random doubles: about half is saved, as zlib says on the same bytes
    half = np.concatenate([rng.random(5000), np.full(5000, np.nan)])
    import zlib

    shuffled = half.view("u1").reshape(-1, 8).T.tobytes()
    assert deflate_saving([half], 1) == pytest.approx(1 - len(zlib.compress(shuffled, 1)) / half.nbytes)
    assert 0.45 < deflate_saving([half], 1) < 0.6
    assert deflate_saving([]) == 0.0


def _layout(path):
    with netCDF4.Dataset(path) as nc:
        return {name: (var.chunking(), bool(var.filters()["zlib"])) for name, var in nc.variables.items()
                if var.dimensions[:1] == ("time",)}


def test_compressed_files_have_one_snapshot_per_chunk_and_deflate_only_what_shrinks(tmp_path):
    """Every slot of the harmonic series holds a random force: zlib saves little on fn, normal,
    point (stored as they are) and most of i, j, kind (deflated). compress_file and the xarray
    path (netcdf_options) make the same layout, and the values read back unchanged."""
    from grainview.contract.dataset import netcdf_options
    from grainview.datasets import harmonic_series

    ds = harmonic_series(n_snapshots=6, n_contacts=20_000, seed=1)
    plain, packed, direct = tmp_path / "plain.nc", tmp_path / "packed.nc", tmp_path / "direct.nc"
    ds.to_netcdf(plain, **netcdf_options(ds, compress=False))
    packed.write_bytes(plain.read_bytes())
    compress_file(packed)
    ds.to_netcdf(direct, **netcdf_options(ds))
    layout = _layout(packed)
    for name in ("fn", "normal", "point", "position"):
        assert layout[name][1] is False, name
    for name in ("i", "j", "kind"):
        assert layout[name][1] is True, name
    # one snapshot per chunk; the slots of variables with a fill value in pieces of 64 KiB
    assert layout["i"][0] == [1, 20_000] and layout["fn"][0] == [1, 8192] and layout["normal"][0] == [1, 4096, 2]
    assert layout["contact_count"][0] == [6]  # small rows: the whole (fixed-size) time axis in one chunk
    del layout["time"]  # the coordinate: as xarray writes it
    assert {k: v for k, v in _layout(direct).items() if k != "time"} == layout
    with grainview.open_dataset(plain, chunks=None) as a, grainview.open_dataset(packed, chunks=None) as b, \
            grainview.open_dataset(direct, chunks=None) as c:
        xr.testing.assert_identical(a, b)
        xr.testing.assert_identical(a, c)
    with xr.open_dataset(packed, engine="netcdf4") as d:  # plain xarray reads it too
        np.testing.assert_array_equal(d["fn"].values, ds["fn"].values)


def test_files_compressed_the_previous_way_still_open_unchanged(tmp_path):
    """Files compressed before: zlib 4 on every variable, the netCDF library's own chunks
    (several snapshots per chunk along a fixed-size time)."""
    from grainview.contract.dataset import netcdf_encoding
    from grainview.datasets import harmonic_series

    ds = harmonic_series(n_snapshots=30, n_contacts=3000, seed=2)
    old, plain = tmp_path / "old.nc", tmp_path / "plain.nc"
    encoding = netcdf_encoding(ds)
    for name in encoding:
        if name != "time":
            encoding[name].update(zlib=True, complevel=4, shuffle=True)
    ds.to_netcdf(old, format="NETCDF4_CLASSIC", encoding=encoding)
    ds.to_netcdf(plain, format="NETCDF3_64BIT", encoding=netcdf_encoding(ds))
    with netCDF4.Dataset(old) as nc:
        assert nc.variables["fn"].filters()["zlib"] and nc.variables["fn"].chunking()[0] > 1
    with grainview.open_dataset(old) as a, grainview.open_dataset(plain) as b:
        xr.testing.assert_identical(a.load(), b.load())
        np.testing.assert_allclose(a.grain.stress_invariants()["q_over_p"].values,
                                   b.grain.stress_invariants()["q_over_p"].values, rtol=0, atol=0)


def test_chunks_of_empty_slots_are_not_stored_and_read_back_as_fill(tmp_path):
    """A run whose slots are half empty (NaN from slot 10,240 on, the fill value): the chunks
    that hold only empty slots are left unwritten, so the file is smaller by their bytes, and
    read back the same values bit for bit."""
    from grainview.contract.dataset import netcdf_options
    from grainview.datasets import harmonic_series

    ds = harmonic_series(n_snapshots=6, n_contacts=20_000, seed=1)
    half = ds.copy(deep=True)
    for name in ("fn", "ft", "normal", "point", "branch"):
        half[name][:, 10_240:] = np.nan  # slots 10,240-19,999: 5/4 of the 8192-slot chunks of fn
    sizes = {}
    for label, data in (("full", ds), ("half", half)):
        plain, packed = tmp_path / f"{label}.nc", tmp_path / f"{label}-packed.nc"
        data.to_netcdf(plain, **netcdf_options(data, compress=False))
        packed.write_bytes(plain.read_bytes())
        compress_file(packed)
        sizes[label] = packed.stat().st_size
        if label == "half":
            plain_values, packed_values = _raw(plain)[0], _raw(packed)[0]
            for name, (values, *_) in plain_values.items():  # bit for bit, NaN payloads too
                assert values.tobytes() == packed_values[name][0].tobytes(), name
    # not stored, per snapshot: fn's third chunk of 8192 slots (slots 16,384-19,999; 8192-16,383
    # hold values), and the fourth and fifth chunks of 4096 slots x 2 of normal, point and
    # branch, all four stored as they are (random values); ft's chunk too, deflated or not
    skipped = 6 * (8192 * 8 + 3 * 2 * 4096 * 16)
    assert sizes["full"] - sizes["half"] >= 0.95 * skipped
