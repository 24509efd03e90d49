"""Every setting in one place: the records' declared checks refuse each bad value in one line,
friction has one validator and one way into a running simulation, and the sample's history is
one record whose file attributes are those files have always carried."""

import re
import warnings
from dataclasses import fields, replace

import numpy as np
import pytest

from grainview.contract.errors import ParameterError
from solver.parameters import MAX_FRICTION, BiaxialTest, Parameters, problems
from solver.preparation import Preparation, prepare_sample, preparation
from solver.sample_history import SampleHistory


def _quiet(func, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return func(*args, **kwargs)


def test_every_field_is_declared_with_a_help_text():
    for record in (Parameters, Preparation, BiaxialTest):
        for f in fields(record):
            assert f.metadata.get("help"), f"{record.__name__}.{f.name} has no help"


@pytest.mark.parametrize("record, name, value, fragment", [
    (Parameters, "time_step", -1e-4, "time_step=-0.0001: expected a positive number of seconds"),
    (Parameters, "time_step", np.inf, "time_step=inf: expected a positive number of seconds"),
    (Parameters, "theta", 0.4, "theta=0.4: expected in [0.5, 1]"),
    (Parameters, "friction", 10.5, "friction=10.5: expected in [0, 10] (a Coulomb coefficient)"),
    (Parameters, "wall_friction", -0.1, "wall_friction=-0.1: expected in [0, 10]"),
    (Parameters, "max_iterations", 0, "max_iterations=0: expected >= 1"),
    (Parameters, "domains", 65, "domains=65: expected an integer in 1..64"),
    (Parameters, "alert", -1.0, "alert=-1.0: expected a positive length in m"),
    (Parameters, "tolerance", "small", "tolerance='small': expected > 0"),
    (Preparation, "friction", -0.5, "friction=-0.5: expected in [0, 10]"),
    (Preparation, "compaction_friction", 11.0, "compaction_friction=11.0: expected in [0, 10]"),
    (Preparation, "seed", 2**31, "seed=2147483648: expected an integer in 0 .. 2147483647"),
    (Preparation, "sigma0", 0.0, "sigma0=0.0: expected a positive stress in Pa"),
    (BiaxialTest, "strain", 1.0, "strain=1.0: expected a vertical strain eps_1 in (0, 1)"),
    (BiaxialTest, "velocity", np.nan, "velocity=nan: expected a finite wall speed > 0 in m/s"),
    (BiaxialTest, "every", 2.5, "every=2.5: expected a positive whole number of steps between snapshots"),
])
def test_a_bad_value_is_refused_naming_it(record, name, value, fragment):
    with pytest.raises(ParameterError, match=None) as caught:
        record(**{name: value}).validate()
    message = str(caught.value)
    assert fragment in message and "\n" not in message
    assert [p[0] for p in problems(record(**{name: value}))] == [name]


def test_the_defaults_pass_their_own_checks():
    for record in (Parameters, Preparation, BiaxialTest):
        assert problems(record()) == []
        record().validate()


def test_friction_has_one_validator():
    """The test's friction of a preparation and the stepper's friction accept and refuse the
    same values: the bounds are MAX_FRICTION's."""
    for value in (0.0, 0.4, MAX_FRICTION):
        Parameters(friction=value).validate()
        Preparation(friction=value).validate()
    for value in (-1e-9, MAX_FRICTION * (1 + 1e-12), np.nan, np.inf):
        with pytest.raises(ParameterError, match="friction="):
            Parameters(friction=value).validate()
        with pytest.raises(ParameterError, match="friction="):
            Preparation(friction=value).validate()


def test_a_running_simulation_takes_new_parameters_only_once_checked():
    from solver import compaction_sample

    sim = compaction_sample(6, "disk")
    before = sim.parameters
    with pytest.raises(ParameterError, match="friction=-1"):
        sim.set_parameters(friction=-1.0)
    assert sim.parameters is before and sim.parameters.friction == 0.4
    with pytest.raises(ParameterError, match="density: fixed when the simulation is built"):
        sim.set_parameters(density=1000.0)
    assert sim.set_parameters(friction=0.25).friction == 0.25 and before.friction == 0.4


def test_friction_reaches_a_prepared_sample_by_the_preparation_only():
    with pytest.raises(ParameterError, match="the grains' friction is the preparation's"):
        prepare_sample(preparation("paper", particles=6, shape="disk"), friction=0.3)


ATTRIBUTES = {"preparation_particles", "preparation_shape", "preparation_seed", "preparation_aspect",
              "preparation_sigma0", "preparation_friction", "preparation_compaction_friction",
              "preparation_max_wall_speed", "preparation_max_inertia_number", "preparation_pressure_ramp",
              "preparation_max_steps", "preparation_name", "sigma0_Pa", "compaction_steps", "compaction_settled",
              "compaction_inertia_number", "compaction_unconverged_steps",
              "compaction_unconverged_local_law_residual"}
"""The history's attributes a prepared sample's file has carried since before SampleHistory."""


def test_the_history_is_one_record_written_and_read_back_as_before(tmp_path):
    from solver import load_sample
    from solver.output import Recorder

    prep = preparation("frictionless", particles=8, shape="disk", seed=3, max_steps=30)
    sim = _quiet(prepare_sample, prep, progress=False)
    history = sim.history
    assert isinstance(history, SampleHistory) and history.preparation == prep
    assert history.compaction_steps == sim.step_index == 30 and history.settled is False
    assert sim.parameters.friction == prep.friction == 0.4  # compacted frictionless, tested with 0.4
    attrs = history.attrs()
    assert set(attrs) == ATTRIBUTES
    assert attrs["preparation_name"] == "custom" and attrs["preparation_compaction_friction"] == 0.0  # max_steps
    assert attrs["sigma0_Pa"] == 1e4 and attrs["compaction_steps"] == 30 and attrs["compaction_settled"] == 0
    assert attrs["preparation_max_inertia_number"] == "none"
    # the simulation's old names read the same record
    assert (sim.sigma0, sim.settled, sim.compaction_steps) == (1e4, False, 30)
    assert sim.preparation_attrs == attrs
    path = tmp_path / "sample.nc"
    with Recorder(path, sim, attrs=attrs) as rec:
        rec.write()
    loaded = load_sample(path)
    # restart reads each field by its declared type; alert and skin are written as the lengths used
    assert (loaded.parameters.alert, loaded.parameters.skin) == (sim.alert, sim.skin)
    assert replace(loaded.parameters, alert=None, skin=None) == sim.parameters
    for f in fields(Parameters):
        if f.name not in ("alert", "skin"):
            assert type(getattr(loaded.parameters, f.name)) is type(getattr(sim.parameters, f.name)), f.name
    again = loaded.history
    assert again.sigma0 == 1e4 and again.preparation is None
    assert set(again.attrs()) == ATTRIBUTES - {"sigma0_Pa"}
    for key, value in again.attrs().items():
        assert value == attrs[key] or str(value) == str(attrs[key]), key


def test_a_sample_no_preparation_made_has_an_empty_history():
    from solver import compaction_sample

    sim = compaction_sample(6, "disk", sigma0=2e4)
    assert sim.history.sigma0 == 2e4 and sim.history.attrs() == {} and sim.history.settled is None
    with pytest.raises(AttributeError):  # the history is written in one place, sim.history
        sim.sigma0 = 1e3
    assert sim.sigma0 == 2e4
    assert SampleHistory.from_attrs({"title": "x"}).attrs() == {}
    assert np.isnan(SampleHistory.from_attrs({}).sigma0)


def test_the_scenes_take_their_defaults_from_the_records():
    import inspect

    from grainview.app.ensemble import RunSpec
    from solver.scenes import biaxial_test, compaction_sample, isotropic_compaction

    def defaults(func):
        return {k: p.default for k, p in inspect.signature(func).parameters.items()}

    sample, compaction, test = defaults(compaction_sample), defaults(isotropic_compaction), defaults(biaxial_test)
    prep = Preparation()
    assert (sample["n"], sample["shape"], sample["sigma0"], sample["seed"], sample["aspect"],
            sample["max_wall_speed"]) == (prep.particles, prep.shape, prep.sigma0, prep.seed, prep.aspect,
                                          prep.max_wall_speed)
    assert "friction" not in sample and "time_step" not in sample  # Parameters' own, through **parameters
    assert (compaction["max_steps"], compaction["max_inertia_number"], compaction["pressure_ramp"]) == (
        prep.max_steps, prep.max_inertia_number, prep.pressure_ramp)
    assert (test["strain"], test["velocity"], test["every"]) == (BiaxialTest.strain, BiaxialTest.velocity,
                                                                 BiaxialTest.every)
    spec = RunSpec()
    assert (spec.shape, spec.particles, spec.seed) == (prep.shape, prep.particles, prep.seed)
    assert spec.test() == BiaxialTest()


@pytest.mark.parametrize("change, named", [
    (dict(overlap_recovery_iterations="abc"), "overlap_recovery_iterations='abc'"),
    (dict(overlap_recovery_iterations=0), "overlap_recovery_iterations=0"),
    (dict(overlap_recovery_tolerance=-1.0), "overlap_recovery_tolerance=-1.0"),
    (dict(overlap_recovery_threshold=float("nan")), "overlap_recovery_threshold=nan"),
    (dict(seed=-1), "seed=-1"),
    (dict(solver="nlgs", shuffle="yes"), "shuffle='yes'"),
])
def test_every_numerical_setting_has_its_check(change, named):
    from solver.parameters import Parameters

    with pytest.raises(ParameterError, match=re.escape(named)):
        Parameters(**change).validate()


def test_the_shape_is_checked_by_the_preparation_as_by_the_command_line():
    from solver.shape_families import MAX_VERTICES

    Preparation(shape=MAX_VERTICES).validate()
    with pytest.raises(ParameterError, match=f"shape=100: expected at most {MAX_VERTICES} vertices"):
        Preparation(shape=100).validate()


def test_a_box_too_narrow_for_its_largest_particle_is_refused_before_the_deposit():
    """Preparation.validate refuses the sizes whose deposit would fail (the deposit's own
    check, packing.deposit, is the independent computation): 4 particles at aspect 2 or 43 at
    aspect 20 make a box narrower than the largest diameter; 5 and 44 deposit."""
    from solver.packing import box_width_for, deposit

    for particles, aspect, fits in ((4, 2.0, False), (5, 2.0, True), (43, 20.0, False), (44, 20.0, True)):
        prep = Preparation(particles=particles, aspect=aspect)
        width = box_width_for(particles, aspect_ratio=aspect)
        if fits:
            prep.validate()
            assert len(deposit(particles, nvert=0, width=width, seed=0).pos) == particles
        else:
            with pytest.raises(ParameterError, match=rf"particles={particles}, aspect={aspect:g}: the deposit's box "
                                                     rf"would be {width:.3g} m wide, narrower than its largest"):
                prep.validate()
            with pytest.raises(ParameterError, match="expected a box width"):
                deposit(particles, nvert=0, width=width, seed=0)
