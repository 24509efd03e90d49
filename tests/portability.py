"""Digests of everything a run and its analysis produce, for comparing compile targets.

Run as ``python -m tests.portability WORKDIR`` it prints one JSON object: the solver's fingerprint
digests (:mod:`tests.solver.test_fingerprint`); for each of three short ``grainview run`` commands
(pentagons, disks, pentagons on two domains; compaction included) and each file the readers
write from the repository's fixtures, a digest of what a reader of the file sees and one of its
bytes; one per output of every ``ds.grain`` analysis of the pentagons' file and of the converted
LMGC90 fixture (the analyses on an input that does not depend on the solver); and one of the
report's table. :mod:`tests.test_processor_independence` runs it in subprocesses that compile the
numba kernels for different processors (and restrict numpy's and OpenBLAS's kernels to a
processor's instruction set) and requires the same digests from all of them.
"""

from __future__ import annotations

import hashlib
import json
import sys
import warnings
from pathlib import Path

import numpy as np

DATA = Path(__file__).parent / "data"
CONVERSIONS = {  # label: arguments of `grainview convert` (the readers on the repository's fixtures)
    "lammps": ["lammps", "--particles", str(DATA / "lammps" / "dump.particles"),
               "--contacts", str(DATA / "lammps" / "dump.contacts"), "--walls", str(DATA / "lammps" / "dump.walls"),
               "--log", str(DATA / "lammps" / "log.lammps")],
    "lmgc90": ["lmgc90", str(DATA / "lmgc90" / "sample")],
    "mercurydpm": ["mercurydpm", str(DATA / "mercurydpm" / "Settle2D.data"), "--units", "si"],
    "pegs": ["pegs", str(DATA / "pegs" / "Adjacency_list.txt"), "--positions",
             str(DATA / "pegs" / "particle_positions.txt"), "--metres-per-pixel", "4.375e-05", "--force-unit-n", "1"],
    "box2d": ["box2d", str(DATA / "peers" / "box2d"), "--sample", str(DATA / "peers" / "sample.npz")],
}
RUNS = {  # label: arguments of `grainview run`, after the scene
    "pentagons": ["--shape", "pentagon"],
    "disks": ["--shape", "disk"],
    "pentagons_domains": ["--shape", "pentagon", "--domains", "2"],
}
SHORT = ["--particles", "40", "--strain", "0.01", "--every", "40", "--progress", "off"]


def _update(h, value) -> None:
    """Feed ``value`` (arrays, xarray objects, containers, scalars, text) into hash ``h``,
    names and shapes included, in a fixed order."""
    import xarray as xr

    if isinstance(value, xr.Dataset):
        for name in sorted(value.variables):
            h.update(str(name).encode())
            _update(h, value.variables[name])
        _update(h, dict(value.attrs))
    elif isinstance(value, (xr.DataArray, xr.Variable)):
        h.update(repr(value.dims).encode())
        _update(h, value.values)
        _update(h, dict(value.attrs))
    elif isinstance(value, dict):
        for key in sorted(value, key=str):
            h.update(str(key).encode())
            _update(h, value[key])
    elif isinstance(value, (list, tuple)):
        for item in value:
            _update(h, item)
    elif hasattr(value, "to_numpy"):  # a pandas table
        _update(h, list(map(str, getattr(value, "columns", []))))
        _update(h, value.to_numpy())
    else:
        array = np.asarray(value)
        h.update(f"{array.dtype.str}{array.shape}".encode())
        if array.dtype.kind == "O":
            h.update(repr(array.tolist()).encode())
        else:
            h.update(np.ascontiguousarray(array).tobytes())


def digest(value) -> str:
    """SHA-256 (first 16 hex digits) of ``value``'s exact bits (see :func:`_update`)."""
    h = hashlib.sha256()
    _update(h, value)
    return h.hexdigest()[:16]


def file_digest(path: Path) -> str:
    """Digest of every variable (values, dimensions, attributes) and global attribute of a
    netCDF file: what a user reads from it, independent of the HDF5 layout's bytes."""
    import netCDF4

    h = hashlib.sha256()
    with netCDF4.Dataset(path) as nc:
        nc.set_auto_mask(False)
        _update(h, {name: nc.getncattr(name) for name in nc.ncattrs()})
        for name in sorted(nc.variables):
            variable = nc.variables[name]
            h.update(f"{name}{variable.dimensions}".encode())
            _update(h, {key: variable.getncattr(key) for key in variable.ncattrs()})
            _update(h, variable[...])
    return h.hexdigest()[:16]


def analysis_digests(path: Path) -> dict:
    """One digest per analysis of the accessor on the file at ``path`` (computed eagerly)."""
    import grainview
    from grainview.accessor import GrainAccessor, _Delegate

    out = {}
    with grainview.open_dataset(path) as ds:
        for name, member in sorted(vars(GrainAccessor).items()):
            if isinstance(member, _Delegate):
                result = getattr(ds.grain, name)()
                if hasattr(result, "compute"):
                    result = result.compute()
                out[name] = digest(result)
    return out


def all_digests(workdir: Path) -> dict:
    """Every digest of this module, the runs' files written under ``workdir``."""
    from grainview.app.cli import main
    from grainview.contract.errors import ConvergenceWarning
    from tests.solver.test_fingerprint import RUNS as TRAJECTORIES, run

    out = {}
    for label, arguments in CONVERSIONS.items():  # the readers and the analyses on fixed inputs first
        path = workdir / f"{label}-converted.nc"
        main(["convert", *arguments, "--out", str(path), "--overwrite"])
        out[f"convert/{label}"] = file_digest(path)
        out[f"convert-bytes/{label}"] = hashlib.sha256(path.read_bytes()).hexdigest()[:16]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        out.update({f"analysis-lmgc90/{k}": v for k, v in analysis_digests(workdir / "lmgc90-converted.nc").items()})
    out.update({f"trajectory/{name}": run(name)[:16] for name in sorted(TRAJECTORIES)})
    for label, arguments in RUNS.items():
        path = workdir / f"{label}.nc"
        main(["run", "biaxial", *arguments, *SHORT, "--out", str(path), "--overwrite"])
        out[f"file/{label}"] = file_digest(path)
        out[f"file-bytes/{label}"] = hashlib.sha256(path.read_bytes()).hexdigest()[:16]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        out.update({f"analysis/{k}": v for k, v in analysis_digests(workdir / "pentagons.nc").items()})
    report = workdir / "report"
    main(["report", str(workdir / "pentagons.nc"), str(workdir / "disks.nc"), "--labels", "pentagons,disks",
          "--residual-strain", "0.005", "--figures", "03", "--out", str(report), "--overwrite"])
    out["report/headline"] = digest((report / "headline.md").read_text())
    return out


if __name__ == "__main__":
    workdir = Path(sys.argv[1])
    workdir.mkdir(parents=True, exist_ok=True)
    result = all_digests(workdir)
    sys.stdout.write("\nDIGESTS " + json.dumps(result, sort_keys=True) + "\n")
