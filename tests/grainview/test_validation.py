"""validate(): every problem of the contract named, all at once, lazily in one pass."""

import numpy as np
import pytest
import xarray as xr

import grainview
from grainview.contract.errors import SchemaError

from . import builders
from .conftest import raise_if_dask_computes


def _problems(ds):
    with pytest.raises(SchemaError) as info:
        grainview.validate(ds)
    return info.value.problems


def test_valid_dataset_passes_eager_and_chunked(prepare):
    ds = prepare(builders.mixed_contacts())
    assert grainview.validate(ds) is ds


def test_chunked_validation_is_a_single_compute():
    ds = builders.mixed_contacts(t=4).chunk(time=1)
    with raise_if_dask_computes(max_computes=1):
        ds.grain.validate()


def test_missing_variable_and_wrong_dims():
    ds = builders.two_disks().drop_vars("fn")
    ds["radius"] = ds.radius.expand_dims(time=ds.time)
    problems = _problems(ds)
    assert any("'fn' is missing" in p for p in problems)
    assert any("'radius' has dims ('time', 'particle')" in p for p in problems)


def test_shuffled_dims_and_float_integers():
    ds = builders.two_disks()
    ds["normal"] = ds.normal.transpose("time", "xy", "contact")
    ds["i"] = ds.i.astype(float)
    problems = _problems(ds)
    assert any("'normal' has dims in order" in p for p in problems)
    assert any("'i' has dtype float64, expected an integer" in p for p in problems)


@pytest.mark.parametrize("backend_name", ["eager", "chunked"])
def test_all_value_problems_are_collected(backend_name):
    ds = builders.square_lattice()
    ds["fn"][0, 0] = np.nan
    ds["normal"][0, 1] = [2.0, 0.0]
    ds["j"][0, 2] = 999
    ds["radius"][3] = -1.0
    ds["kind"][0, 4] = 7
    if backend_name == "chunked":
        ds = ds.chunk(time=1)
    problems = _problems(ds)
    text = "\n".join(problems)
    assert len(problems) == 5, text
    assert "fn: 1 NaN" in text
    assert "normal: 1 occupied slot(s) whose normal is not a unit vector" in text
    assert "j: 1 occupied slot(s) with a body id outside [0, 12)" in text
    assert "radius: 1 particle(s) with negative" in text
    assert "kind: 1 occupied slot(s)" in text


def test_empty_slots_are_not_checked():
    ds = builders.two_disks()
    assert ds.sizes["contact"] > 1 and np.isnan(ds.fn[0, 1])  # padding holds fill values
    grainview.validate(ds)


def test_pair_order_and_particle_range():
    ds = builders.two_disks()
    ds["i"][0, 0], ds["j"][0, 0] = 1, 0
    assert any("i >= j" in p for p in _problems(ds))
    ds = builders.two_disks()
    ds["i"][0, 0] = -3
    assert any("i: 1 occupied slot(s) with a particle id outside [0, 2)" in p for p in _problems(ds))


def test_not_a_dataset():
    with pytest.raises(SchemaError, match="expected an xarray.Dataset"):
        grainview.validate({"fn": 1})


@pytest.mark.parametrize("chunked", [False, True])
def test_a_pair_stored_twice_in_one_snapshot_is_reported(chunked):
    from .test_persistence import S, sequence_dataset

    ds = sequence_dataset([[(0, 1, S, 1.0), (1, 2, S, 1.0)], [(0, 1, S, 1.0), (0, 1, S, 2.0), (2, 3, S, 1.0)]])
    ds = ds.chunk({"time": 1}) if chunked else ds
    with pytest.raises(SchemaError, match=r"1 slot\(s\) repeating a pair"):
        grainview.validate(ds)
    # the same pair in two snapshots is normal
    grainview.validate(sequence_dataset([[(0, 1, S, 1.0)], [(0, 1, S, 2.0)]]))


def test_wrong_units_are_reported_missing_ones_are_taken_as_the_contracts():
    ds = builders.mixed_contacts()
    ds["fn"].attrs["units"] = "kN"
    ds["radius"].attrs["units"] = "mm"
    with pytest.raises(SchemaError) as caught:
        grainview.validate(ds)
    message = str(caught.value)
    assert "'fn' has units 'kN', expected 'N'" in message and "'radius' has units 'mm', expected 'm'" in message
    ds = builders.mixed_contacts()
    ds["kind"].attrs["units"] = ""  # another spelling of dimensionless
    del ds["position"].attrs["units"]  # as after an edit that dropped the attributes
    grainview.validate(ds)


def _four_snapshots(time=(0.0, 0.5, 1.0, 1.5), step=None):
    """square_lattice's one snapshot repeated four times at ``time`` (and ``step``)."""
    ds = builders.square_lattice()
    ds = xr.concat([ds.isel(time=[0])] * 4, "time", data_vars="minimal").assign_coords(time=list(time))
    ds["contact_count"] = ds.contact_count.astype("i4")
    if step is not None:
        ds["step"] = ("time", np.asarray(step, "i4"))
    return ds


@pytest.mark.parametrize("chunked", [False, True])
def test_time_must_increase_strictly(chunked):
    def problems(**kw):
        ds = _four_snapshots(**kw)
        return _problems(ds.chunk(time=1) if chunked else ds)

    grainview.validate(_four_snapshots(step=[0, 10, 20, 30]))
    found = problems(time=(0.0, 0.5, 0.5, 1.5))
    assert found == ["time: 1 snapshot(s) repeating the previous snapshot's time (first: snapshot 2, time = 0.5 s); "
                     "expected time to increase strictly (each snapshot written once)"]
    found = problems(time=(0.0, 1.0, 0.5, 0.2))
    assert found == ["time: 2 snapshot(s) earlier than the previous snapshot (first: snapshot 2, time = 0.5 s after "
                     "1 s); expected time to increase strictly"]
    # the same snapshot written twice: same step, same time
    found = problems(time=(0.0, 0.5, 0.5, 1.5), step=[0, 10, 10, 30])
    assert len(found) == 2 and found[1].startswith("step: 1 snapshot(s) repeating the previous snapshot's step "
                                                   "(first: snapshot 2, step = 10)")


@pytest.mark.parametrize("chunked", [False, True])
def test_a_negative_normal_force_is_refused_with_its_contact_and_snapshot(chunked):
    ds = _four_snapshots()
    fn = ds["fn"].values.copy()
    fn[2, 5], fn[3, 1] = -50.0, -1e-3
    ds["fn"] = (ds.fn.dims, fn)
    i, j = int(ds.i[2, 5]), int(ds.j[2, 5])
    found = _problems(ds.chunk(time=1) if chunked else ds)
    assert found == [f"fn: 2 negative normal force(s) in occupied slots (first: snapshot 2, slot 5, bodies {i} and "
                     f"{j}, fn = -50 N); expected fn >= 0 (compression positive)"]
    fn[2, 5], fn[3, 1] = 0.0, 0.0  # zero: a pair in contact that carries no force
    grainview.validate(ds.assign(fn=(ds.fn.dims, fn)))
