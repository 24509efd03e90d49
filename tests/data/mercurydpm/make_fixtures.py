"""Make grainview's MercuryDPM fixtures by running the Settle2D driver (this folder).

    python tests/data/mercurydpm/make_fixtures.py [--seed K] [--out DIR] [--build DIR]

MercuryDPM has no package on the index: ``build_mercurydpm.sh SOURCE BUILD`` builds its kernel
and the driver ``Settle2D.cpp`` from a MercuryDPM source tree. This script runs the executable
``BUILD/Settle2D`` (``--build``, or $GRAINVIEW_MERCURYDPM_BUILD; default /work/mercury-build) in
``--out`` (default: this folder, the committed fixtures), which writes ``Settle2D.data``,
``Settle2D.fstat`` and ``Settle2D.restart``.
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


def find_driver(build=None) -> Path | None:
    """The Settle2D executable of a MercuryDPM build folder, or None."""
    folder = Path(build or os.environ.get("GRAINVIEW_MERCURYDPM_BUILD", DEFAULT_BUILD))
    driver = folder / "Settle2D"
    return driver if driver.is_file() and os.access(driver, os.X_OK) else None


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
    parser.add_argument("--out", type=Path, default=HERE)
    parser.add_argument("--build", help="the MercuryDPM build folder holding Settle2D")
    args = parser.parse_args(argv)
    run(args.out, args.seed, args.build)
    print(f"wrote {', '.join(str(args.out / name) for name in FILES)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
