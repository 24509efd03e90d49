"""How steady a walled test's stress is over its residual window, one row per test: the table of
docs/fidelity.md, "Why the walled stress swings".

    python -m benchmarks.fidelity.swings FILE [FILE ...] [--window 0.4]

Each FILE is a walled biaxial test's file, or the measures a carry folder keeps of a test run
over several sittings (``<label>.measures.nc``, :mod:`benchmarks.fidelity.carry`). The columns:
the top wall's speed v; the paper's inertia number at the test's start; the right wall's mass
over the sample's; the window's snapshots; the share of them whose contact sigma_xx, and whose
right wall's stress, is below sigma0/2 (:mod:`benchmarks.wall_motion`); the mean stress p over
the window (10th-90th percentiles, least-largest); and the window means of q/p, a, z and the very
weak fraction (:func:`benchmarks.fidelity.measure.window_means`, force-bearing contacts).
It only reads; the table is printed.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

HEADER = ["v (cm/s)", "I", "right wall / sample", "snapshots", "sigma_xx < sigma0/2", "wall's stress < sigma0/2",
          "p (kPa), 10-90%", "p (kPa), min-max", "q/p", "a", "z", "very weak"]


def swing_row(measures, window=0.4) -> list:
    """The row (:data:`HEADER`) of one walled test's measures
    (:func:`benchmarks.fidelity.measure.snapshot_measures`, force-bearing)."""
    from benchmarks.fidelity.measure import window_means
    from benchmarks.wall_motion import wall_motion

    motion = wall_motion(measures, window)
    means = window_means(measures, (window, np.inf))
    p = measures["p"].values[measures["eps_q"].values >= window] / 1e3
    low, high = means["p 10-90%"]
    return [f"{100 * motion['velocity']:.2g}", f"{measures.attrs['inertia_number_start']:.1e}",
            f"{motion['mass ratio']:.2g}", motion["snapshots"], f"{100 * motion['sxx<1/2']:.0f}%",
            f"{100 * motion['wall<1/2']:.0f}%", f"{low / 1e3:.1f}-{high / 1e3:.1f}", f"{p.min():.1f}-{p.max():.1f}",
            f"{means['q/p']:.3f}", f"{means['a']:.3f}", f"{means['z']:.2f}", f"{means['very weak']:.3f}"]


def main(argv=None) -> int:
    from benchmarks.common import markdown_table
    from benchmarks.fidelity.measure import snapshot_measures
    from benchmarks.wall_motion import carried_or_file
    from grainview.contract.errors import GrainviewError

    parser = argparse.ArgumentParser(prog="python -m benchmarks.fidelity.swings", description=__doc__.split("\n\n")[0])
    parser.add_argument("files", nargs="+", help="walled biaxial test files, or carried measures (<label>.measures.nc)")
    parser.add_argument("--window", type=float, default=0.4, help="the residual window's first eps_q (default 0.4)")
    args = parser.parse_args(argv)
    rows = []
    try:
        for path in args.files:
            source = carried_or_file(path)
            measures = snapshot_measures(source) if source is path else source
            rows.append(swing_row(measures, args.window))
    except (ValueError, OSError, GrainviewError) as exc:
        parser.error(str(exc))
    print(markdown_table(["file"] + HEADER, [[path] + row for path, row in zip(args.files, rows)]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
