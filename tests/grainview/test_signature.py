"""The core dimensions declared beside the array functions (grainview.analysis.arrays.signature)."""

import inspect

import numpy as np
import pytest
import xarray as xr

from grainview.analysis import arrays
from grainview.analysis._lift import apply
from grainview.analysis.arrays import connectivity, fabric, force_networks, force_pdf, forces, stress, tensors, xi_network
from grainview.analysis.arrays.signature import TENSOR, core_dims

LIFTED = [connectivity.contact_numbers, connectivity.coordination, connectivity.connectivity_pdf,
          connectivity.joint_connectivity_pdf, fabric.fabric_tensor, fabric.orientation_pdf,
          force_networks.force_classes, force_networks.proportions, force_pdf.force_histogram,
          forces.angular_averages, forces.force_tensors, stress.stress_tensor, xi_network.xi_network,
          tensors.principal]


@pytest.mark.parametrize("func", LIFTED, ids=lambda f: f"{f.__module__.split('.')[-1]}.{f.__name__}")
def test_every_lifted_function_declares_its_core_dims_for_its_leading_parameters(func):
    params = list(inspect.signature(func).parameters)
    assert 1 <= len(func.core_dims) <= len(params)
    assert len(func.output_core_dims) >= 1
    assert all(isinstance(d, tuple) for d in (*func.core_dims, *func.output_core_dims))


def test_apply_reads_the_declaration_and_fills_the_tensor_sizes():
    @core_dims(("contact",), out=(TENSOR,))
    def outer(v):
        return v[..., :2, None] * v[..., None, :2]

    v = xr.DataArray(np.arange(12.0).reshape(3, 4), dims=("time", "contact"))
    out = apply(outer, v.chunk({"time": 1}))
    assert out.dims == ("time", "xy_a", "xy_b") and list(out.xy_a.values) == ["x", "y"]
    np.testing.assert_array_equal(out.values[1], [[16.0, 20.0], [20.0, 25.0]])


def test_apply_says_when_the_arguments_do_not_match_the_declaration():
    with pytest.raises(TypeError, match="declares 1 core-dim inputs, got 2 arguments"):
        apply(arrays.tensors.principal, xr.DataArray(np.eye(2), dims=TENSOR), xr.DataArray(1.0))
