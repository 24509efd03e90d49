"""Make the Box2D and pymunk fixtures of grainview's peer readers with the real engines.

    python tests/data/peers/make_fixtures.py --peer-python PATH [--out DIR]

1. compacts a 30-pentagon sample with this project (``grainview run isotropic``, seed 3);
2. exports it for the engines (``benchmarks/crosscheck/export.py``'s ``sample_to_npz``);
3. runs the cross-check's engines (``benchmarks/crosscheck/engines_box2d.py`` and
   ``engines_pymunk.py``) through the first 0.4 % of the biaxial test, a snapshot every 50
   steps, with the interpreter ``--peer-python`` (a virtual environment made with
   ``pip install -r benchmarks/requirements-peers.txt``: Box2D 2.3.10, pymunk 7.3.1).

Writes ``sample.npz``, ``box2d/`` and ``pymunk/`` (raw snapshots and meta.json) into ``--out``
(default: this folder, the committed fixtures).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
CROSSCHECK = HERE.parents[2] / "benchmarks" / "crosscheck"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--peer-python", required=True, help="python of a venv with Box2D and pymunk")
    parser.add_argument("--out", type=Path, default=HERE)
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as scratch:
        nc = Path(scratch) / "sample.nc"
        subprocess.run([sys.executable, "-m", "grainview", "run", "isotropic", "--shape", "pentagon",
                        "--particles", "30", "--seed", "3", "--out", str(nc), "--progress", "off"], check=True)
        sys.path.insert(0, str(CROSSCHECK))
        import export

        export.sample_to_npz(str(nc), str(args.out / "sample.npz"))
    for engine in ("box2d", "pymunk"):
        raw = args.out / engine
        for old in raw.glob("*"):
            old.unlink()
        subprocess.run([args.peer_python, str(CROSSCHECK / f"engines_{engine}.py"), str(args.out / "sample.npz"),
                        str(raw), "--strain", "0.004", "--every", "50"], check=True)
    print(f"wrote {args.out}/sample.npz, box2d/, pymunk/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
