"""The command line's simulation options are derived from the settings records (their flags,
types, choices, defaults and help), a named preparation's own values hold for the options not
given, and run, study and ensemble reach the simulation through an engine of the registry."""

import ast
from dataclasses import fields
from pathlib import Path

import numpy as np
import pytest

import grainview.app.cli as cli
from grainview.app import settings
from grainview.app.cli import build_parser, main
from solver.parameters import BiaxialTest, Parameters
from solver.preparation import Preparation
from solver.sample_history import SampleHistory

RECORDS = (Parameters, Preparation, BiaxialTest)
SIMULATING = ("run", "study", "ensemble")


def _subparser(name):
    return build_parser()._subparsers._group_actions[0].choices[name]


def _field(name):
    return next(f for record in RECORDS for f in fields(record) if f.name == name)


def test_every_derived_option_has_its_fields_default_type_and_help():
    seen = set()
    for command in SIMULATING:
        for action in _subparser(command)._actions:
            if not isinstance(action, settings.Given):
                continue
            f = _field(action.dest)
            seen.add(action.dest)
            assert action.default == f.default, (command, action.dest)
            shown = "none" if f.default is None else f"{f.default:g}" if isinstance(f.default, float) else f.default
            assert f"default {shown}" in action.help, action.help
            if f.metadata.get("choices"):
                assert tuple(action.choices) == tuple(f.metadata["choices"]())
            elif command == "study" and action.dest == "particles":  # one size, or one per sample: parsed by the study
                assert action.type is str and "comma-separated, one per sample" in action.help
            else:
                kinds = [kind.strip() for kind in str(f.type).split("|")]
                expected = {"float": float, "int": int, "str": str}[kinds[0]]
                if expected is float and "None" in kinds:  # float | None: a float, or the word none
                    expected = settings.optional_float
                assert action.type is expected
    expected = set(settings.SOLVER_OPTIONS) | set(settings.PREPARATION_OPTIONS) | set(settings.TEST_OPTIONS) | {"particles", "seed",
                                                                                                 "shape"}
    assert seen == expected


def _set_defaults(parser) -> dict:
    """The values ``parser`` and its subparsers set by ``set_defaults`` (no option of theirs)."""
    found = dict(parser._defaults)
    for action in parser._actions:
        if isinstance(action.choices, dict):  # a subcommand's parsers
            for sub in action.choices.values():
                found.update(_set_defaults(sub))
    return found


def test_no_option_of_a_simulating_command_bypasses_the_records():
    """An option whose destination is a field of the records is the field's own option, and no
    ``set_defaults`` gives a field of the records a value of the command line's own."""
    names = {f.name for record in RECORDS for f in fields(record)}
    for command in SIMULATING:
        for action in _subparser(command)._actions:
            if action.dest in names:
                assert isinstance(action, settings.Given), (command, action.option_strings)
        assert not names & set(_set_defaults(_subparser(command))), command


def test_the_check_sees_a_record_field_set_by_set_defaults():
    import argparse

    parser = argparse.ArgumentParser()
    sub = parser.add_subparsers().add_parser("run")
    sub.set_defaults(func=print, tolerance=1e-3)
    assert _set_defaults(parser) == {"func": print, "tolerance": 1e-3}


def _numeric_defaults(source):
    """The ``default=`` keywords of ``source``, and every keyword of a ``set_defaults(...)`` call,
    whose value is a number written out."""
    found = []
    tree = ast.parse(source)
    set_defaults = {id(k) for node in ast.walk(tree) if isinstance(node, ast.Call)
                    and isinstance(node.func, ast.Attribute) and node.func.attr == "set_defaults" for k in node.keywords}
    for node in ast.walk(tree):
        if isinstance(node, ast.keyword) and (node.arg == "default" or id(node) in set_defaults):
            sign = -1 if isinstance(node.value, ast.UnaryOp) and isinstance(node.value.op, ast.USub) else 1
            value = node.value.operand if isinstance(node.value, ast.UnaryOp) else node.value
            if isinstance(value, ast.Constant) and isinstance(value.value, (int, float)) \
                    and not isinstance(value.value, bool):
                found.append((node.lineno, sign * value.value))
    return found


def _numeric_constants(source, allowed=()):
    """The module-level assignments of ``source`` whose value holds a number written out (a
    default kept under a name of its own), except the names ``allowed``."""
    found = []
    for node in ast.parse(source).body:
        if isinstance(node, (ast.Assign, ast.AnnAssign)) and node.value is not None:
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            names = {t.id for t in targets if isinstance(t, ast.Name)}
            numbers = [c.value for c in ast.walk(node.value) if isinstance(c, ast.Constant)
                       and isinstance(c.value, (int, float)) and not isinstance(c.value, bool)]
            if numbers and not names <= set(allowed):
                found.append((node.lineno, sorted(names), numbers))
    return found


NOT_SETTINGS = set()
"""Module-level numbers of cli.py that are no setting (none today)."""


def test_the_command_line_holds_no_numeric_default_of_its_own():
    """Neither an option's ``default=`` nor a module-level constant of the command line's modules
    holds a number:
    defaults come from the settings records (solver.parameters) or the library function the
    option feeds, imported as values (grainview.app.ensemble.SEEDS_PER_SETTING...)."""
    assert _numeric_defaults("p.add_argument('--x', default=-0.5)\np.add_argument('--y', default=3)\n"
                             "p.set_defaults(func=run, every=20)") == [(1, -0.5), (2, 3), (3, 20)]  # the scan sees them
    assert _numeric_constants("SEEDS = 3\nSIZE = {'n': 11}\nNAMES = ('a',)\nX = len('..') + 7", {"X"}) \
        == [(1, ["SEEDS"], [3]), (2, ["SIZE"], [11])]
    from grainview.app import convert_command

    for module in (cli, settings, convert_command):  # the command line's options
        source = Path(module.__file__).read_text(encoding="utf-8")
        assert _numeric_defaults(source) == []
        assert _numeric_constants(source, NOT_SETTINGS) == []


def test_options_of_other_functions_take_those_functions_defaults():
    from grainview.datasets import harmonic_series
    from grainview.formats.pegs import convert_pegs
    import inspect

    from grainview.app.demo import run_demo
    from grainview.app.ensemble import SEEDS_PER_SETTING, grid

    demo = build_parser().parse_args(["demo"])
    assert (demo.snapshots, demo.contacts) == tuple(inspect.signature(run_demo).parameters[k].default
                                                    for k in ("snapshots", "contacts"))
    assert demo.seed == inspect.signature(harmonic_series).parameters["seed"].default
    assert build_parser().parse_args(["ensemble"]).seeds == SEEDS_PER_SETTING \
        == inspect.signature(grid).parameters["seeds"].default
    from grainview.analysis.strain import RESIDUAL_STRAIN

    assert build_parser().parse_args(["report", "x.nc"]).residual_strain == RESIDUAL_STRAIN
    pegs = build_parser().parse_args(["convert", "pegs", "a.txt", "--positions", "p.txt", "--metres-per-pixel", "1",
                                      "--force-unit-n", "1", "--out", "x.nc"])
    assert (pegs.frame_interval, pegs.thickness, pegs.density) == tuple(
        inspect.signature(convert_pegs).parameters[name].default
        for name in ("frame_interval_s", "thickness_m", "density_kg_m3"))


@pytest.mark.parametrize("argv, expected", [
    ([], {"max_inertia_number": None, "compaction_friction": None, "friction": 0.4}),
    (["--preparation", "quasistatic"], {"max_inertia_number": 2e-4, "max_steps": 200000}),
    (["--preparation", "quasistatic", "--max-inertia-number", "1e-3"], {"max_inertia_number": 1e-3}),
    (["--preparation", "frictionless"], {"compaction_friction": 0.0, "friction": 0.4}),
    (["--preparation", "frictionless", "--friction", "0.3", "--aspect", "1.5"],
     {"compaction_friction": 0.0, "friction": 0.3, "aspect": 1.5}),
])
def test_a_named_preparation_holds_where_no_option_is_given(argv, expected):
    args = build_parser().parse_args(["run", *argv])
    prep = settings.preparation_of(args, "pentagon")
    for name, value in expected.items():
        assert getattr(prep, name) == value, name


def test_only_the_solver_settings_given_are_passed_on():
    args = build_parser().parse_args(["run", "--time-step", "4e-4", "--solver", "nlgs"])
    assert settings.solver_parameters(args) == {"time_step": 4e-4, "solver": "nlgs"}
    assert settings.solver_parameters(build_parser().parse_args(["run"])) == {}
    old = build_parser().parse_args(["run", "--acceleration", "off"])
    assert settings.solver_parameters(old) == {"solver": "nlgs"}


@pytest.mark.parametrize("argv, line", [
    (["--every", "0"], "--every 0: expected a positive whole number of steps between snapshots"),
    (["--strain", "1.5"], "--strain 1.5: expected a vertical strain eps_1 in (0, 1)"),
    (["--acceleration", "off", "--solver", "nlgs"], "--acceleration and --solver name the same setting"),
    (["--wall-mass", "0"], "--wall-mass 0: expected a finite multiple >= 1e-06 of the sample's mass, or none"),
    (["--wall-mass", "1e-300"], "--wall-mass 1e-300: expected a finite multiple >= 1e-06 of the sample's mass, or none"),
    (["shear", "--wall-mass", "0.1"], "the right wall's mass is the biaxial test's; scene shear has no such wall"),
])
def test_bad_test_settings_are_named_by_their_flag(tmp_path, capsys, argv, line):
    assert main(["run", *argv, "--out", str(tmp_path / "x.nc")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and line in err
    assert list(tmp_path.iterdir()) == []


# -- engines -------------------------------------------------------------------------------
CALLS = []


class FakeEngine:
    """An engine that simulates nothing: it records what it is asked."""

    name = "fake"

    def check(self, preparation, parameters, test=None):
        CALLS.append(("check", preparation, dict(parameters), test))

    def prepare(self, preparation, parameters, progress=None):
        CALLS.append(("prepare", preparation, dict(parameters)))
        sample = type("Sample", (), {})()
        sample.history = SampleHistory(sigma0=preparation.sigma0, preparation=preparation, settled=True,
                                       compaction_steps=0, compaction_stress=np.full(2, preparation.sigma0))
        sample.parameters = Parameters(**parameters)
        return sample

    def shear(self, sample, path, test, *, attrs=None, near_contacts=False, overwrite=False, progress=None,
              compress=True):
        CALLS.append(("shear", Path(path).name, test, attrs["preparation_name"]))
        return 0

    def write_state(self, sample, path, *, attrs=None, near_contacts=False, overwrite=False, compress=True):
        CALLS.append(("write_state", Path(path).name, attrs))

    def resume(self, path, progress=None, compress=True):
        CALLS.append(("resume", Path(path).name))
        return 0

    def file_state(self, path):
        return "missing"


@pytest.fixture
def fake_engine(monkeypatch):
    import solver.engine

    monkeypatch.setitem(solver.engine.ENGINES, "fake", f"{__name__}:FakeEngine")
    CALLS.clear()
    yield CALLS


def test_the_engines_are_a_registry():
    from grainview.contract.errors import ParameterError
    from solver.engine import DEFAULT_ENGINE, ContactDynamics, Engine, engine, engine_names

    assert engine_names()[0] == DEFAULT_ENGINE and isinstance(engine(), ContactDynamics)
    assert isinstance(engine(), Engine) and isinstance(FakeEngine(), Engine)
    with pytest.raises(ParameterError, match="engine='lammps': expected one of solver"):
        engine("lammps")


def test_run_reaches_the_simulation_through_the_chosen_engine(tmp_path, fake_engine, capsys):
    """Another engine plugs in through the registry alone: ``run --engine fake`` hands it the
    records the command line made."""
    assert main(["run", "--engine", "fake", "--particles", "12", "--friction", "0.3", "--time-step", "4e-4",
                 "--strain", "0.05", "--every", "7", "--out", str(tmp_path / "r.nc"), "--progress", "off"]) == 0
    (check, prep, parameters, test), prepare, shear = fake_engine
    assert check == "check" and prepare[0] == "prepare" and shear[0] == "shear"
    assert prep.particles == 12 and prep.friction == 0.3 and parameters == {"time_step": 4e-4}
    assert test == BiaxialTest(strain=0.05, velocity=BiaxialTest.velocity, every=7)
    assert shear[1:] == ("r.nc", test, "custom")  # the paper's preparation with another friction
    main(["run", "isotropic", "--engine", "fake", "--out", str(tmp_path / "i.nc"), "--progress", "off"])
    assert fake_engine[-1] == ("write_state", "i.nc", {"scene": "isotropic"})
    assert fake_engine[-3][3] is None  # an isotropic run checks the preparation without a test


def test_an_optional_setting_takes_the_word_none(capsys):
    assert build_parser().parse_args(["run", "--wall-mass", "none"]).wall_mass is None
    assert build_parser().parse_args(["run", "--wall-mass", "0.1"]).wall_mass == 0.1
    assert build_parser().parse_args(["run", "--compaction-friction", "None"]).compaction_friction is None
    with pytest.raises(SystemExit):
        build_parser().parse_args(["run", "--wall-mass", "heavy"])
    assert "argument --wall-mass: invalid float value: 'heavy'" in capsys.readouterr().err


def test_an_engine_that_does_not_take_the_wall_mass_is_not_given_one(tmp_path, fake_engine, capsys):
    argv = ["run", "--engine", "fake", "--particles", "12", "--out", str(tmp_path / "r.nc"), "--progress", "off"]
    assert main([*argv, "--wall-mass", "0.1"]) == 2
    assert "wall_mass=0.1: the right wall's mass is set by this package's solver (solver), not by engine fake" \
        in capsys.readouterr().err
    assert fake_engine == [] and list(tmp_path.iterdir()) == []


def test_ensemble_runs_go_through_their_engine(tmp_path, fake_engine):
    from grainview.app.ensemble import grid, run_one

    spec, = grid(shapes=("disk",), particles=(12,), seeds=1, engine="fake", strain=0.05, every=5)
    result = run_one(spec, tmp_path)
    assert result["action"] == "ran" and [c[0] for c in fake_engine] == ["check", "check", "prepare", "shear"]
    assert fake_engine[-1][1] == f"{spec.name}.nc" and fake_engine[-1][2] == spec.test()


class CheckpointingEngine(FakeEngine):
    """A fake engine that keeps compaction checkpoints: the study asks it to check one."""

    name = "fake-checkpoints"

    def check_checkpoint(self, checkpoint, preparation, parameters):
        CALLS.append(("check_checkpoint", Path(checkpoint).name, preparation.shape))


def test_the_study_asks_the_engine_to_check_a_checkpoint_it_finds(tmp_path, fake_engine, monkeypatch):
    """A compaction checkpoint left by an earlier run is checked by the engine that keeps such
    files (through solver.engine.check_checkpoint), whatever its name; an engine without
    checkpoints is not asked and starts afresh."""
    import solver.engine

    monkeypatch.setitem(solver.engine.ENGINES, "fake-checkpoints", f"{__name__}:CheckpointingEngine")
    out = tmp_path / "study"
    out.mkdir()
    (out / "pentagons.compaction.nc").write_bytes(b"left by an earlier run")
    argv = ["study", "--particles", "12", "--strain", "0.05", "--every", "5", "--no-report", "--progress", "off",
            "--out", str(out), "--jobs", "1"]
    assert main([*argv, "--engine", "fake-checkpoints"]) == 0
    assert ("check_checkpoint", "pentagons.compaction.nc", "pentagon") in fake_engine
    assert not any(c[0] == "check_checkpoint" and c[1].startswith("disks") for c in fake_engine)
    fake_engine.clear()
    assert main([*argv, "--engine", "fake"]) == 0
    assert not any(c[0] == "check_checkpoint" for c in fake_engine) and any(c[0] == "prepare" for c in fake_engine)


def test_a_compacted_study_does_not_take_a_foreign_file_for_an_empty_one(tmp_path, capsys):
    import netCDF4

    out = tmp_path / "samples"
    out.mkdir()
    with netCDF4.Dataset(out / "pentagons.nc", "w") as nc:  # someone's own netCDF file, no snapshot of a run
        nc.createDimension("x", 3)
        nc.createVariable("temperature", "f8", ("x",))[:] = [1.0, 2.0, 3.0]
    before = (out / "pentagons.nc").read_bytes()
    assert main(["study", "--scene", "isotropic", "--particles", "20", "--jobs", "1", "--progress", "off",
                 "--out", str(out)]) == 2
    assert "pentagons.nc is not a file of grainview's runs (no snapshot, no scene attribute); pass --overwrite" \
        in capsys.readouterr().err
    assert (out / "pentagons.nc").read_bytes() == before and sorted(p.name for p in out.iterdir()) == ["pentagons.nc"]
