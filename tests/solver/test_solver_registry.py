"""The registry of contact solvers (solver.contact_solvers): names, what each method can run,
the stepper's dispatch through it, the problem a step poses and the step's stage timings."""

import copy
import dataclasses
import pickle
import re
import time
import warnings

import numpy as np
import pytest

from grainview.contract.errors import ConvergenceWarning, ParameterError
from solver import Parameters, compaction_sample, contact_solvers, isotropic_compaction
from solver.stepper import STAGES


def test_the_registered_methods_and_what_each_solves():
    assert contact_solvers.stepper_methods() == ("anderson", "nlgs", "pcg")
    assert contact_solvers.matrix_methods() == ("newton", "nlgs", "pcg")
    assert contact_solvers.method("anderson").domains and not contact_solvers.method("anderson").shuffle
    assert contact_solvers.method("nlgs").domains and contact_solvers.method("nlgs").shuffle
    pcg = contact_solvers.method("pcg")
    assert pcg.in_stepper and not (pcg.domains or pcg.shuffle or pcg.stall)
    assert not contact_solvers.method("newton").in_stepper
    # the periodic cell under a normal stress: the methods whose sweeps couple its rate, and no other
    assert contact_solvers.cell_coupling_methods() == ("anderson", "nlgs")
    contact_solvers.check_cell_coupling(Parameters(solver="nlgs"))
    with pytest.raises(ParameterError, match="solver='pcg': a periodic cell under a normal stress is solved by "
                                             r"anderson or nlgs \(its height's rate is swept with the contacts\)"):
        contact_solvers.check_cell_coupling(Parameters(solver="pcg"))


@pytest.mark.parametrize("name", ["fast", "newton", None])
def test_an_unknown_or_matrix_only_solver_is_refused_in_one_line_naming_the_registered_ones(name):
    with pytest.raises(ParameterError) as caught:
        Parameters(solver=name).validate()
    message = str(caught.value)
    assert "\n" not in message
    assert f"solver={name!r}: expected one of ('anderson', 'nlgs', 'pcg')" in message
    if name == "newton":  # registered, for problems given by their matrix
        assert not contact_solvers.method(name).in_stepper
        return
    with pytest.raises(ParameterError, match=r"expected one of anderson, nlgs, pcg \(the time stepper's\); problems "
                                             r"given by their matrix: newton, nlgs, pcg"):
        contact_solvers.method(name)


def test_a_method_registers_once():
    with pytest.raises(ValueError, match="'nlgs' is already registered"):
        contact_solvers.register(contact_solvers.Method("nlgs", "again", "alternative", solve=lambda *a: None))
    with pytest.raises(ValueError, match="needs a stepper entry"):
        contact_solvers.register(contact_solvers.Method("nothing", "no entry point", "alternative"))
    assert "nothing" not in contact_solvers.stepper_methods() + contact_solvers.matrix_methods()


def _stepper(problem, state, limits, *, memory=3):
    pass


def _matrix(W, q, mu, tolerance, max_iterations, initial, *, scale=1.0):
    pass


@pytest.mark.parametrize("entry, words", [
    (dict(status="best", solve=_stepper), "status='best', expected one of default, alternative, experimental"),
    (dict(status="default", solve=_stepper), "the default is one stepper method ('anderson' is)"),
    (dict(status="default", solve_matrix=_matrix), "the default is one stepper method"),
    (dict(status="alternative", solve=_matrix), "solve takes (W, q, mu, tolerance, max_iterations, initial) where "
                                                "StepperSolve takes (problem, state, limits)"),
    (dict(status="alternative", solve_matrix=_stepper), "solve_matrix takes (problem, state, limits) where "
                                                        "MatrixSolve takes (W, q, mu, tolerance, max_iterations, "
                                                        "initial)"),
    (dict(status="alternative", solve=lambda problem, state, limits, memory: None),
     "solve takes (problem, state, limits, memory)"),
])
def test_a_method_is_refused_without_a_status_or_with_an_entry_point_of_another_signature(entry, words):
    with pytest.raises(ValueError, match=re.escape(words)):
        contact_solvers.register(contact_solvers.Method("trial", "a trial", **entry))
    assert "trial" not in contact_solvers.stepper_methods() + contact_solvers.matrix_methods()


def test_every_method_has_a_status_and_the_stepper_one_default():
    statuses = {name: contact_solvers.method(name).status
                for name in (*contact_solvers.stepper_methods(), *contact_solvers.matrix_methods())}
    assert set(statuses.values()) <= set(contact_solvers.STATUSES)
    assert [name for name, status in statuses.items() if status == "default"] == [Parameters.solver] == \
        [contact_solvers.default_method()]
    assert [name for name, _, _ in contact_solvers.choices()] == ["anderson", "nlgs", "pcg"]  # the default first
    assert [status for _, status, _ in contact_solvers.choices()] == ["default", "alternative", "experimental"]
    for name, status, summary in contact_solvers.choices():
        assert f"{name!r} ({status}): {summary}" in contact_solvers.choices_help()


def test_what_a_method_cannot_run_with_is_named():
    with pytest.raises(ParameterError, match="shuffle=True: expected False with solver='anderson'"):
        Parameters(shuffle=True).validate()
    with pytest.raises(ParameterError, match="domains=2: expected 1 with shuffle"):
        Parameters(solver="nlgs", shuffle=True, domains=2).validate()
    with pytest.raises(ParameterError, match="domains=2: expected 1 with solver='pcg' .*; stall_sweeps=200: "
                                             "expected 0 with solver='pcg'"):
        Parameters(solver="pcg", domains=2, stall_sweeps=200).validate()
    Parameters(solver="nlgs", shuffle=True).validate()
    Parameters(solver="anderson", domains=2).validate()


def test_the_options_a_method_reads_from_the_parameters():
    p = Parameters(solver="anderson", anderson_memory=5, anderson_period=2, domains=2)
    x = np.arange(3.0)
    options = contact_solvers.method("anderson").options(p, x=x, decomposition="d", shuffle=True, seed=7)
    assert options == dict(memory=5, period=2, domains=2, x=x, decomposition="d")  # no random order
    options = contact_solvers.method("nlgs").options(Parameters(solver="nlgs"), x=x, shuffle=True, seed=7)
    assert options == dict(domains=1, x=x, decomposition=None, shuffle=True, seed=7)


def test_the_former_acceleration_setting_names_a_solver():
    assert Parameters(acceleration="off").solver == "nlgs"
    assert Parameters(acceleration="anderson").solver == "anderson"
    p = Parameters(solver="nlgs")
    assert p.acceleration == "off"
    p.acceleration = "anderson"
    assert p.solver == "anderson" and p.acceleration == "anderson"
    with pytest.raises(ParameterError, match="acceleration='fast': expected one of off, anderson"):
        Parameters(acceleration="fast")
    assert "acceleration" not in Parameters.__dataclass_fields__
    assert "acceleration" not in dataclasses.asdict(p)  # a file records solver_solver only
    assert dataclasses.replace(p, domains=2).solver == "anderson"
    assert dataclasses.replace(p, acceleration="off").solver == "nlgs"


@pytest.mark.parametrize("before, after", [("nlgs", "anderson"), ("anderson", "nlgs")])
def test_replace_sets_the_solver_it_is_given(before, after):
    p = Parameters(solver=before)
    assert dataclasses.replace(p, solver=after).solver == after
    assert dataclasses.replace(p, domains=2).solver == before


def test_a_parameters_record_pickled_before_the_solver_field_unpickles_with_its_solver():
    p = Parameters(solver="anderson")
    assert pickle.loads(pickle.dumps(p)) == p and copy.deepcopy(p) == p
    old = dict(p.__dict__)
    del old["solver"]
    old["acceleration"] = "off"  # how a Parameters was pickled before
    restored = Parameters.__new__(Parameters)
    restored.__setstate__(old)
    assert restored.solver == "nlgs" and "acceleration" not in restored.__dict__


def _sample(solver="anderson", **settings):
    """30 pentagons 800 steps into their isotropic compaction (about 50 contact points)."""
    sim = compaction_sample(30, "pentagon", seed=3, solver=solver, **settings)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        isotropic_compaction(sim, max_steps=800, progress=False)
    return sim


@pytest.mark.parametrize("solver", ["anderson", "nlgs"])
def test_the_problem_taken_is_the_one_the_step_solves_and_taking_it_changes_nothing(solver):
    """contact_problem() gives the next step's problem: solved by the registry's method it gives
    the step's impulses bit for bit, and a simulation whose problem was taken steps on exactly
    as one whose was not."""
    sim = _sample(solver)
    twin = copy.deepcopy(sim)
    posed = sim.contact_problem()
    assert len(posed.problem.a) > 40 and np.any(posed.state.pn > 0)  # a loaded packing, warm-started
    assert posed.limits == (sim.parameters.tolerance, sim.parameters.max_tolerance, sim.parameters.max_iterations,
                            sim.parameters.stall_sweeps)
    state = contact_solvers.ContactState(*(a.copy() for a in posed.state))
    method = contact_solvers.method(solver)
    method.solve(posed.problem, state, posed.limits,
                 **method.options(sim.parameters, x=sim.position[:sim.n_particles, 0], seed=sim.parameters.seed
                                  + sim.step_index))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        twin.step()
        sim.step()
    np.testing.assert_array_equal(twin.impulse, np.stack([state.pn, state.pt], -1))
    np.testing.assert_array_equal(sim.impulse, twin.impulse)
    np.testing.assert_array_equal(sim.position, twin.position)
    np.testing.assert_array_equal(sim.velocity, twin.velocity)


def test_the_stage_timings_add_up_to_the_steps():
    sim = _sample("anderson")
    assert tuple(sim.timings) == STAGES
    before = dict(sim.timings)
    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        for _ in range(20):
            sim.step()
    elapsed = time.perf_counter() - start
    spent = {k: sim.timings[k] - before[k] for k in STAGES}
    assert all(v >= 0 for v in spent.values()), spent
    assert all(spent[k] > 0 for k in ("narrow_phase", "warm_start", "contact_problem", "solve", "diagnostics",
                                      "update", "other")), spent
    assert 0.95 * elapsed <= sum(spent.values()) <= elapsed


def test_a_run_with_the_projected_conjugate_gradient_reaches_the_residual_it_claims():
    """800 steps of a compaction solved by 'pcg' on the step's matrix: the local-law residual
    each step reports (the PCG's, from W and q) is the one the stepper measures from the
    impulses and velocities (solver.residuals, point by point); every step it calls converged
    is within the tolerance; most steps converge, the others say so (its known stall on
    singular W, solver.contact_solvers)."""
    sim = compaction_sample(30, "pentagon", seed=3, solver="pcg")
    infos = []
    with warnings.catch_warnings(record=True) as caught, sim.watch(after=infos.append):
        warnings.simplefilter("always", ConvergenceWarning)
        isotropic_compaction(sim, max_steps=800, progress=False)
    said = [str(w.message) for w in caught if issubclass(w.category, ConvergenceWarning)]
    assert said and all(m.startswith("the contact solver (pcg) did not converge") for m in said)
    assert any("stopped by its own stall test" in m for m in said)
    claimed = np.array([i.residual for i in infos])
    measured = np.array([i.local_law_residual for i in infos])
    converged = np.array([i.converged for i in infos])
    assert len(infos) == 800 and max(i.n_points for i in infos) > 40
    np.testing.assert_allclose(claimed, measured, rtol=1e-5, atol=1e-12)
    assert np.all(measured[converged] <= sim.parameters.tolerance)
    assert np.all(measured[~converged] > sim.parameters.tolerance)
    assert converged.mean() > 0.8
    assert sim.counters["unconverged_steps"] == (~converged).sum()


def test_each_method_states_what_stops_it_in_its_own_words():
    """The words the stepper's warnings and the reports use (contact_solvers.stop_rule): the
    NLGS family counts sweeps and its stall test only when it is on; the projected CG counts
    iterations and always has its own stall test, with the numbers its code uses."""
    from solver import nlgs, projected_cg

    assert contact_solvers.stop_rule("nlgs", 2000, 0) == "the sweep cap (2000 sweeps)"
    assert contact_solvers.stop_rule("anderson", 2000, 200) == (
        f"the sweep cap (2000 sweeps) or the stall test (quadratic norm down by < "
        f"{100 * nlgs.STALL_IMPROVEMENT:g}% over 200 sweeps)")
    assert contact_solvers.stop_rule("pcg", 100, 200) == (
        f"the iteration cap (100 iterations) or its own stall test (the best local-law residual down by < "
        f"{100 * projected_cg.STALL_IMPROVEMENT:g}% over {projected_cg.STALL_ITERATIONS} iterations)")
    from solver import nonsmooth_newton

    assert contact_solvers.stall_rule("nlgs", 0) == ""
    assert contact_solvers.stop_rule("newton", 200, 20) == (
        f"the Newton step cap (200 Newton steps) or its own stall test (the best local-law residual down by < "
        f"{100 * nonsmooth_newton.STALL_IMPROVEMENT:g}% over {nonsmooth_newton.STALL_STEPS} Newton steps)")
    assert contact_solvers.method("newton").norms == contact_solvers.method("pcg").norms
    assert "local-law residual" in contact_solvers.method("newton").norms
    with pytest.raises(ParameterError, match="solver='apgd': expected one of"):
        contact_solvers.stop_rule("apgd")
