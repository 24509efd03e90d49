"""The run, study and ensemble commands check every setting before any work: one line each,
before the compaction starts; negative numbers parse and are refused for their value; shapes
are names or numbers of vertices."""

import os
import time

import numpy as np
import pytest

import grainview
from grainview.app.cli import main

RUN = ["run", "--particles", "10", "--progress", "off"]


def _one_line_at_once(argv, capsys):
    start = time.perf_counter()
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert time.perf_counter() - start < 5  # refused before any compaction
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("grainview: error: ") and "Traceback" not in err, err
    return lines[0]


@pytest.mark.parametrize("argv, fragment", [
    (["--seed", str(2**64)], f"seed={2**64}: expected an integer in 0 .. 2147483647"),
    (["--seed", str(2**31)], "seed=2147483648: expected an integer in 0 .. 2147483647"),
    (["--velocity", "1e-300"], "velocity=1e-300: the test would take about 6.81e+301 steps"),
    (["--velocity", "inf"], "--velocity inf: expected a finite wall speed > 0 in m/s"),
    (["--velocity", "nan"], "--velocity nan: expected a finite wall speed > 0 in m/s"),
    (["--velocity", "20"], "velocity=20: the test would reach eps_1 = 0.2 in about 3.4 steps"),
    (["--time-step", "-1e-4"], "time_step=-0.0001: expected a positive number of seconds"),
    (["--friction", "-0.5"], "friction=-0.5: expected in [0, 10]"),
    (["--shape", "hexagonal"], "--shape hexagonal: expected 'disk', 'pentagon', a number of vertices from 3 to 64, 'irregular' or a .json file of vertex lists"),
    (["--shape", "2"], "--shape 2: a polygon needs at least 3 vertices"),
    (["--shape", "65"], "--shape 65: expected at most 64 vertices"),
    (["--shape", "6.5"], "--shape 6.5: expected 'disk', 'pentagon', a number of vertices from 3 to 64, 'irregular' or a .json file of vertex lists"),
])
def test_run_settings_are_refused_before_any_work(tmp_path, capsys, argv, fragment):
    out = tmp_path / "run.nc"
    line = _one_line_at_once(RUN + argv + ["--out", str(out)], capsys)
    assert fragment in line
    assert os.listdir(tmp_path) == []


def test_the_velocity_rule_is_the_number_of_steps_of_the_test():
    """The test's length in steps from the deposit's height: h (e^eps_1 - 1) / (v dt); the
    bounds of the refusals are those of the message."""
    from solver.packing import box_width_for
    from solver.preparation import MIN_TEST_STEPS, preparation

    prep = preparation("paper", particles=400)
    height = 2.0 * box_width_for(400)
    steps = height * (np.exp(0.2) - 1) / (0.01 * 5e-4)
    assert prep.test_steps(5e-4, 0.01, 0.2) == pytest.approx(steps, rel=1e-12)
    fastest = height * (np.exp(0.2) - 1) / (MIN_TEST_STEPS * 5e-4)
    prep.check_test_speed(5e-4, 0.999 * fastest, 0.2)
    with pytest.raises(grainview.contract.errors.ParameterError, match=f"at most {fastest:.3g} m/s"):
        prep.check_test_speed(5e-4, 1.001 * fastest, 0.2)


@pytest.mark.parametrize("name_bytes, fragment", [
    (255, "a file name of 255 bytes: expected at most 238"),
    (242, "a file name of 242 bytes: expected at most 238"),
])
def test_an_output_name_too_long_for_the_writers_temporary_files_is_refused(tmp_path, capsys, name_bytes, fragment):
    out = tmp_path / ("r" * (name_bytes - 3) + ".nc")
    line = _one_line_at_once(RUN + ["--out", str(out)], capsys)
    assert fragment in line and "temporary" in line
    assert os.listdir(tmp_path) == []


def test_the_longest_accepted_name_is_written_and_compressed(tmp_path):
    """The limit is the writer's: a file of the longest accepted name is created, appended and
    compressed (its temporary names fit)."""
    from grainview.app.simulation import longest_output_name
    from grainview.contract.writer import compress_file

    from . import builders
    from .test_schema_io import _write  # a file written by SnapshotWriter, as the solver writes it

    limit = longest_output_name(tmp_path)
    assert limit == os.pathconf(tmp_path, "PC_NAME_MAX") - 17
    path = tmp_path / ("w" * (limit - 3) + ".nc")
    _write(builders.square_lattice(), path)
    compress_file(path)
    assert grainview.open_dataset(path).sizes["time"] >= 1


def test_a_dangling_symlink_output_is_refused(tmp_path, capsys):
    link = tmp_path / "run.nc"
    link.symlink_to(tmp_path / "gone" / "target.nc")
    line = _one_line_at_once(RUN + ["--out", str(link)], capsys)
    assert f"--out {link} is a symbolic link to {tmp_path / 'gone' / 'target.nc'}, which does not exist" in line
    assert os.listdir(tmp_path) == ["run.nc"] and link.is_symlink()


@pytest.mark.parametrize("argv, fragment", [
    (["ensemble", "--shapes", "pentagon,2"], "--shapes pentagon,2: a polygon needs at least 3 vertices"),
    (["ensemble", "--velocity", "inf"], "expected a finite wall speed > 0 in m/s"),
    (["ensemble", "--velocity", "1e-300"], "the test would take about"),
    (["ensemble", "--first-seed", str(2**40)], "expected an integer in 0 .. 2147483647"),
    (["ensemble", "--time-step", "-1e-4"], "time_step=-0.0001"),
    (["study", "--velocity", "inf"], "--velocity inf: expected a finite wall speed > 0 in m/s"),
    (["study", "--seed", str(2**64)], "expected an integer in 0 .. 2147483647"),
])
def test_study_and_ensemble_settings_are_refused_before_any_work(tmp_path, capsys, argv, fragment):
    line = _one_line_at_once(argv + ["--out", str(tmp_path / "o")], capsys)
    assert fragment in line
    assert os.listdir(tmp_path) == []


def test_shape_given_as_a_number_of_vertices_runs(tmp_path, capsys):
    path = tmp_path / "hexagons.nc"
    assert main(RUN + ["--shape", "6", "--strain", "0.005", "--out", str(path)]) == 0
    with grainview.open_dataset(path, chunks=None) as ds:
        assert (ds.n_vertices.values == 6).all() and ds.attrs["preparation_shape"] == 6


def test_ensemble_shapes_are_names_and_numbers(tmp_path, monkeypatch):
    import grainview.app.ensemble

    seen = []

    def run_ensemble(specs, out, **kwargs):
        seen.extend(specs)
        return []
    monkeypatch.setattr(grainview.app.ensemble, "run_ensemble", run_ensemble)
    assert main(["ensemble", "--shapes", "disk, 6,pentagons", "--seeds", "1", "--no-report",
                 "--out", str(tmp_path / "e")]) == 0
    assert [s.shape for s in seen] == ["disk", 6, "pentagons"]
    assert [s.name for s in seen] == ["disk_n400_s0", "6_n400_s0", "pentagons_n400_s0"]
