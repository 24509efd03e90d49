"""Sample preparation options: a quasi-static compaction keeps its inertia number under the
cap, the pressure ramp, the compaction friction, and clear errors for bad options."""

import warnings

import numpy as np
import pytest

from grainview.contract.errors import ParameterError
from grainview.contract.shapes import particle_area
from solver import compaction_sample, isotropic_compaction
from solver.preparation import PRESETS, Preparation, prepare_sample, preparation
from solver.scenes import inertia_number_speed


def _solid_fraction(sim):
    lo, hi = sim.walls.box_bounds()
    return float(particle_area(sim.radius, sim.n_vertices).sum() / np.prod(hi - lo))


def _quiet(func, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return func(*args, **kwargs)


def test_inertia_number_speed_by_hand():
    # I = (v / L) d sqrt(rho / sigma0): v = 1e-3 * 0.5 / (0.04 * sqrt(2500 / 1e4)) = 0.025 m/s
    assert inertia_number_speed(1e-3, 0.5, 0.04, 2500.0, 1e4) == pytest.approx(0.025, rel=1e-14)


def test_quasi_static_compaction_keeps_its_inertia_number_under_the_cap():
    cap = 2e-4
    sim = compaction_sample(40, "disk", seed=1)
    _quiet(isotropic_compaction, sim, max_steps=1500, max_inertia_number=cap, progress=False)
    # the cap is set from the box before each step and I measured after it: the box shrinks
    # by v h in between, a relative change of ~1e-5 here
    assert 0 < sim.compaction_inertia_number <= cap * (1 + 1e-4)
    # without the cap the same deposit is closed faster than that
    free = compaction_sample(40, "disk", seed=1)
    _quiet(isotropic_compaction, free, max_steps=1500, progress=False)
    assert free.compaction_inertia_number > 2 * cap


def test_pressure_ramp_raises_the_stress_linearly_to_sigma0():
    sim = compaction_sample(20, "disk", seed=2, sigma0=1e4)
    h = sim.parameters.time_step
    ramp = 40 * h
    seen = []
    with sim.watch(before=lambda: seen.append(sim.walls.stress[[1, 2]].copy())):
        _quiet(isotropic_compaction, sim, max_steps=60, pressure_ramp=ramp, progress=False)
    seen = np.array(seen)
    np.testing.assert_allclose(seen[:40, 0], 1e4 * np.arange(1, 41) / 40, rtol=1e-12)
    np.testing.assert_allclose(seen[40:], 1e4, rtol=0)
    assert not sim.settled  # 60 steps: equilibrium is not looked for during the ramp
    np.testing.assert_allclose(sim.walls.stress[[1, 2]], 1e4)


def test_frictionless_compaction_is_denser_and_the_test_gets_its_friction_back():
    frictional = _quiet(prepare_sample, preparation("paper", particles=60, shape="disk", seed=3, max_steps=8000))
    frictionless = _quiet(prepare_sample, preparation("frictionless", particles=60, shape="disk", seed=3,
                                                      max_steps=8000))
    assert frictional.settled and frictionless.settled
    assert frictionless.parameters.friction == frictional.parameters.friction == 0.4
    assert _solid_fraction(frictionless) > _solid_fraction(frictional) + 0.005


def test_presets_and_attributes():
    assert PRESETS["paper"] == Preparation()
    from dataclasses import replace
    assert PRESETS["fast"] == replace(Preparation(), max_wall_speed=0.2)  # only the walls' speed cap differs
    prep = preparation("frictionless", particles=100, seed=4)
    assert prep.compaction_friction == 0.0 and prep.particles == 100 and prep.seed == 4
    attrs = prep.attrs()
    assert attrs["preparation_compaction_friction"] == 0.0
    assert attrs["preparation_max_inertia_number"] == "none"


@pytest.mark.parametrize("changes,match", [
    (dict(particles=1), "particles"), (dict(aspect=0.0), "aspect"), (dict(compaction_friction=-1.0), "compaction_"),
    (dict(max_inertia_number=0.0), "max_inertia_number"), (dict(pressure_ramp=-1.0), "pressure_ramp"),
    (dict(shape="hexagram"), "shape"),
])
def test_bad_preparations_say_what_is_wrong(changes, match):
    with pytest.raises(ParameterError, match=match):
        preparation("paper", **changes)


def test_unknown_preset():
    with pytest.raises(ParameterError, match="expected one of"):
        preparation("dense")


def test_the_s1s2_preset_prepares_each_shape_as_the_paper_s_sample():
    assert preparation("s1s2", shape="pentagon").compaction_friction is None  # the test's 0.4
    assert preparation("s1s2", shape="disk", particles=50).compaction_friction == 0.0
    with pytest.raises(ParameterError, match="s1s2"):
        preparation("s1s2", shape=7)


def test_a_test_started_from_a_saved_sample_shows_the_samples_contacts_first(tmp_path):
    """load_sample + biaxial_test: the test's first snapshot holds the contacts and forces of
    the sample's last snapshot (same pairs, same forces), and the test goes on from there."""
    import grainview
    from solver import biaxial_test, load_sample
    from solver.output import Recorder

    sim = _quiet(prepare_sample, preparation("paper", particles=30, shape="pentagon", seed=2, max_steps=3000),
                 progress=False)
    sample = tmp_path / "sample.nc"
    with Recorder(sample, sim, attrs={"sigma0_Pa": 1e4}) as rec:
        rec.write()
    test = tmp_path / "test.nc"
    _quiet(biaxial_test, load_sample(sample), test, strain=0.002, every=5, progress=False)
    with grainview.open_dataset(sample, chunks=None) as a, grainview.open_dataset(test, chunks=None) as b:
        first, last = b.isel(time=0), a.isel(time=-1)
        n = int(last.contact_count)
        assert n > 20 and int(first.contact_count) == n
        pairs = lambda s: {(int(i), int(j)): (float(fn), float(ft))  # noqa: E731
                           for i, j, fn, ft in zip(s.i.values[:n], s.j.values[:n], s.fn.values[:n], s.ft.values[:n])}
        before, after = pairs(last), pairs(first)
        assert before.keys() == after.keys()
        for key, (fn, ft) in before.items():
            assert after[key] == pytest.approx((fn, ft), rel=1e-12, abs=1e-12)
        np.testing.assert_array_equal(first.position.values, last.position.values)
        assert b.sizes["time"] > 2 and int(b.contact_count[-1]) > 20


def test_a_test_records_how_its_sample_was_prepared(tmp_path):
    """biaxial_test writes the preparation (preset name included) and the compaction's outcome
    without being told, from prepare_sample and again from a saved sample."""
    import grainview
    from solver import biaxial_test, load_sample
    from solver.output import Recorder

    sim = _quiet(prepare_sample, preparation("frictionless", particles=20, shape="disk", seed=4), progress=False)
    sample = tmp_path / "sample.nc"
    with Recorder(sample, sim, attrs=sim.preparation_attrs) as rec:
        rec.write()
    for start, name in ((sim, "direct.nc"), (load_sample(sample), "from_file.nc")):
        _quiet(biaxial_test, start, tmp_path / name, strain=0.001, every=5, progress=False)
        with grainview.open_dataset(tmp_path / name, chunks=None) as ds:
            assert ds.attrs["preparation_name"] == "frictionless"
            assert ds.attrs["preparation_compaction_friction"] == 0.0 and ds.attrs["solver_friction"] == 0.4
            assert ds.attrs["compaction_steps"] == sim.compaction_steps
            assert ds.attrs["compaction_settled"] == int(sim.settled)
