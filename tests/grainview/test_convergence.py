"""What the report and the command line say of a run's unconverged NLGS steps
(grainview.app.convergence): the counts and largest residuals read from the file, and the text."""

from __future__ import annotations

import re

import netCDF4
import numpy as np
import pytest

import grainview
from grainview.app.simulation import simulate as _simulate
from grainview.app.convergence import compaction_in_file, compaction_text, unconverged_in_file, unconverged_text
from grainview.app.report import convergence_notes, convergence_text
from solver.parameters import BiaxialTest
from solver.preparation import preparation

ATTRS = {"solver_tolerance": 1.7e-4, "solver_max_tolerance": 1e-2, "solver_max_iterations": 2000,
         "solver_stall_sweeps": 0, "scene": "biaxial"}


def _variables(complete=(1, 1, 1, 1, 0)):
    """Five snapshots 200 steps apart, the last one incomplete (its values must not count)."""
    return {
        "time": np.array([0.0, 0.1, 0.2, 0.3, 0.4]),
        "complete": np.array(complete, "i1"),
        "step": np.array([1000, 1200, 1400, 1600, 1800]),
        "local_law_residual": np.array([1e-4, 2e-4, 3e-4, 5e-4, 9.0]),
        "nlgs_unconverged_steps": np.array([0, 2, 0, 1, 50]),
        "nlgs_unconverged_residual": np.array([0.0, 3.4e-4, 0.0, 5.1e-4, 9.0]),
        "nlgs_unconverged_local_law_residual": np.array([0.0, 2e-3, 0.0, 1e-3, 9.0]),
    }


def test_counts_and_largest_residuals_over_the_complete_snapshots():
    counts = unconverged_in_file(_variables(), ATTRS)
    assert counts["steps"] == 3 and counts["of"] == 600 and counts["snapshots"] == 2
    assert counts["residual"] == 5.1e-4 and counts["local_law_residual"] == 2e-3
    assert counts["typical_local_law_residual"] == pytest.approx(2.5e-4)  # median of 1, 2, 3, 5 e-4
    assert counts["tolerance"] == 1.7e-4 and counts["max_iterations"] == 2000


def test_the_text_states_the_counts_the_rule_and_the_residuals_against_the_tolerance():
    text = unconverged_text(unconverged_in_file(_variables(), ATTRS))
    assert "3 of the test's 600 steps (0.5%)" in text
    assert "in 2 of the intervals between snapshots" in text
    assert "the sweep cap (2000 sweeps) before both stopping norms" in text and "stall" not in text
    assert "quadratic norm 0.00017, max norm 0.01" in text
    assert "The largest quadratic norm among them was 0.00051 (3x its tolerance)" in text
    assert "the largest local-law residual |F|/|r| 0.002 (zero for" in text
    assert "the snapshots' own steps: median 0.00025)" in text
    stalled = unconverged_text(unconverged_in_file(_variables(), {**ATTRS, "solver_stall_sweeps": 200}))
    assert "or the stall test (quadratic norm down by < 5% over 200 sweeps)" in stalled


def test_the_text_speaks_of_the_solver_the_file_names():
    """A file made with the projected CG says iterations, its own stall test and its one norm;
    a file from before ``solver_solver`` is read as its ``solver_acceleration`` says; a name this
    package does not know gets neutral words."""
    pcg = unconverged_text(unconverged_in_file(_variables(), {**ATTRS, "solver_solver": "pcg"}))
    assert pcg.startswith("Projected-CG convergence: 3 of the test's 600 steps")
    assert ("stopped at the iteration cap (2000 iterations) or its own stall test (the best local-law residual "
            "down by < 5% over 500 iterations) before its local-law residual |F|/|r| met the tolerance") in pcg
    assert "sweep" not in pcg
    anderson = unconverged_text(unconverged_in_file(_variables(), {**ATTRS, "solver_solver": "anderson"}))
    older = unconverged_text(unconverged_in_file(_variables(), {**ATTRS, "solver_acceleration": "anderson"}))
    assert anderson == older == unconverged_text(unconverged_in_file(_variables(), ATTRS))
    assert anderson.startswith("NLGS convergence: ") and "the sweep cap (2000 sweeps) before both" in anderson
    other = unconverged_text(unconverged_in_file(_variables(), {**ATTRS, "solver_solver": "interior-point"}))
    assert other.startswith("Contact-solver convergence: ") and "the iteration cap or a stall test" in other


def test_no_unconverged_step_and_no_record_are_said_so():
    variables = _variables()
    variables["nlgs_unconverged_steps"] = np.zeros(5, int)
    text = unconverged_text(unconverged_in_file(variables, ATTRS))
    assert text.startswith("NLGS convergence: every step of the test's 600 stopped once both stopping norms "
                           "(the impulses' change over a sweep) met their tolerances")
    pcg = unconverged_text(unconverged_in_file(variables, {**ATTRS, "solver_solver": "pcg"}))
    assert pcg.startswith("Projected-CG convergence: every step of the test's 600 stopped once its local-law "
                          "residual |F|/|r| met the tolerance") and "both stopping" not in pcg
    del variables["nlgs_unconverged_steps"]
    assert unconverged_in_file(variables, ATTRS) is None
    assert "not recorded in this file" in unconverged_text(None)


def test_the_run_command_warns_with_the_counts_its_file_and_report_hold(tmp_path, capsys):
    """30 pentagons capped at 10 sweeps a step: the printed total (the stepper's warnings) is
    the compaction's count (a file attribute) plus the test's (the snapshots' sum); each phase
    is given with its own largest residuals, and the report states the same two counts and
    residuals, each named by its phase."""
    path = tmp_path / "run.nc"
    prep = preparation("paper", particles=30, shape="pentagon", seed=0)
    _simulate(prep, path, test=BiaxialTest(strain=0.004, every=10, velocity=0.01), near_contacts=False,
              overwrite=False, progress=False, parameters={"max_iterations": 10})
    err = " ".join(capsys.readouterr().err.split())
    found = re.search(r"did not converge in (\d+) step\(s\): (\d+) of the compaction's (\d+) \((.*?)\); "
                      r"(\d+) of the test's (\d+) \((.*?)\)\. They stopped at", err)
    total, compaction, compaction_steps, test, test_steps = map(int, found.group(1, 2, 3, 5, 6))
    compaction_words, test_words = found.group(4, 7)
    with netCDF4.Dataset(path) as nc:
        stored = int(nc["nlgs_unconverged_steps"][:].sum())
        assert compaction == nc.getncattr("compaction_unconverged_steps") > 0
        assert compaction_steps == nc.getncattr("compaction_steps")
        assert test_steps == nc.getncattr("biaxial_steps") == int(nc["step"][-1] - nc["step"][0])
        test_law = float(nc["nlgs_unconverged_local_law_residual"][:].max())
        compaction_law = float(nc.getncattr("compaction_unconverged_local_law_residual"))
    assert test == stored > 0 and total == compaction + test
    assert "the contact solver (anderson) did not converge in" in err
    assert "They stopped at the sweep cap (10 sweeps) before both stopping norms" in err
    assert f"the largest local-law residual |F|/|r| {compaction_law:.2g} (zero for" in compaction_words
    assert f"the largest local-law residual |F|/|r| {test_law:.2g} (zero for" in test_words
    assert "its report states both, apart" in err
    with grainview.open_dataset(path, chunks=None) as ds:
        text = convergence_text(ds)
        assert text.startswith(unconverged_text(unconverged_in_file(ds, ds.attrs)) + " ")
        assert f"NLGS convergence: {test} of the test's {test_steps} steps" in text
        assert f"local-law residual |F|/|r| {test_law:.2g} (zero for" in text
        assert (f"The isotropic compaction before the test (its steps are not counted above): {compaction} of its "
                f"{compaction_steps} steps stopped unconverged, the largest local-law residual |F|/|r| among them "
                f"{compaction_law:.2g}") in text
        assert convergence_notes({"pentagons": ds}) == [f"**pentagons.** {text}"]


def test_the_compaction_sentence_reads_the_attributes_and_says_nothing_without_them():
    attrs = {"compaction_steps": 1641, "compaction_unconverged_steps": 2,
             "compaction_unconverged_local_law_residual": 0.048}
    assert compaction_in_file(attrs) == {"steps": 2, "of": 1641, "local_law_residual": 0.048}
    assert compaction_text(compaction_in_file(attrs)) == (
        "The isotropic compaction before the test (its steps are not counted above): 2 of its 1641 steps stopped "
        "unconverged, the largest local-law residual |F|/|r| among them 0.048 (the file's compaction_unconverged_* "
        "attributes).")
    none = compaction_text(compaction_in_file({**attrs, "compaction_unconverged_steps": 0}))
    assert none == "The isotropic compaction before the test (its steps are not counted above): 0 of its 1641 steps " \
                   "stopped unconverged."
    assert compaction_in_file(ATTRS) is None and compaction_text(None) == ""
