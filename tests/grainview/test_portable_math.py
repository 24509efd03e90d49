"""grainview.contract.portable_math: the C library's functions, the same bits through the small
(Python's math) and the large (numba ufunc) paths, numpy's conventions at the domain's edges."""

from __future__ import annotations

import math
import subprocess
import sys
import warnings

import numpy as np
import pytest

from grainview.contract import portable_math as pm

RNG = np.random.default_rng(7)
INPUTS = {  # name: (arguments over the domain and its edges, the scalar reference)
    "arctan2": ((RNG.normal(size=6000) * 10.0 ** RNG.integers(-3, 4, 6000), RNG.normal(size=6000)), math.atan2),
    "arcsin": ((RNG.uniform(-1, 1, 6000),), math.asin),
    "exp": ((RNG.uniform(-700, 700, 6000),), math.exp),
    "expm1": ((RNG.uniform(-1e-3, 1e-3, 6000),), math.expm1),
    "log": ((10.0 ** RNG.uniform(-300, 300, 6000),), math.log),
    "log1p": ((RNG.uniform(-0.999, 1e3, 6000),), math.log1p),
}


@pytest.mark.parametrize("name", sorted(INPUTS))
def test_both_paths_give_the_c_librarys_bits(name):
    args, scalar = INPUTS[name]
    expected = np.array([scalar(*values) for values in zip(*args)])
    large = getattr(pm, name)(*args)  # 6000 > SMALL: the compiled loop
    small = np.concatenate([getattr(pm, name)(*[a[k:k + 1000] for a in args]) for k in range(0, 6000, 1000)])
    assert 6000 > pm.SMALL >= 1000
    assert large.tobytes() == expected.tobytes()
    assert small.tobytes() == expected.tobytes()


@pytest.mark.parametrize("name", sorted(INPUTS))
def test_within_two_ulp_of_numpy(name):
    """Another implementation (numpy's, whichever this processor picks) agrees to rounding."""
    args, _ = INPUTS[name]
    np.testing.assert_array_max_ulp(getattr(pm, name)(*args), getattr(np, name)(*args), maxulp=2)


def test_domain_edges_follow_numpy():
    with np.errstate(all="ignore"):
        for size in (3, pm.SMALL + 1):  # both paths
            zeros = np.zeros(size)
            assert np.all(pm.log(zeros) == -np.inf) and np.all(np.isnan(pm.log(zeros - 1)))
            assert np.all(pm.log1p(zeros - 1) == -np.inf) and np.all(np.isnan(pm.log1p(zeros - 2)))
            assert np.all(np.isnan(pm.arcsin(zeros + 1.5)))
            assert np.all(pm.exp(zeros + 1e3) == np.inf) and np.all(pm.expm1(zeros + 1e3) == np.inf)
            assert np.all(pm.exp(zeros - np.inf) == 0) and np.all(np.isnan(pm.exp(zeros + np.nan)))
            assert np.all(pm.arctan2(zeros, zeros - 1) == np.pi)
    assert pm.arctan2(1.0, 0.0) == math.pi / 2 and isinstance(pm.exp(0.5), np.floating)


def test_floating_point_warnings_as_numpy_says():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        pm.log(np.array([0.0, -1.0]))
    assert sorted(str(w.message) for w in caught) == ["divide by zero encountered in log",
                                                      "invalid value encountered in log"]
    with np.errstate(over="raise"), pytest.raises(FloatingPointError, match="overflow encountered in exp"):
        pm.exp(np.array([1e3]))
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("error")
        pm.log(np.array([0.0, -1.0]))
        pm.log(np.array([np.nan, np.inf]))  # nan and inf in: no condition met


def test_dataarrays_keep_coordinates_and_dask_stays_lazy():
    xr = pytest.importorskip("xarray")
    a = xr.DataArray([0.5, 1.0, 2.0], dims="time", coords={"time": [0.0, 1.0, 2.0]}, name="v")
    out = pm.log(a)
    assert isinstance(out, xr.DataArray) and out.time.values.tolist() == [0.0, 1.0, 2.0]
    assert out.values.tolist() == [math.log(0.5), 0.0, math.log(2.0)]
    lazy = pm.log(a.chunk(2))
    assert type(lazy.data).__module__.startswith("dask") and lazy.values.tolist() == out.values.tolist()


def test_small_inputs_load_no_compiler():
    code = ("import sys, numpy as np; from grainview.contract import portable_math as pm; "
            "pm.arctan2(np.ones(100), np.ones(100)); pm.log(2.0); print('numba' in sys.modules)")
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip() == "False"
