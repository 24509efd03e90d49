"""``grainview study`` resumable across sittings, and its paper-size preset: the same command,
run again after stops and kills in the compaction and in the test, ends on the files an
uninterrupted study writes, bit for bit; files of other settings are refused."""

from __future__ import annotations

import os
import signal

import netCDF4
import numpy as np
import pytest

from grainview.app.cli import build_parser, main
from grainview.app.study import study_particles as _study_particles
from grainview.app.study import study_tests as _study_tests
from solver import stepper
from solver.compaction_checkpoint import CompactionCheckpoint

# the paper-size preset's code path at a small size: two sizes, one per sample, the top walls at
# the speeds --paper-size gives 14,400 and 10,000 particles (so the same per-sample tests)
STUDY = ["study", "--particles", "30,24", "--strain", "0.004", "--every", "10", "--jobs", "1", "--progress", "off",
         "--no-report"]


def _contents(path):
    """Every variable's values and every global attribute of a file."""
    with netCDF4.Dataset(path) as nc:
        nc.set_auto_mask(False)
        return ({name: np.asarray(var[...]) for name, var in nc.variables.items()},
                {name: nc.getncattr(name) for name in nc.ncattrs()})


def _assert_same_file(a, b):
    (va, aa), (vb, ab) = _contents(a), _contents(b)
    assert sorted(va) == sorted(vb)
    for name in va:
        floating = va[name].dtype.kind == "f"
        assert va[name].dtype == vb[name].dtype and np.array_equal(va[name], vb[name], equal_nan=floating), name
    assert sorted(aa) == sorted(ab)
    for name in aa:
        assert np.array_equal(np.asarray(aa[name]), np.asarray(ab[name])), name


def _act_at(monkeypatch, particles, step_index, action):
    """Run ``action()`` right after the step that brings the sample of ``particles`` to ``step_index``."""
    original = stepper.Simulation.step

    def step(self):
        info = original(self)
        if self.n_particles == particles and self.step_index == step_index:
            action()
        return info

    monkeypatch.setattr(stepper.Simulation, "step", step)


def _sigterm():
    os.kill(os.getpid(), signal.SIGTERM)


def _hard_kill():  # nothing of the run's own stopping runs: what SIGKILL leaves
    raise KeyboardInterrupt


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory):
    out = tmp_path_factory.mktemp("uninterrupted")
    assert main([*STUDY, "--out", str(out), "--velocity", "0.06"]) == 0
    return out


def test_stopped_and_killed_study_resumes_to_the_uninterrupted_files(tmp_path, monkeypatch, uninterrupted, capsys):
    out = tmp_path / "study"
    command = [*STUDY, "--out", str(out), "--velocity", "0.06"]
    monkeypatch.setattr(CompactionCheckpoint, "due", lambda self, steps: steps % 100 == 0)
    pentagons_steps = int(_contents(uninterrupted / "pentagons.nc")[1]["compaction_steps"])
    disks_steps = int(_contents(uninterrupted / "disks.nc")[1]["compaction_steps"])
    assert pentagons_steps > 400 and disks_steps > 450

    with monkeypatch.context() as m:  # 1. SIGTERM in the pentagons' compaction: a checkpoint of step 333
        _act_at(m, 30, 333, _sigterm)
        assert main(command) == 143
    checkpoint = out / "pentagons.compaction.nc"
    assert not (out / "pentagons.nc").exists()
    assert int(_contents(checkpoint)[1]["checkpoint_steps"]) == 333

    with monkeypatch.context() as m:  # 2. SIGTERM in the pentagons' test: a partial file
        _act_at(m, 30, pentagons_steps + 20, _sigterm)
        assert main(command) == 143
    assert "resuming the compaction of" in capsys.readouterr().out
    attrs = _contents(out / "pentagons.nc")[1]
    assert int(attrs["compaction_steps"]) == pentagons_steps and int(attrs["biaxial_steps"]) > 20

    with monkeypatch.context() as m:  # 3. killed in the disks' compaction: the checkpoint of step 400 is left
        _act_at(m, 24, 450, _hard_kill)
        assert main(command) == 130
    assert not checkpoint.exists()  # the pentagons' test is complete: their checkpoint is gone
    assert int(_contents(out / "disks.compaction.nc")[1]["checkpoint_steps"]) == 400

    assert main(command) == 0  # 4. nothing interrupts it
    printed = capsys.readouterr().out
    assert "pentagons.nc is complete (skipped)" in printed and "resuming the compaction of" in printed
    assert sorted(os.listdir(out)) == ["disks.nc", "pentagons.nc"]
    for name in ("pentagons.nc", "disks.nc"):
        _assert_same_file(out / name, uninterrupted / name)

    assert main([*command[:-2], "--velocity", "0.05"]) == 2  # another speed: refused, the files kept
    err = capsys.readouterr().err
    assert "holds another run (wall_velocity_m_s = 0.06, this run's is 0.05)" in err and "--overwrite" in err
    _assert_same_file(out / "pentagons.nc", uninterrupted / "pentagons.nc")


def test_a_checkpoint_of_other_settings_is_refused(tmp_path, monkeypatch, capsys):
    out = tmp_path / "study"
    with monkeypatch.context() as m:
        _act_at(m, 30, 50, _sigterm)
        assert main([*STUDY, "--out", str(out)]) == 143
    before = (out / "pentagons.compaction.nc").read_bytes()
    assert main([*STUDY, "--out", str(out), "--tolerance", "1e-4"]) == 2
    assert "holds the compaction of another sample or with other settings" in capsys.readouterr().err
    assert (out / "pentagons.compaction.nc").read_bytes() == before
    (out / "disks.compaction.nc").write_bytes(b"keep")  # not a checkpoint: refused before any work too
    assert main([*STUDY, "--out", str(out)]) == 2
    assert "disks.compaction.nc: not a readable netCDF file" in capsys.readouterr().err
    assert sorted(os.listdir(out)) == ["disks.compaction.nc", "pentagons.compaction.nc"]
    assert (out / "pentagons.compaction.nc").read_bytes() == before


def _parsed(*argv):
    args = build_parser().parse_args(["study", *argv])
    return args, _study_particles(args)


def test_paper_size_preset():
    args, particles = _parsed("--paper-size")
    assert particles == {"pentagons": 14400, "disks": 10000}
    tests = _study_tests(args, particles)  # the strain rate of 400 particles at 1 cm/s: 0.01 sqrt(N / 400)
    assert (tests["pentagons"].velocity, tests["disks"].velocity) == (0.06, 0.05)
    assert tests["pentagons"].strain == 0.2  # eps_q ~0.6 at 400 particles
    args, particles = _parsed("--paper-size", "--velocity", "0.01")  # the paper's own speed
    assert {t.velocity for t in _study_tests(args, particles).values()} == {0.01}
    args, particles = _parsed("--particles", "1000")  # without the preset: the speed given, both sizes alike
    assert particles == {"pentagons": 1000, "disks": 1000}
    assert {t.velocity for t in _study_tests(args, particles).values()} == {0.01}


@pytest.mark.parametrize("argv, fragment", [
    (["--paper-size", "--particles", "400"], "--paper-size sets --particles (14400,10000); expected one of them"),
    (["--particles", "10,20,30"], "--particles 10,20,30: expected one whole number for both samples or 2"),
    (["--particles", "ten"], "--particles ten: expected one whole number"),
])
def test_bad_sizes_are_refused_in_one_line(tmp_path, capsys, argv, fragment):
    assert main(["study", "--out", str(tmp_path / "s"), *argv]) == 2
    err = capsys.readouterr().err
    assert fragment in err and len(err.strip().splitlines()) == 1 and not (tmp_path / "s").exists()


def test_estimate_from_measured_costs():
    from grainview.app.paper_size import COSTS, estimate, velocity_for
    from solver.parameters import BiaxialTest
    from solver.preparation import preparation

    prep = preparation("paper", particles=14400, shape="pentagon")
    test = BiaxialTest(velocity=velocity_for(14400))
    stages = estimate(prep, test, 5e-4, domains=1)
    compaction = COSTS[("pentagon", "compaction")][-1]  # the cost measured at 14,400
    steps = compaction.steps * np.sqrt(14400 / compaction.particles)  # steps as sqrt(N) from the measured size
    assert stages["compaction"][0] == round(steps)
    assert stages["compaction"][2] == pytest.approx(steps * 14400 * compaction.serial * 1e-6)
    # the test: the deposit's height h times (e^0.2 - 1) at 0.06 m/s, 5e-4 s a step, at the measured cost
    h, cost = prep.deposit_height(), COSTS[("pentagon", "test")][-1]
    assert stages["test"][0] == round(h * np.expm1(0.2) / (0.06 * 5e-4))
    assert stages["test"][2] == pytest.approx(h * np.expm1(0.2) / (0.06 * 5e-4) * 14400 * cost.serial * 1e-6)
    assert estimate(prep, test, 5e-4, domains=2)["test"][1] == cost.two_domains


def test_side_by_side_progress_without_a_terminal_prints_lines(capsys):
    from grainview.app.progress import SampleProgress as _SampleProgress

    progress = _SampleProgress.for_jobs(None)
    assert _SampleProgress.for_jobs(False) is False and _SampleProgress.for_jobs(True).terminal
    if progress.terminal:  # stderr is a terminal here: nothing to check
        return
    progress.every = 0.0
    with progress.at(1, "disks")(300, "biaxial test") as bar:
        bar.update(120)
    assert capsys.readouterr().out.startswith("disks: biaxial test: step 120 of at most 300, 0 min")
