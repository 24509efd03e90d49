"""Malformed datasets and files, drawn by hypothesis: each gives the project's own error,
naming the variable, from open_dataset, validate and the accessors; files are never modified."""

import hashlib

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

import grainview
from grainview.contract.errors import FileFormatError, GrainviewError, SchemaError
from grainview.contract.dataset import netcdf_encoding
from grainview.contract.schema import VARIABLES

from . import builders

BASE = builders.mixed_contacts(t=2)
FLOAT_VARS = [n for n, v in VARIABLES.items() if v.required and not v.is_integer]
OPTIONAL = {"velocity": np.zeros((2, 12, 2)), "angular_velocity": np.zeros((2, 12)),
            "kinetic_energy": np.zeros(2)}


def _broken(action, name, value):
    ds = BASE.copy(deep=True).assign({k: (VARIABLES[k].dims, v) for k, v in OPTIONAL.items()})
    if action == "drop":
        return ds.drop_vars(name)
    if action == "dtype":
        var = VARIABLES[name]
        return ds.assign({name: ds[name].astype("f8" if var.is_integer else "i4")}) if var.is_integer or name != "time" else ds
    if action == "shuffle":
        dims = ds[name].dims
        return ds.assign({name: ds[name].transpose(*reversed(dims))}) if len(dims) > 1 else ds.drop_vars(name)
    # a bad value in an occupied slot / any entry
    arr = ds[name].values.copy()
    index = (0,) * arr.ndim
    arr[index] = value
    return ds.assign({name: (ds[name].dims, arr, ds[name].attrs)})


def _sha(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


actions = st.one_of(
    st.tuples(st.just("drop"), st.sampled_from([n for n, v in VARIABLES.items() if v.required]), st.just(0)),
    st.tuples(st.just("dtype"), st.sampled_from(["i", "j", "kind", "contact_count", "fn", "radius"]), st.just(0)),
    st.tuples(st.just("shuffle"), st.sampled_from(["normal", "position", "fn", "branch"]), st.just(0)),
    st.tuples(st.just("value"), st.sampled_from(FLOAT_VARS + list(OPTIONAL)), st.sampled_from([np.nan, np.inf, -np.inf])),
)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(case=actions)
def test_malformed_datasets_name_the_problem(tmp_path, case):
    action, name, value = case
    ds = _broken(action, name, value)
    with pytest.raises(SchemaError) as info:
        grainview.validate(ds)
    assert name in str(info.value) or (name in ("box_min", "box_max") and "box" in str(info.value))
    if action != "value":  # structural problems stop every analysis before it computes
        with pytest.raises(SchemaError):
            ds.grain.stress_tensor()
    path = tmp_path / f"{action}_{name}.nc"
    if path.exists():
        path.unlink()
    ds.to_netcdf(path, encoding=netcdf_encoding(ds), format="NETCDF3_64BIT")
    before = _sha(path)
    with pytest.raises(GrainviewError):
        grainview.open_dataset(path, validate=True)
    assert _sha(path) == before


def test_accessor_on_missing_variable_is_a_schema_error_not_a_key_error():
    with pytest.raises(SchemaError, match="'fn' is missing"):
        BASE.drop_vars("fn").grain.coordination()


def test_empty_file_and_directory(tmp_path):
    empty = tmp_path / "empty.nc"
    empty.write_bytes(b"")
    with pytest.raises(FileFormatError):
        grainview.open_dataset(empty)
    with pytest.raises(FileFormatError):
        grainview.open_dataset(tmp_path)
