"""benchmarks/fidelity/reshear.py: a study's compacted sample sheared again from its file.

The independent check: resheared at the study's own speed and snapshot interval, the new
file is the study's file again, bit for bit (the sample, its warm start and the test are all
restored from snapshot 0); resheared at another speed, it starts from the same state and
records the new speed and where it came from. A sample compacted alone (``grainview study
--scene isotropic``, what the repository keeps of the paper-size study) is the study's
snapshot 0, and sheared from it gives the study's file again."""

from __future__ import annotations

import netCDF4
import numpy as np
import pytest

from grainview.app.cli import main
from grainview.app.simulation import simulate as _simulate
from grainview.contract.errors import ParameterError
from solver.parameters import BiaxialTest
from solver.preparation import preparation

from .conftest import load_benchmark, stored_values as _values

VARIABLES = ("position", "angle", "velocity", "fn", "ft", "normal_impulse", "wall_position", "wall_force", "step")


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    """A finished study folder holding one small test, pentagons.nc (30 pentagons)."""
    folder = tmp_path_factory.mktemp("study")
    prep = preparation("paper", particles=30, shape="pentagon", seed=0)
    _simulate(prep, folder / "pentagons.nc", test=BiaxialTest(strain=0.004, every=10, velocity=0.01),
              near_contacts=True, overwrite=False, progress=False, parameters={})
    return folder


def test_resheared_at_the_same_speed_is_the_study_file_again(study, tmp_path):
    reshear = load_benchmark("fidelity.reshear")
    assert reshear.reshear(study, tmp_path, "pentagons", velocity=0.01, every=10, domains=None) == "started"
    for name in VARIABLES:
        assert np.array_equal(_values(study / "pentagons.nc", name), _values(tmp_path / "pentagons.nc", name),
                              equal_nan=True), name
    assert reshear.reshear(study, tmp_path, "pentagons", velocity=0.01, every=10, domains=None) == "finished"


def test_resheared_at_another_speed_starts_from_the_same_state(study, tmp_path):
    reshear = load_benchmark("fidelity.reshear")
    reshear.reshear(study, tmp_path, "pentagons", velocity=0.02, every=5, domains=None)
    new, old = tmp_path / "pentagons.nc", study / "pentagons.nc"
    for name in ("position", "normal_impulse", "wall_position"):
        assert np.array_equal(_values(new, name)[0], _values(old, name)[0], equal_nan=True), name
    with netCDF4.Dataset(new) as nc:
        assert nc.getncattr("wall_velocity_m_s") == 0.02
        assert nc.getncattr("resheared_from_velocity_m_s") == 0.01
        assert nc.getncattr("resheared_from") == str(old)
        steps = nc["step"][:]
    # twice the speed, the same strain: half the steps of the study's test
    assert steps[-1] - steps[0] == (_values(old, "step")[-1] - _values(old, "step")[0] + 1) // 2
    # the same folder asked for another speed or snapshot interval: refused, not taken as finished
    with pytest.raises(ParameterError, match=r"wall_velocity_m_s = 0\.02, this run's is 0\.01"):
        reshear.reshear(study, tmp_path, "pentagons", velocity=0.01, every=5, domains=None)
    with pytest.raises(ParameterError, match=r"snapshot_every = 5, this run's is 10"):
        reshear.reshear(study, tmp_path, "pentagons", velocity=0.02, every=10, domains=None)


def test_an_unfinished_source_is_refused(tmp_path):
    reshear = load_benchmark("fidelity.reshear")
    with pytest.raises(ParameterError, match="is neither a finished test nor a compacted sample"):
        reshear.reshear(tmp_path, tmp_path / "out", "pentagons", velocity=0.01, every=10, domains=None)


def test_a_compacted_sample_sheared_is_the_study_file_again(study, tmp_path, capsys):
    samples = tmp_path / "samples"
    command = ["study", "--scene", "isotropic", "--particles", "30,24", "--jobs", "1", "--progress", "off",
               "--out", str(samples)]
    assert main(command) == 0
    with netCDF4.Dataset(samples / "pentagons.nc") as nc:
        assert nc.getncattr("scene") == "isotropic" and nc.dimensions["time"].size == 1
        assert nc.getncattr("compaction_settled") == 1
    for name in ("position", "angle", "velocity", "normal_impulse", "wall_position", "step"):
        assert np.array_equal(_values(samples / "pentagons.nc", name)[0], _values(study / "pentagons.nc", name)[0],
                              equal_nan=True), name
    assert main(command) == 0  # the same command again: nothing to do
    assert "pentagons.nc is complete (skipped)" in capsys.readouterr().out
    assert main([*command, "--seed", "2"]) == 2  # a sample of other settings: refused in one line, kept
    assert "holds another run (preparation_seed = 0, this run's is 2)" in capsys.readouterr().err
    biaxial = [c for c in command if c not in ("--scene", "isotropic")]  # a test asked for in the samples' folder
    assert main(biaxial) == 2
    assert "holds another run (scene = isotropic, this run's is biaxial); give another --out" in capsys.readouterr().err
    reshear = load_benchmark("fidelity.reshear")
    out = tmp_path / "resheared"
    assert reshear.reshear(samples, out, "pentagons", velocity=0.01, every=10, domains=None, strain=0.004) == "started"
    for name in VARIABLES:
        assert np.array_equal(_values(study / "pentagons.nc", name), _values(out / "pentagons.nc", name),
                              equal_nan=True), name
    with netCDF4.Dataset(out / "pentagons.nc") as nc:
        assert nc.getncattr("resheared_from") == str(samples / "pentagons.nc")
        assert "resheared_from_velocity_m_s" not in nc.ncattrs()


def test_unconverged_steps_are_said_in_one_line_and_other_warnings_shown(study, capsys):
    import warnings

    from grainview.contract.errors import ConvergenceWarning

    reshear = load_benchmark("fidelity.reshear")
    with pytest.warns(UserWarning, match="something else"):
        with reshear.one_line_on_unconverged(study / "pentagons.nc"):
            for _ in range(3):
                warnings.warn("did not converge", ConvergenceWarning)
            warnings.warn("something else", UserWarning)
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("pentagons: warning: the contact solver")
    assert "did not converge in 3 of the steps taken now" in err[0]


def test_ctrl_c_ends_the_command_without_a_traceback(study, tmp_path, monkeypatch, capsys):
    """The solver prints where a stopped test is and how to resume it; the command then exits 130."""
    reshear = load_benchmark("fidelity.reshear")

    def stopped(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(reshear, "reshear", stopped)
    assert reshear.main([str(study), str(tmp_path / "out"), "--velocity", "0.01", "--every", "10",
                         "--samples", "pentagons"]) == 130
    assert capsys.readouterr().out == "pentagons: ...\n"
