"""The solver's sections of the benchmarks (solver_bench/) and the analysis throughput, one
section per call, each written to its own file.

    python -m benchmarks.sections scaling --out benchmarks/results/scaling.md
    python -m benchmarks.sections stress --quick --out /tmp/stress.md

``python -m benchmarks`` calls this once per section (benchmarks/README.md); run it directly
to measure one section alone. Sections: scaling (solver speed on dense samples, serial and on
2 domains), work_precision, acceleration (needs the fidelity study's 1000-particle runs, built
on first use), peers (pymunk, Box2D; needs the venv of benchmarks/requirements-peers.txt at
/tmp/peervenv or $PEER_PYTHON), analysis (throughput of grainview), skipping (what a scene
does not need), stress (numerical stress tests), ensemble (dask.distributed runner and
out-of-core analysis). Set NUMBA_CACHE_DIR to reuse compiled kernels between runs.
"""

from __future__ import annotations

import argparse
import os
import time

from benchmarks import solver_bench as sb
from benchmarks.common import machine_description

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "_data")
TITLES = {
    "scaling": "Scaling on dense samples, serial and on 2 domains: time per step, per particle, per contact point "
               "per NLGS sweep, memory",
    "work_precision": "Work-precision: run time against error",
    "acceleration": "Fewer sweeps at equal accuracy: candidates against the NLGS",
    "peers": "Peers: pymunk and Box2D on the same settled piles",
    "analysis": "Analysis throughput (grainview)",
    "skipping": "Skipping what a scene does not need",
    "stress": "Numerical stress tests at larger sizes",
    "ensemble": "Ensembles on dask.distributed: runner efficiency, out-of-core analysis",
}
"""Each section's title, in the order of benchmarks/RESULTS.md."""


def _analysis(quick):
    from benchmarks import analysis

    snaps, contacts = (40, 3000) if quick else (1000, 30_000)
    return analysis.run(n_snapshots=snaps, n_contacts=contacts, chunk=10 if quick else 25,
                        n_eager=20 if quick else 50, workdir=DATA)


def _skipping(cfg):
    series = sorted(f for f in os.listdir(DATA) if f.startswith("series_")) if os.path.isdir(DATA) else []
    return sb.section_skipping(cfg, series_path=os.path.join(DATA, series[0]) if series else None)[0]


def _ensemble(quick):
    from benchmarks import ensemble

    folder = os.path.join(DATA, "ensemble_quick" if quick else "ensemble")
    os.makedirs(folder, exist_ok=True)
    return (ensemble.runner_efficiency(folder, **ensemble.RUNNER_SIZES[quick]) + "\n\n"
            + ensemble.out_of_core(folder, **ensemble.OUT_OF_CORE_SIZES[quick]))


def measure(name: str, quick: bool, plot_dir: str) -> str:
    """Run section ``name`` (tiny sizes when ``quick``) and return its Markdown; its plots go
    to ``plot_dir``, beside the file that links them."""
    cfg = sb.Config(quick=quick)
    cfg.plot_dir = plot_dir
    if name == "analysis":
        return _analysis(quick)
    if name == "ensemble":
        return _ensemble(quick)
    if name == "skipping":
        return _skipping(cfg)
    return getattr(sb, f"section_{name}")(cfg)[0]


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m benchmarks.sections", description=__doc__.split("\n\n")[0])
    parser.add_argument("section", choices=list(TITLES), help="the section to measure")
    parser.add_argument("--quick", action="store_true", help="tiny sizes: checks that the section works")
    parser.add_argument("--out", required=True, help="the section's file (Markdown)")
    args = parser.parse_args(argv)
    start = time.perf_counter()
    text = measure(args.section, args.quick, os.path.dirname(os.path.abspath(args.out)))
    run = "quick run: tiny sizes, the numbers only check that the section works" if args.quick else "full run"
    body = [f"# {TITLES[args.section]}", "",
            f"Written by `python -m benchmarks --only {args.section}{' --quick' if args.quick else ''}` ({run}). "
            "See docs/benchmarks.md for what each table means.", "", machine_description(), "", text, "",
            f"_Section time: {time.perf_counter() - start:.0f} s._"]
    with open(args.out, "w") as fh:
        fh.write("\n".join(body) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
