"""Make grainview's MercuryDPM fixtures by running the drivers of this folder.

    python tests/data/mercurydpm/make_fixtures.py [--seed K] [--out DIR] [--build DIR]
    python tests/data/mercurydpm/make_fixtures.py --periodic [--seed K] [--out DIR] [--build DIR]

MercuryDPM has no package on the index: ``build_mercurydpm.sh SOURCE BUILD`` builds its kernel
and the drivers ``Settle2D.cpp`` and ``Periodic2D.cpp`` from a MercuryDPM source tree. This
script runs the executable ``BUILD/Settle2D`` (``--build``, or $GRAINVIEW_MERCURYDPM_BUILD;
default /work/mercury-build) in ``--out`` (default: this folder, the committed fixtures), which
writes ``Settle2D.data``, ``Settle2D.fstat`` and ``Settle2D.restart``; with ``--periodic``,
``BUILD/Periodic2D`` four times (default ``--out``: this folder's ``periodic/``), which writes
``Periodic2D.*`` (periodic in x and y), ``LeesEdwards2D.*`` (a LeesEdwardsBoundary shearing),
``Channel2D.*`` (periodic in x, walls across y) and ``Tilted2D.*`` (a fixed tilted cell: the
PeriodicBoundary across y shifts its images in x too).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
DEFAULT_BUILD = "/work/mercury-build"
FILES = ("Settle2D.data", "Settle2D.fstat", "Settle2D.restart")
PERIODIC = {"periodic": "Periodic2D", "lees": "LeesEdwards2D", "channel": "Channel2D", "tilted": "Tilted2D"}
"""Periodic2D's modes and the run name each writes (NAME.data, NAME.fstat, NAME.restart)."""


def find_driver(build=None, name="Settle2D") -> Path | None:
    """The executable ``name`` (Settle2D or Periodic2D) of a MercuryDPM build folder, or None."""
    folder = Path(build or os.environ.get("GRAINVIEW_MERCURYDPM_BUILD", DEFAULT_BUILD))
    driver = folder / name
    return driver if driver.is_file() and os.access(driver, os.X_OK) else None


def run_periodic(out: Path, mode: str, seed: int = 1, build=None) -> Path:
    """Run ``Periodic2D mode seed`` in ``out`` (mode: a key of :data:`PERIODIC`); returns the
    path of the run's ``.data`` file. Raises RuntimeError when the driver is missing or fails."""
    driver = find_driver(build, "Periodic2D")
    if driver is None:
        raise RuntimeError("MercuryDPM's Periodic2D driver not found: build it with tests/data/mercurydpm/"
                           "build_mercurydpm.sh SOURCE BUILD (or set GRAINVIEW_MERCURYDPM_BUILD)")
    name = PERIODIC[mode]
    files = [out / f"{name}{suffix}" for suffix in (".data", ".fstat", ".restart")]
    out.mkdir(parents=True, exist_ok=True)
    for path in files:
        path.unlink(missing_ok=True)
    done = subprocess.run([str(driver), mode, str(seed)], cwd=out, capture_output=True, text=True)
    if done.returncode != 0 or not all(path.is_file() for path in files):
        raise RuntimeError(f"Periodic2D {mode} failed ({done.returncode}): {(done.stdout + done.stderr).strip()[-500:]}")
    (out / f"{name}.xballs").unlink(missing_ok=True)
    return files[0]


def run(out: Path, seed: int = 1, build=None) -> Path:
    """Run Settle2D with ``seed`` in ``out``; returns ``out``. Raises RuntimeError when the
    driver is missing or fails."""
    driver = find_driver(build)
    if driver is None:
        raise RuntimeError("MercuryDPM's Settle2D driver not found: build it with tests/data/mercurydpm/"
                           "build_mercurydpm.sh SOURCE BUILD (or set GRAINVIEW_MERCURYDPM_BUILD)")
    out.mkdir(parents=True, exist_ok=True)
    for name in FILES:
        (out / name).unlink(missing_ok=True)
    done = subprocess.run([str(driver), str(seed)], cwd=out, capture_output=True, text=True)
    if done.returncode != 0 or not all((out / name).is_file() for name in FILES):
        raise RuntimeError(f"Settle2D failed ({done.returncode}): {(done.stdout + done.stderr).strip()[-500:]}")
    (out / "Settle2D.xballs").unlink(missing_ok=True)  # an XBalls script, not needed
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--out", type=Path)
    parser.add_argument("--build", help="the MercuryDPM build folder holding Settle2D and Periodic2D")
    parser.add_argument("--periodic", action="store_true", help="the periodic runs (Periodic2D) instead of Settle2D")
    args = parser.parse_args(argv)
    if args.periodic:
        out = args.out or HERE / "periodic"
        for mode in PERIODIC:
            print(f"wrote {run_periodic(out, mode, args.seed, args.build).with_suffix('.*')}")
        return 0
    args.out = args.out or HERE
    run(args.out, args.seed, args.build)
    print(f"wrote {', '.join(str(args.out / name) for name in FILES)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
