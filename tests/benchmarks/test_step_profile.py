"""benchmarks/step_profile.py: every timed piece of a step is counted once per step, the stages
add up to the wall time, and the profiled shear is the shear itself (the same sweeps, step by
step, as an unprofiled one from the same sample)."""

import copy

import numpy as np
import pytest

from .conftest import load_benchmark as load, shear_sweeps


@pytest.mark.parametrize("domains", [1, 2])
def test_every_stage_is_the_steppers_own_and_the_stages_add_up(pentagon_sample, domains):
    """The stages come from the simulation's own timings (no method wrapped): the step's
    stages are timed, the rows add up to the wall time, and nothing is left on the simulation."""
    from solver import stepper

    step_profile = load("step_profile")
    sim, _ = step_profile.load_sample(pentagon_sample)
    assert set(step_profile.TIMINGS) == set(stepper.STAGES)
    out = step_profile.profile(sim, 5, 12, domains)
    assert out["steps"] == 12 and sim.parameters.domains == domains
    ms = out["ms"]
    assert set(ms) == set(step_profile.STAGES)
    assert min(ms.values()) >= 0.0
    assert all(ms[s] > 0 for s in ("narrow phase", "warm start", "contact problem", "solve", "diagnostics",
                                   "update, other", "step, other", "outside the step"))
    assert sum(ms.values()) * 12 / 1e3 == pytest.approx(out["seconds"], rel=1e-9)
    assert "step" not in vars(sim) and not {"_solve", "_contact_problem"} & set(vars(sim))


def test_the_profiled_shear_is_the_shear(pentagon_sample):
    """The same 12 steps after 5, sheared once profiled and once with only a counter: the
    same sweeps per step (profiling times the pieces, it does not change them)."""
    step_profile = load("step_profile")
    sim, _ = step_profile.load_sample(pentagon_sample)
    plain = copy.deepcopy(sim)
    out = step_profile.profile(sim, 5, 12)
    sweeps = shear_sweeps(plain, 17)
    assert out["sweeps"] == pytest.approx(np.mean(sweeps[5:]), rel=1e-12)
    np.testing.assert_array_equal(sim.position, plain.position)


def test_the_table_takes_the_median_of_the_turns(pentagon_sample):
    step_profile = load("step_profile")
    stages = step_profile.STAGES

    def run(domains, solve):
        ms = dict.fromkeys(stages, 1.0)
        ms["solve"] = solve
        return dict(domains=domains, ms=ms, sweeps=50.0, points=100)

    # one domain: solve 10, 14, 12 ms (median 12); two: 6, 8 (median 7); other stages 1 ms each
    table = step_profile.table([run(1, 10.0), run(2, 6.0), run(1, 14.0), run(2, 8.0), run(1, 12.0)])
    solve = next(line for line in table.splitlines() if line.startswith("| solve |"))
    cells = [c.strip() for c in solve.strip("|").split("|")]
    n = len(stages) - 1  # the other stages
    assert cells[1] == f"12.00 ({100 * 12 / (12 + n):.0f}%)" and cells[2] == f"7.00 ({100 * 7 / (7 + n):.0f}%)"
    assert cells[3] == f"{12 / 7:.2f}x"
    whole = next(line for line in table.splitlines() if line.startswith("| whole step |"))
    assert whole.strip("|").split("|")[3].strip() == f"{(12 + n) / (7 + n):.2f}x"
