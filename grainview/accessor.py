"""The ``ds.grain`` accessor: holds the dataset and delegates to the topic modules.

Every method calls the function of the same name in a topic module (:mod:`grainview.stress`,
:mod:`grainview.fabric`, ...), where the docstring with the formula and the paper reference
lives; the accessor shows that docstring too. Nothing is computed here.
"""

from __future__ import annotations

import functools

import xarray as xr

from . import connectivity, fabric, force_networks, forces, sample, strain, stress, validation
from . import force_pdf as _force_pdf
from . import persistence as _persistence
from . import xi_network as _xi_network


def _delegate(func):
    @functools.wraps(func)
    def method(self, *args, **kwargs):
        self._check_structure()
        return func(self._ds, *args, **kwargs)
    return method


@xr.register_dataset_accessor("grain")
class GrainAccessor:
    """Analyses of a packing dataset of the grainview contract: ``ds.grain.<name>(...)``."""

    def __init__(self, ds: xr.Dataset):
        self._ds = ds
        self._structure_ok = False

    def _check_structure(self):
        """Structural check (no data read) before any analysis, so that a malformed dataset
        gives a :class:`~grainview.errors.SchemaError` naming the problem, not a KeyError."""
        if not self._structure_ok:
            validation.check_structure(self._ds)
            self._structure_ok = True

    def validate(self):
        """Check the dataset against the contract (:func:`grainview.validation.validate`)."""
        return validation.validate(self._ds)

    # stress and strain
    stress_tensor = _delegate(stress.stress_tensor)
    stress_invariants = _delegate(stress.stress_invariants)
    strains = _delegate(strain.strains)
    friction_and_dilatancy = _delegate(strain.friction_and_dilatancy)
    inertia_number = _delegate(strain.inertia_number)
    solid_fraction = _delegate(sample.solid_fraction)
    # texture
    fabric_tensor = _delegate(fabric.fabric_tensor)
    fabric_anisotropy = _delegate(fabric.fabric_anisotropy)
    orientation_pdf = _delegate(fabric.orientation_pdf)
    contact_numbers = _delegate(connectivity.contact_numbers)
    coordination = _delegate(connectivity.coordination)
    connectivity_pdf = _delegate(connectivity.connectivity_pdf)
    joint_connectivity_pdf = _delegate(connectivity.joint_connectivity_pdf)
    # forces
    angular_force_averages = _delegate(forces.angular_force_averages)
    force_tensors = _delegate(forces.force_tensors)
    force_anisotropies = _delegate(forces.force_anisotropies)
    harmonic_prediction = _delegate(forces.harmonic_prediction)
    force_pdf = _delegate(_force_pdf.force_pdf)
    pooled_force_pdf = _delegate(_force_pdf.pooled_force_pdf)
    force_class = _delegate(force_networks.force_class)
    contact_proportions = _delegate(force_networks.contact_proportions)
    xi_network = _delegate(_xi_network.xi_network)
    # contact history (these compute, one time-chunk at a time)
    persistence = _delegate(_persistence.persistence)
    type_transitions = _delegate(_persistence.type_transitions)

    @property
    def plot(self):
        """The paper's figures drawn from this dataset: ``ds.grain.plot.<name>(...)``
        (:mod:`grainview.plot`; matplotlib is imported on first use)."""
        from .plot import PlotAccessor

        return PlotAccessor(self._ds)
