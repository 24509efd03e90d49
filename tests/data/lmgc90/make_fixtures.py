"""Run LMGC90 on the two scenes of gen_sample.py and keep what the reader's tests read.

    python tests/data/lmgc90/make_fixtures.py            # rewrites sample/ and handmade/ here
    python tests/data/lmgc90/make_fixtures.py periodic   # rewrites periodic/ (x period 10 m)

LMGC90 has no wheel: build it first with build_lmgc90.sh (its build folder, /work/lmgc90-build
by default, or the folder named by LMGC90_BUILD, holds the ``pylmgc90`` package). :func:`run`
is also what the test that regenerates a run calls.

Kept: ``DATBOX/BODIES.DAT``, ``BULK_BEHAV.DAT``, ``TACT_BEHAV.DAT`` and ``OUTBOX/DOF.OUT.n``,
``Vloc_Rloc.OUT.n``; the other files LMGC90 writes (``*.OUT`` copies of DATBOX, timers) are not.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
DEFAULT_BUILD = "/work/lmgc90-build"
KEEP = {"DATBOX": ("BODIES.DAT", "BULK_BEHAV.DAT", "TACT_BEHAV.DAT"), "OUTBOX": ("DOF.OUT.", "Vloc_Rloc.OUT.")}


def find_build():
    """The LMGC90 build folder holding ``pylmgc90`` (LMGC90_BUILD or /work/lmgc90-build), or None."""
    folder = Path(os.environ.get("LMGC90_BUILD", DEFAULT_BUILD))
    return folder if any((folder / "pylmgc90" / "chipy").glob("_lmgc90*.so")) else None


def run(folder, scene="sample", seed=7):
    """Write the scene's DATBOX into ``folder`` and run LMGC90 there; returns ``folder``."""
    build = find_build()
    if build is None:
        raise RuntimeError("no LMGC90 build: run tests/data/lmgc90/build_lmgc90.sh (or set LMGC90_BUILD)")
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(build)] + [p for p in [os.environ.get("PYTHONPATH")] if p]))
    for script, extra in (("gen_sample.py", ["--seed", str(seed)]), ("command.py", [])):
        done = subprocess.run([sys.executable, str(HERE / script), "--scene", scene, *extra], cwd=folder, env=env,
                              capture_output=True, text=True)
        if done.returncode != 0:
            raise RuntimeError(f"{script} --scene {scene} failed: {done.stderr.strip().splitlines()[-1:]}")
    return folder


def keep(source, target):
    """Copy the files the tests read from run folder ``source`` into ``target``."""
    for box, names in KEEP.items():
        (target / box).mkdir(parents=True, exist_ok=True)
        for path in sorted((source / box).iterdir()):
            if any(path.name == n or (n.endswith(".") and path.name.startswith(n)) for n in names):
                shutil.copy(path, target / box / path.name)


def main():
    for scene in sys.argv[1:] or ("sample", "handmade"):
        with tempfile.TemporaryDirectory() as tmp:
            folder = run(Path(tmp) / scene, scene)
            target = HERE / scene
            shutil.rmtree(target, ignore_errors=True)
            keep(folder, target)
            print(f"wrote {target}")


if __name__ == "__main__":
    main()
