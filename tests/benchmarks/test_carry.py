"""benchmarks/fidelity/carry.py: a test carried from sitting to sitting in the repository.

The independent check is the uninterrupted run: a test stopped part-way, carried (its first and
last snapshots and its snapshots' measures), restored into an empty folder and resumed by the
reshear gives the uninterrupted test's snapshots bit for bit, and the measures carried over both
parts are the measures of the uninterrupted file, value for value, so the page written from the
carry folder is the page written from the file."""

from __future__ import annotations

import numpy as np
import pytest

from grainview.app.simulation import simulate as _simulate
from grainview.contract.errors import ParameterError
from grainview.contract.writer import copy_snapshots
from solver.parameters import BiaxialTest
from solver.preparation import preparation

from .conftest import load_benchmark, stored_values as _values

VARIABLES = ("position", "angle", "velocity", "fn", "ft", "normal_impulse", "tangential_impulse", "wall_position",
             "wall_velocity", "wall_force", "step", "time")
SETTINGS = dict(velocity=0.01, every=10, domains=None)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """A compacted 30-pentagon study and its uninterrupted reshear, pentagons.nc in each folder."""
    study = tmp_path_factory.mktemp("study")
    prep = preparation("paper", particles=30, shape="pentagon", seed=0)
    _simulate(prep, study / "pentagons.nc", test=BiaxialTest(strain=0.006, every=10, velocity=0.01),
              near_contacts=True, overwrite=False, progress=False, parameters={})
    whole = tmp_path_factory.mktemp("whole")
    load_benchmark("fidelity.reshear").reshear(study, whole, "pentagons", **SETTINGS)
    return study, whole / "pentagons.nc"


def test_a_carried_test_resumes_bit_for_bit_and_keeps_every_snapshots_measures(runs, tmp_path):
    carry = load_benchmark("fidelity.carry")
    measure = load_benchmark("fidelity.measure")
    reshear = load_benchmark("fidelity.reshear")
    study, whole = runs
    n = int(_values(whole, "step").size)
    stop = n // 2
    assert stop >= 3
    stopped = tmp_path / "sitting1"
    stopped.mkdir()
    copy_snapshots(whole, stopped / "pentagons.nc", range(stop))  # what a run stopped after snapshot stop-1 leaves
    kept = tmp_path / "carry"
    first = carry.save(stopped / "pentagons.nc", kept)
    assert first["new"] == first["snapshots measured"] == stop
    assert first["step"] == int(_values(whole, "step")[stop - 1])

    again = tmp_path / "sitting2"  # a fresh machine: nothing but the carry folder
    assert carry.restore(kept, again, "pentagons") == str(again / "pentagons.nc")
    with pytest.raises(ParameterError, match="exists: resume it"):
        carry.restore(kept, again, "pentagons")
    assert reshear.reshear(study, again, "pentagons", **SETTINGS) == "resumed"
    for name in VARIABLES:
        resumed, straight = _values(again / "pentagons.nc", name), _values(whole, name)
        assert np.array_equal(resumed[1:], straight[stop - 1:], equal_nan=True), name
        assert np.array_equal(resumed[0], straight[0], equal_nan=True), name

    second = carry.save(again / "pentagons.nc", kept)
    assert second["new"] == n - stop and second["snapshots measured"] == n
    for name in VARIABLES:  # the carried state: the test's first and last snapshots
        assert np.array_equal(_values(kept / "pentagons.nc", name), _values(whole, name)[[0, -1]], equal_nan=True), name
    for how, near in carry._near_gaps().items():
        carried, direct = carry.load_measures(kept, "pentagons", how), measure.snapshot_measures(whole, near)
        assert sorted(carried.data_vars) == sorted(direct.data_vars)
        for name in direct.data_vars:
            assert np.array_equal(carried[name].values, direct[name].values, equal_nan=True), (how, name)
        assert carried.attrs["eps_q_max"] == direct.attrs["eps_q_max"]
        assert measure.window_means(carried, (0.0, np.inf)) == measure.window_means(whole, (0.0, np.inf), near)
    wall_motion = load_benchmark("wall_motion")
    from_carry = wall_motion.wall_motion(wall_motion.carried_or_file(kept / "pentagons.measures.nc"), 0.0)
    from_file = wall_motion.wall_motion(whole, 0.0)
    assert from_carry.keys() == from_file.keys()
    for key, value in from_file.items():
        assert np.array_equal(from_carry[key], value, equal_nan=True), key


def test_status_says_where_a_carried_test_stands(runs, tmp_path, capsys):
    carry = load_benchmark("fidelity.carry")
    _, whole = runs
    steps = _values(whole, "step")
    carry.save(whole, tmp_path / "carry")
    assert carry.main(["status", str(tmp_path / "carry")]) == 0
    done = int(steps[-1] - steps[0])
    assert capsys.readouterr().out.startswith(f"pentagons: step {done:,} of {done:,} (100.0%), eps_q ")


def test_the_repository_carry_folders_readmes_say_where_their_tests_stand():
    """Each carry folder kept in the repository quotes `carry status` in its README, as it is."""
    from pathlib import Path

    carry = load_benchmark("fidelity.carry")
    root = Path(__file__).resolve().parents[2] / "benchmarks" / "fidelity" / "carry"
    folders = [f for f in root.iterdir() if f.is_dir()] if root.is_dir() else []
    for folder in folders:
        readme = (folder / "README.md").read_text()
        for line in carry.status(folder):
            assert f"    {line}\n" in readme, f"{folder}/README.md does not quote: {line}"


def test_carrying_another_test_into_the_folder_is_refused(runs, tmp_path):
    carry = load_benchmark("fidelity.carry")
    reshear = load_benchmark("fidelity.reshear")
    study, whole = runs
    carry.save(whole, tmp_path / "carry")
    other = tmp_path / "other"
    reshear.reshear(study, other, "pentagons", velocity=0.02, every=10, domains=None)
    with pytest.raises(ParameterError, match="wall_velocity_m_s = 0.02, this run's is 0.01"):
        carry.save(other / "pentagons.nc", tmp_path / "carry")
    with pytest.raises(ParameterError, match="no such carried run"):
        carry.restore(tmp_path / "carry", tmp_path / "runs", "disks")


def test_the_page_from_a_carry_folder_is_the_page_from_the_file(runs, tmp_path):
    """benchmarks/fidelity/paper_size.py on the run's folder and on its carry folder."""
    carry = load_benchmark("fidelity.carry")
    paper_size = load_benchmark("fidelity.paper_size")
    _, whole = runs
    carry.save(whole, tmp_path / "carry")
    pages = []
    for folder in (whole.parent, tmp_path / "carry"):
        out = tmp_path / f"page_{len(pages)}" / "paper-size.md"
        paper_size.main([str(folder), "--output", str(out)])
        pages.append(out.read_text().splitlines())
    assert pages[0][3:] == pages[1][3:]  # all but the title and the line with the date and time
    assert "pentagons 30" in "\n".join(pages[0]) and "Not there (yet): paper size disks" in pages[0][2]


def test_the_swing_row_of_a_carried_test_is_the_files(runs, tmp_path, capsys):
    """benchmarks/fidelity/swings.py on the file and on its carried measures: the same row, whose
    p range and share of sigma_xx below sigma0/2 are those of the accessors on the file."""
    import grainview

    carry = load_benchmark("fidelity.carry")
    swings = load_benchmark("fidelity.swings")
    _, whole = runs
    carry.save(whole, tmp_path / "carry")
    assert swings.main([str(whole), str(tmp_path / "carry" / "pentagons.measures.nc"), "--window", "0"]) == 0
    table = capsys.readouterr().out.splitlines()
    from_file, from_carry = ([c.strip() for c in line.split("|")[2:-1]] for line in table[2:4])
    assert from_file == from_carry and len(from_file) == len(swings.HEADER)
    with grainview.open_dataset(whole, chunks=None) as ds:
        p = ds.grain.stress_invariants()["p"].values / 1e3
        sxx = ds.grain.stress_tensor().values[:, 0, 0] / float(ds.attrs["sigma0_Pa"])
        snapshots = ds.sizes["time"]
    cells = dict(zip(swings.HEADER, from_file))
    assert cells["v (cm/s)"] == "1" and cells["snapshots"] == str(snapshots)
    assert cells["p (kPa), min-max"] == f"{p.min():.1f}-{p.max():.1f}"
    assert cells["sigma_xx < sigma0/2"] == f"{100 * np.mean(sxx < 0.5):.0f}%"
