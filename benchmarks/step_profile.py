"""Where a biaxial step's time goes, on one domain and on several: the whole-step speed-up's account.

    python -m benchmarks.step_profile --sample benchmarks/_data/samples/pentagon_4000_fast.pkl --domains 1,2

A sample saved by ``compaction.py --save`` is sheared as the shear benchmarks shear it
(``solver.biaxial_test``, top wall at 1 cm/s, Anderson sweeps with an extrapolation every 2
sweeps and the stall test over 200; ``benchmarks.shear.shear``) for ``--skip`` steps, and the
next ``--steps`` steps are timed stage by stage, by the stepper itself
(``Simulation.timings``, whose stages ``solver.stepper.STAGES`` are disjoint and add up to the
time spent in ``Simulation.step``):

- broad phase and narrow phase;
- warm start: the points' keys and the matching of last step's impulses;
- contact problem: the free velocities and the step's :class:`solver.nlgs.ContactProblem`;
- solve: the step's solver (``Parameters.solver``, its domain decomposition included);
- overlap recovery: the split-impulse pass (a second, frictionless solve, when overlaps remain);
- diagnostics: the local-law residual and the unbalanced force of every step;
- update, other: the rest of the end of the step (end velocities, integration, bookkeeping);
- step, other: the rest of ``Simulation.step`` (the alert distance, the convergence count, the
  step's record);
- outside the step: what ``biaxial_test`` does between steps (wall control, output checks).

Each domain count shears its own copy of the sample, in turns (``--repeats``: the order
reversed every other turn, so that the machine's drift falls on each alike). Domain counts
above 1 follow another trajectory (a domain-decomposed sweep is another Gauss–Seidel order),
so their sweeps per step differ a little; the table gives them. Stages that only numpy and
Python do run on one core whatever the domains: with the solve's and the narrow phase's
speed-ups they bound the whole step's (Amdahl). Writes benchmarks/results/step-profile-<N>.md.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))

from benchmarks.common import load_sample, write_results

STAGES = ["broad phase", "narrow phase", "warm start", "contact problem", "solve", "overlap recovery",
          "diagnostics", "update, other", "step, other", "outside the step"]
"""The stages of the table, in the order of a step."""
TIMINGS = {"broad_phase": "broad phase", "narrow_phase": "narrow phase", "warm_start": "warm start",
           "contact_problem": "contact problem", "solve": "solve", "overlap_recovery": "overlap recovery",
           "diagnostics": "diagnostics", "update": "update, other", "other": "step, other"}
"""The stepper's stages (``solver.stepper.STAGES``, keys of ``Simulation.timings``) and their row."""


def profile(sim, skip: int, steps: int, domains: int = 1) -> dict:
    """Shear ``sim`` (module docstring) on ``domains`` NLGS domains ``skip`` steps, then time
    ``steps`` steps by stage, from the simulation's own stage timings (``Simulation.timings``).
    Returns ms per step per stage (``ms``), the steps timed (``steps``), the sweeps and contact
    points per step and the wall seconds of the timed steps."""
    from benchmarks.shear import Done, shear

    done = [0]
    mark = {}

    def before_step():
        if done[0] == skip:
            mark.update(start=time.perf_counter(), sweeps=sim.counters["sweeps"], timings=dict(sim.timings))

    def after_step(info):
        done[0] += 1
        if done[0] == skip + steps:
            mark["end"] = time.perf_counter()
            raise Done

    shear(sim, after_step, before_step=before_step, domains=domains)
    wall = mark["end"] - mark["start"]
    seconds = {TIMINGS[k]: sim.timings[k] - mark["timings"][k] for k in TIMINGS}
    seconds["outside the step"] = wall - sum(seconds.values())
    return dict(ms={s: 1e3 * seconds[s] / steps for s in STAGES}, steps=done[0] - skip, seconds=wall,
                sweeps=(sim.counters["sweeps"] - mark["sweeps"]) / steps, points=len(sim.points.gap), domains=domains)


def _run(path: str, domains: int, skip: int, steps: int) -> dict:
    sim, _ = load_sample(path)
    return profile(sim, skip, steps, domains)


def table(runs: list) -> str:
    """Markdown: ms per step of each stage, per domain count (the turns' median), its share of
    the step, and the speed-up of each stage over the first domain count."""
    counts = sorted({r["domains"] for r in runs})
    median = {d: {s: float(np.median([r["ms"][s] for r in runs if r["domains"] == d])) for s in STAGES}
              for d in counts}
    total = {d: sum(median[d].values()) for d in counts}
    base = counts[0]
    head = "| stage | " + " | ".join(f"{d} domain{'s' if d > 1 else ''}: ms per step (share)" for d in counts)
    head += "".join(f" | speed-up {d}/{base}" for d in counts[1:]) + " |"
    lines = [head, "|---" * (1 + len(counts) + len(counts) - 1) + "|"]
    for s in STAGES + ["whole step"]:
        cells = []
        for d in counts:
            ms = total[d] if s == "whole step" else median[d][s]
            cells.append(f"{ms:.2f} ({100 * ms / total[d]:.0f}%)")
        for d in counts[1:]:
            a = total[base] if s == "whole step" else median[base][s]
            b = total[d] if s == "whole step" else median[d][s]
            cells.append(f"{a / b:.2f}x" if b > 0 else "-")
        lines.append(f"| {s} | " + " | ".join(cells) + " |")
    lines += ["", "| domains | turns | sweeps per step (mean) | contact points (last step) |", "|---|---|---|---|"]
    for d in counts:
        mine = [r for r in runs if r["domains"] == d]
        lines.append(f"| {d} | {len(mine)} | {np.mean([r['sweeps'] for r in mine]):.1f} | {mine[-1]['points']} |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sample", required=True, help="a pickled compacted sample (compaction.py --save)")
    parser.add_argument("--domains", default="1,2", help="the domain counts compared (default 1,2)")
    parser.add_argument("--skip", type=int, default=300, help="shear steps before the timed ones (default 300)")
    parser.add_argument("--steps", type=int, default=300, help="shear steps timed (default 300)")
    parser.add_argument("--repeats", type=int, default=2, help="turns over the domain counts (default 2)")
    parser.add_argument("--out", help="the results file (default benchmarks/results/step-profile-<N>.md)")
    args = parser.parse_args(argv)
    counts = [int(d) for d in args.domains.split(",")]
    if not os.path.exists(args.sample):
        raise SystemExit(f"step_profile.py: no sample at {args.sample}: make one with compaction.py --save")
    runs = []
    for turn in range(args.repeats):
        for d in (counts if turn % 2 == 0 else counts[::-1]):
            runs.append(_run(args.sample, d, args.skip, args.steps))
            print(f"turn {turn}, {d} domain(s): {sum(runs[-1]['ms'].values()):.2f} ms per step", flush=True)
    n = load_sample(args.sample)[0].n_particles
    out = args.out or os.path.join(HERE, "results", f"step-profile-{n}.md")
    intro = (f"Written by `python -m benchmarks.step_profile --sample {os.path.basename(args.sample)} --domains "
             f"{args.domains} --skip {args.skip} --steps {args.steps} --repeats {args.repeats}` (its docstring gives "
             f"the method): {n} particles, shear steps {args.skip + 1}-{args.skip + args.steps}, the median of the "
             "turns. Read with docs/solver.md, \"Both cores\".")
    write_results(out, f"Where a step's time goes: {n} particles", intro, [table(runs)])


if __name__ == "__main__":
    main()
