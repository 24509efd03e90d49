"""Section d: skipping what a scene does not need (per-step costs that a run can avoid)."""

from __future__ import annotations

import copy
import os
import tempfile
import time
import warnings

from benchmarks.common import markdown_table

from .config import Config
from .helpers import dense_sample, reset_meters, run_steps, start_biaxial


def _per_step(sim, steps):
    reset_meters(sim)
    elapsed, _, _, _ = run_steps(sim, steps)
    return elapsed / steps, {k: v / steps for k, v in sim.timings.items()}, dict(sim.counters)


def section_skipping(cfg: Config, series_path=None, log=print):
    from solver.output import OPTIONAL, Recorder

    n, steps = cfg.skip_particles, cfg.skip_steps
    seconds = 5.0 if cfg.quick else 20.0
    rows = []
    samples = {}
    for shape in ("pentagon", "disk"):
        sim, _ = dense_sample(n, shape, seconds, seed=5)
        start_biaxial(sim)
        run_steps(sim, 2)
        samples[shape] = sim
    pent = samples["pentagon"]
    # detection reuse
    for reuse in (True, False):
        sim = copy.deepcopy(pent)
        sim.reuse_detection = reuse
        t, parts, c = _per_step(sim, steps)
        rows.append([f"detection reuse {'on' if reuse else 'off'} (pentagons)", f"{1e3 * t:.2f}",
                     f"broad phase {1e3 * parts['broad_phase']:.3f} ms/step, {c['broad_phase_runs']}/{steps} runs; "
                     f"narrow phase {1e3 * parts['narrow_phase']:.3f} ms/step; NLGS {1e3 * parts['solve']:.2f} ms/step"])
        log(rows[-1])
    # disks vs pentagons narrow phase
    for shape, sim0 in samples.items():
        sim = copy.deepcopy(sim0)
        t, parts, c = _per_step(sim, steps)
        npts = sim.last.n_points
        rows.append([f"{shape} scene: narrow phase", f"{1e3 * t:.2f}",
                     f"narrow phase {1e3 * parts['narrow_phase']:.3f} ms/step = {1e9 * parts['narrow_phase'] / max(npts, 1):.0f} "
                     f"ns/point ({npts} points); " + ("polygon kernels never entered (all n_vertices = 0)"
                                                      if shape == "disk" else "polygon kernels")])
        log(rows[-1])
    # gravity
    for g in ((0.0, 0.0), (0.0, -9.81)):
        sim = copy.deepcopy(pent)
        sim.parameters.gravity = g
        t, parts, c = _per_step(sim, steps)
        rows.append([f"gravity {'zero' if g == (0.0, 0.0) else '9.81 m/s2'} (pentagons)", f"{1e3 * t:.2f}",
                     f"{c['sweeps'] / steps:.0f} NLGS sweeps/step; gravity itself is one vectorised add to the free "
                     "velocities, skipped by an `if` when zero: a step-time difference is the different contact problem"])
        log(rows[-1])
    # optional variables
    for optional, label in ((OPTIONAL, "all optional variables"), ((), "required variables only")):
        sim = copy.deepcopy(pent)
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "run.nc")
            writes = 20 if not cfg.quick else 5
            write_time = 0.0
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                with Recorder(path, sim, optional=optional, compress=False) as rec:
                    for _ in range(writes):
                        sim.step()
                        s = time.perf_counter()
                        rec.write()
                        write_time += time.perf_counter() - s
            size = os.path.getsize(path)
        rows.append([f"output: {label}", "-", f"{1e3 * write_time / writes:.2f} ms/snapshot, "
                     f"{size / writes / 1024:.0f} KiB/snapshot ({writes} snapshots of {n} pentagons)"])
        log(rows[-1])
    # lazy accessor
    if series_path and os.path.exists(series_path):
        import grainview
        ds = grainview.open_dataset(series_path, chunks=25)
        s = time.perf_counter()
        lazy = ds.grain.stress_invariants()
        build = time.perf_counter() - s
        s = time.perf_counter()
        for v in (lazy.values() if hasattr(lazy, "values") and callable(lazy.values) else [lazy]):
            if hasattr(v, "compute"):
                v.compute()
        compute = time.perf_counter() - s
        rows.append(["lazy accessor: stress_invariants on " + os.path.basename(series_path), f"-",
                     f"graph built in {1e3 * build:.1f} ms (nothing computed, nothing read); computing it: {compute:.2f} s"])
        log(rows[-1])
    header = ["case", "ms / step", "what is skipped / measured"]
    text = (f"Dense samples of {n} particles ({seconds:.0f} s of compaction), biaxial steps, {steps} steps per row, "
            "each row from a copy of the same state.\n\n")
    return text + markdown_table(header, rows), rows
