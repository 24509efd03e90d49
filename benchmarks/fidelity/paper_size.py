"""The paper-size study's residual state, beside the 400-particle study: the rows of
docs/fidelity.md sections 4, 7 and 8 at 14,400 pentagons and 10,000 disks.

    grainview study --paper-size --jobs 1 --domains 2 --out paper_size      # the runs (hours, resumable)
    grainview study --out study                                              # the 400-particle study (minutes)
    python -m benchmarks.fidelity.paper_size paper_size --reference study    # this page

Reads ``FOLDER/pentagons.nc`` and ``FOLDER/disks.nc`` of each study (or, for a test carried over
sittings, ``python -m benchmarks.fidelity.carry``, the per-snapshot measures kept beside them:
``FOLDER/<label>.measures.nc``) and writes ``benchmarks/fidelity/paper-size.md`` and the figure
``fidelity_paper_size.png`` beside it:

* the size-series rows (the ``sizes`` section of ``python -m benchmarks.fidelity``): window
  means over eps_q 0.3-0.4 and eps_q >= 0.4 of q/p, its two boundary-free checks (the core's
  stress, the walls' forces: :func:`benchmarks.fidelity.measure.boundary_checks`), the harmonic
  predictions, a, a_n, a_t, z, k_d and the very weak fraction;
* the residual state (eps_q >= 0.4) counted two ways, force-bearing contacts and pairs within
  1% of d_min (:data:`benchmarks.fidelity.RELATION_NEAR`): z (with walls, counting points),
  very weak (simple, double), alpha, k_d;
* the paper's twelve relations at each study's size (one seed: no spread);
* each test's inertia numbers, steps and last eps_q;
* q/p, a and z against eps_q for both studies (the figure).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))

from benchmarks.fidelity import figures, measure, relations
from benchmarks.fidelity.__main__ import D_MIN, RELATION_NEAR, RESIDUAL, _f, _table, _window

SAMPLES = {"pentagon": "pentagons.nc", "disk": "disks.nc"}
"""Shape -> the study's file of it."""
WINDOWS = ((0.3, 0.4), RESIDUAL)
"""The shear-strain windows of the size-series rows."""


def study_measures(folder, file) -> dict | None:
    """The per-snapshot measures (:func:`benchmarks.fidelity.measure.snapshot_measures`) of one
    run of a study folder in both counting conventions, {"force-bearing": ..., "near": ...}:
    the carried ones where the folder holds ``<label>.measures.nc`` (a run carried over
    sittings, :mod:`benchmarks.fidelity.carry`), else measured from the run's file; None when
    the folder has neither."""
    from benchmarks.fidelity import carry

    label = os.path.splitext(file)[0]
    if os.path.isfile(carry.measures_path(folder, label)):
        return {how: carry.load_measures(folder, label, how) for how in carry.COUNTINGS}
    path = os.path.join(folder, file)
    if not os.path.isfile(path):
        return None
    return {"force-bearing": measure.snapshot_measures(path), "near": measure.snapshot_measures(path, RELATION_NEAR * D_MIN)}


def run_facts(m) -> dict:
    """Particles, steps, the last eps_q, the median inertia number and the mean stress p (Pa)
    over eps_q >= 0.3 (median, 10th percentile, least and largest: how steady the test's stress
    level is) of a test's measures."""
    eps_q = m["eps_q"].values
    p = m["p"].values[eps_q >= 0.3]
    levels = np.percentile(p, [50, 10, 0, 100]) if p.size else np.full(4, np.nan)
    step = m["step"].values
    return {"particles": int(m.attrs["particles"]), "snapshots": int(m.sizes["time"]),
            "steps": int(step[-1] - step[0]) if step[0] >= 0 else -1, "eps_q max": float(m.attrs["eps_q_max"]),
            "inertia": float(np.median(m["inertia_number"].values)), "velocity": float(m.attrs["velocity"]),
            "compaction steps": int(m.attrs["compaction_steps"]), "p levels": levels}


def size_rows(label, m) -> list:
    """The size-series rows of one test's measures (module docstring), one per window."""
    rows = []
    for window in WINDOWS:
        s = measure.window_means(m, window)
        if not s["snapshots"]:
            rows.append([label, _window(window), 0] + ["-"] * 12)
            continue
        checks = measure.boundary_checks(m, window)
        rows.append([label, _window(window), s["snapshots"], _f(s["q/p"]), _f(checks["q/p central"]),
                     checks["central particles"], _f(checks["q/p walls"]), _f(s["prediction"]),
                     _f(s["prediction cross"]), _f(s["a"], 2), _f(s["a_n"], 2), _f(s["a_t"], 2), _f(s["z"], 2),
                     _f(s["k_d"], 2), _f(s["very weak"], 2)])
    return rows


def residual_states(measures) -> dict:
    """The residual-window summaries (:func:`benchmarks.fidelity.measure.window_means`) of one
    test's measures (:func:`study_measures`), force-bearing and with near pairs counted:
    {"force-bearing": ..., "near": ...}."""
    counted = {how: measure.window_means(m, RESIDUAL) for how, m in measures.items()}
    initial = float(measures["force-bearing"]["solid_fraction"].values[0])  # the test's start: the compacted sample
    for summary in counted.values():
        summary["solid fraction initial"] = initial
    return counted


STATE_COLUMNS = (("q/p", 3), ("a", 2), ("a_n", 2), ("a_t", 2), ("z", 2), ("z with walls", 2), ("z points", 2),
                 ("alpha", 2), ("weak", 2), ("very weak", 2), ("very weak simple", 2), ("very weak double", 2),
                 ("k_d", 2), ("q_d/p", 3), ("q_s/p", 3))
"""(window_means key, digits) of the residual-state table."""


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m benchmarks.fidelity.paper_size", description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", help="the paper-size study's output folder (pentagons.nc, disks.nc)")
    parser.add_argument("--reference", help="the 400-particle study's output folder, for the rows beside it")
    parser.add_argument("--output", default=os.path.join(HERE, "paper-size.md"), help="the page to write")
    argv = sys.argv[1:] if argv is None else list(argv)
    args = parser.parse_args(argv)
    studies = {"paper size": args.folder}
    if args.reference:
        studies = {"400": args.reference, **studies}
    start = time.perf_counter()
    present = {}
    for name, folder in studies.items():
        for shape, file in SAMPLES.items():
            measured = study_measures(folder, file)
            if measured is not None:
                present[(name, shape)] = measured
    if not present:
        raise SystemExit(f"{args.folder}: no {' or '.join(SAMPLES.values())} and no carried measures of them "
                         "(expected a study's output folder, or a carry folder)")
    missing = [f"{name} {shape}s" for name in studies for shape in SAMPLES if (name, shape) not in present]
    facts, sizes, states, curves = [], [], {}, []
    for (name, shape), measured in present.items():
        m = measured["force-bearing"]
        f = run_facts(m)
        label = f"{shape}s {f['particles']}"
        print(f"{label}: {f['snapshots']} snapshots, eps_q up to {f['eps_q max']:.3f} ...", flush=True)
        median, tenth, least, largest = f["p levels"] / 1e3
        facts.append([label, f["compaction steps"], f["steps"], f["snapshots"], f"{f['velocity'] * 100:g}",
                      f"{f['inertia']:.1e}", _f(f["eps_q max"]),
                      f"{median:.1f}, {tenth:.1f}, {least:.1f}-{largest:.1f}"])
        sizes += size_rows(label, m)
        states[(name, shape)] = residual_states(measured)
        curves.append((f"{shape}s, N = {f['particles']}", shape, measure.strain_series(m)))
    state_rows = []
    for (name, shape), counted in states.items():
        for how, s in counted.items():
            state_rows.append([f"{shape}s ({name})", how, s.get("snapshots", 0)]
                              + [_f(s[k], d) if k in s else "-" for k, d in STATE_COLUMNS])
    relation_columns = []
    for name in studies:
        for how in ("force-bearing", "near"):
            if (name, "pentagon") not in states or (name, "disk") not in states:
                continue
            p, d = states[(name, "pentagon")][how], states[(name, "disk")][how]
            if p.get("snapshots") and d.get("snapshots"):
                relation_columns.append((f"{name}, {how}", relations.evaluate([p], [d])))
    relation_rows = []
    if relation_columns:
        for k, (relation, paper, *_rest) in enumerate(relation_columns[0][1]):
            relation_rows.append([relation, paper] + [f"{'holds' if res[k][3] else 'FAILS'}: {res[k][2]}"
                                                      for _, res in relation_columns])
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    figure = figures.evolutions(curves, os.path.join(os.path.dirname(os.path.abspath(args.output)),
                                                     "fidelity_paper_size.png"),
                                "400 particles and the paper's size (one seed each)")
    held = "; ".join(f"{label}: {sum(r[3] for r in res)}/12" for label, res in relation_columns)
    near = f"pairs within {RELATION_NEAR:.0%} of d_min ({RELATION_NEAR * D_MIN * 1e3:g} mm)"
    text = [
        "# The paper's size: 14,400 pentagons and 10,000 disks",
        "",
        f"Made by `python -m benchmarks.fidelity.paper_size {' '.join(argv)}` (its docstring), "
        f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, in {time.perf_counter() - start:.0f} s. "
        "Read with docs/fidelity.md, sections 4, 7 and 8. One seed per size."
        + (f" Not there (yet): {', '.join(missing)}." if missing else ""),
        "",
        "## The runs",
        "",
        _table(["sample", "compaction steps", "test steps", "snapshots", "top wall (cm/s)",
                "inertia number I (median)", "eps_q reached",
                "p over eps_q >= 0.3 (kPa): median, 10th percentile, range"], facts),
        "",
        f"![q/p, a and z against eps_q]({os.path.basename(figure)})",
        "",
        "## Size-series rows",
        "",
        "Window means; q/p central: the stress of the particles farther than three largest diameters from "
        "every wall; q/p walls: from the wall forces alone (benchmarks/fidelity/measure.py).",
        "",
        _table(["sample", "eps_q", "snapshots", "q/p", "q/p central", "central particles", "q/p walls",
                "(a'+a_n+a_t)/2", "(a'+a_n+a_t)/(2+a'a_n)", "a", "a_n", "a_t", "z", "k_d", "very weak"], sizes),
        "",
        "## Residual state (eps_q >= 0.4), counted two ways",
        "",
        f"force-bearing: contacts that carry a force; near: also the {near}.",
        "",
        _table(["sample", "counted", "snapshots"] + [k for k, _ in STATE_COLUMNS], state_rows),
        "",
        "## The twelve relations",
        "",
        f"Each shape's residual state (eps_q >= 0.4) of one seed at each size. Relations that hold: {held}.",
        "",
        _table(["relation", "paper"] + [label for label, _ in relation_columns], relation_rows) if relation_rows
        else "(no residual window reached)",
        "",
    ]
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    with open(args.output + ".part", "w") as fh:
        fh.write("\n".join(text))
    os.replace(args.output + ".part", args.output)
    print(f"wrote {args.output} and {figure}")


if __name__ == "__main__":
    main()
