"""A file-size limit (``ulimit -f``, EFBIG) while ``grainview run isotropic`` creates, writes
and compresses its file: one line each, no traceback, nothing half-written left behind, and
no advice to resume a run that cannot be resumed. The commands run in subprocesses under
``resource.setrlimit(RLIMIT_FSIZE)`` with SIGXFSZ ignored (else the kernel kills the process)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

import grainview
from grainview.contract.writer import is_compressed

resource = pytest.importorskip("resource")
REPO = Path(__file__).resolve().parents[2]

LIMITED = """
import os, resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
limit = int(sys.argv[1])
if limit:
    resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
sys.argv = ["grainview", *sys.argv[2:]]
from grainview.app.cli import main
sys.exit(main())
"""
RUN = ["run", "isotropic", "--shape", "disk", "--particles", "12", "--preparation", "fast", "--progress", "off"]


def _run(path, limit, *options):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]))
    return subprocess.run([sys.executable, "-c", LIMITED, str(limit), *RUN, "--out", str(path), *options],
                          cwd=REPO, env=env, capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def plain(tmp_path_factory):
    """Bytes of the run's netCDF-3 file (the header, the static data and one snapshot, padded)
    and of its one record."""
    import netCDF4
    import numpy as np

    from grainview.contract.writer import netcdf3_data_bytes

    path = tmp_path_factory.mktemp("plain") / "iso.nc"
    done = _run(path, 0, "--no-compress")
    assert done.returncode == 0, done.stderr
    with netCDF4.Dataset(path) as nc:
        record = [v.dtype.itemsize * int(np.prod(v.shape[1:])) for v in nc.variables.values()
                  if v.dimensions[:1] == ("time",)]
    return path.stat().st_size, netcdf3_data_bytes([], record)[1]


def _one_error_line(done):
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    assert done.stderr.count("\n") == 1 and done.stderr.startswith("grainview: error:"), done.stderr
    return done.stderr


def test_the_header_beyond_the_limit_leaves_nothing(tmp_path):
    err = _one_error_line(_run(tmp_path / "iso.nc", 2000))
    assert "could not be created (File too large; the file-size limit, ulimit -f, is 2000 bytes)" in err
    assert list(tmp_path.iterdir()) == []  # neither the file, nor its temporary file, nor the lock's note


def test_a_snapshot_beyond_the_limit_is_not_called_resumable(tmp_path, plain):
    size, record = plain
    err = _one_error_line(_run(tmp_path / "iso.nc", size - record))  # within the record (padding < record)
    assert "could not write snapshot 0" in err and "run it again" in err and "resume" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["iso.nc"]


def test_a_compression_beyond_the_limit_keeps_the_whole_run(tmp_path, plain):
    path = tmp_path / "iso.nc"
    err = _one_error_line(_run(path, plain[0] + 4096))  # an HDF5 file of one snapshot is larger
    assert "the run is complete but could not be compressed" in err and "kept uncompressed" in err
    assert "resume" not in err and "solver.restart" not in err  # an isotropic run is not resumed
    assert sorted(p.name for p in tmp_path.iterdir()) == ["iso.nc"]
    assert not is_compressed(path)
    with grainview.open_dataset(path, chunks=None, validate=True) as ds:
        assert ds.sizes["time"] == 1 and ds.attrs["scene"] == "isotropic"
