"""The ``ds.grain`` accessor: holds the dataset and delegates to the topic modules.

Every method calls the function of the same name in a topic module (:mod:`grainview.analysis.stress`,
:mod:`grainview.analysis.fabric`, ...), where the docstring with the formula and the paper reference
lives; the accessor shows that docstring too. Nothing is computed here.
"""

from __future__ import annotations

import functools
import importlib

import xarray as xr


class _Delegate:
    """An accessor method that calls the function of the same name in topic module
    ``grainview.analysis.<module>`` on the accessor's dataset, with that function's docstring and
    signature. The topic module is imported on first use, so registering the accessor (which
    happens whenever xarray is imported after grainview) loads no analysis code."""

    def __init__(self, module: str):
        self.module = module

    def __set_name__(self, owner, name):
        self.name = name

    def function(self):
        return getattr(importlib.import_module(f"grainview.analysis.{self.module}"), self.name)

    def __get__(self, accessor, owner=None):
        func = self.function()
        if accessor is None:
            return func

        @functools.wraps(func)
        def method(*args, **kwargs):
            if "run" in accessor._ds.dims:  # an ensemble: the analysis of each run, along run
                from .analysis.ensemble import map_runs

                return map_runs(accessor._ds, lambda one: getattr(one.grain, self.name)(*args, **kwargs))
            accessor._check_structure()
            return accessor._with_strains(func(accessor._ds, *args, **kwargs))
        return method


@xr.register_dataset_accessor("grain")
class GrainAccessor:
    """Analyses of a packing dataset of the grainview contract: ``ds.grain.<name>(...)``.

    Each analysis method calls the function of the same name in a topic module, whose
    docstring it shows; on an ensemble (a ``run`` dimension) it runs per run
    (:func:`grainview.analysis.ensemble.map_runs`). Time series come back with the strains
    ``eps_1``, ``eps_p`` and ``eps_q`` as coordinates along ``time`` (when the file has its
    box). ``dir(ds.grain)`` lists the analyses, ``validate`` and ``plot``, nothing internal.

    Parameters
    ----------
    ds : xarray.Dataset
        A dataset of the contract (docs/schema.md), or an ensemble of
        :func:`grainview.analysis.ensemble.open_ensemble`.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    the descriptors of Secs. III-VI; docs/analysis.md.
    """

    def __init__(self, ds: xr.Dataset):
        self._ds = ds
        self._structure_ok = False
        self._strains = None  # the strain coordinates, built once per dataset (see _with_strains)

    def _check_structure(self):
        """Structural check (no data read) before any analysis, so that a malformed dataset
        gives a :class:`~grainview.contract.errors.SchemaError` naming the problem, not a KeyError."""
        if not self._structure_ok:
            from .contract.validation import check_structure

            check_structure(self._ds)
            self._structure_ok = True

    _STRAIN_COORDS = ("eps_1", "eps_p", "eps_q")
    """Strains attached to every time series the accessor returns, as non-index coordinates
    along ``time``, so that ``result.plot(x="eps_q")`` and ``result.swap_dims(time="eps_q")``
    need no merge."""

    def _with_strains(self, result):
        """``result`` with :data:`_STRAIN_COORDS` as coordinates along ``time`` when it is a time
        series of this dataset (and does not hold strains itself)."""
        ds = self._ds
        if (not isinstance(result, (xr.Dataset, xr.DataArray)) or result.sizes.get("time") != ds.sizes.get("time")
                or any(name in result.coords or name in getattr(result, "data_vars", {})
                       or name == getattr(result, "name", None) for name in self._STRAIN_COORDS)
                or not {"box_min", "box_max"} <= set(ds.variables)):
            return result
        if self._strains is None:
            from .analysis.strain import strains

            eps = strains(ds)
            self._strains = {name: eps[name] for name in self._STRAIN_COORDS}
        return result.assign_coords(self._strains)

    def __dir__(self):
        """The user-facing names only (the analyses, ``validate`` and ``plot``), for ``dir`` and
        tab completion.

        Returns
        -------
        list of str
            The public names of the accessor, sorted.
        """
        return sorted(name for name in dir(type(self)) if not name.startswith("_"))

    def validate(self):
        """Check the dataset against the contract (:func:`grainview.contract.validation.validate`).

        On an ensemble (a ``run`` dimension) each run is checked as its file opens alone
        (:func:`grainview.analysis.ensemble.run_dataset`).

        Returns
        -------
        xarray.Dataset
            The dataset unchanged, so that calls can be chained.

        Raises
        ------
        grainview.contract.errors.SchemaError
            Listing every problem found (docs/schema.md).
        """
        from .contract.validation import validate

        if "run" in self._ds.dims:  # an ensemble: each run
            from .analysis.ensemble import run_dataset

            for k in range(self._ds.sizes["run"]):
                validate(run_dataset(self._ds, k))
            return self._ds
        return validate(self._ds)

    # stress and strain
    stress_tensor = _Delegate("stress")
    stress_invariants = _Delegate("stress")
    strains = _Delegate("strain")
    deformation_gradient = _Delegate("strain")
    friction_and_dilatancy = _Delegate("strain")
    friction_offset = _Delegate("strain")
    inertia_number = _Delegate("strain")
    solid_fraction = _Delegate("sample")
    # texture
    fabric_tensor = _Delegate("fabric")
    fabric_anisotropy = _Delegate("fabric")
    orientation_pdf = _Delegate("fabric")
    contact_numbers = _Delegate("connectivity")
    coordination = _Delegate("connectivity")
    connectivity_pdf = _Delegate("connectivity")
    joint_connectivity_pdf = _Delegate("connectivity")
    particle_fields = _Delegate("particle_fields")
    # forces
    angular_force_averages = _Delegate("forces")
    angular_profile = _Delegate("forces")
    force_tensors = _Delegate("forces")
    force_anisotropies = _Delegate("forces")
    harmonic_prediction = _Delegate("forces")
    force_pdf = _Delegate("force_pdf")
    pooled_force_pdf = _Delegate("force_pdf")
    force_class = _Delegate("force_networks")
    contact_proportions = _Delegate("force_networks")
    xi_network = _Delegate("xi_network")
    xi_profile = _Delegate("xi_network")
    network_persistence = _Delegate("network_topology")
    force_chains = _Delegate("force_chains")
    chain_length_pdf = _Delegate("force_chains")
    chain_survival = _Delegate("force_chains")
    # contact history (these compute, one time-chunk at a time)
    persistence = _Delegate("persistence")
    type_transitions = _Delegate("persistence")
    pooled_contacts = _Delegate("persistence")
    contact_events = _Delegate("lifetimes")
    lifetime_survival = _Delegate("lifetimes")
    median_lifetime_by_force = _Delegate("lifetimes")
    strong_persistence = _Delegate("lifetimes")
    # one snapshot in other tools' forms
    contacts_table = _Delegate("tables")
    contact_graph = _Delegate("tables")
    # continuum fields
    coarse_grained = _Delegate("coarse_graining")

    @property
    def plot(self):
        """The paper's figures drawn from this dataset: ``ds.grain.plot.<name>(...)``.

        :mod:`grainview.plot`; matplotlib is imported on first use.

        Returns
        -------
        grainview.plot.PlotAccessor
            The figures of this dataset, one method per figure function ``plot_<name>``.

        Raises
        ------
        grainview.contract.errors.ParameterError
            On an ensemble: plot ``run_dataset(ens, k)`` (or a dict of them), or write the
            ensemble's report.

        References
        ----------
        Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
        Figs. 3-25 (the table in :mod:`grainview.plot`).
        """
        if "run" in self._ds.dims:
            from .contract.errors import ParameterError

            raise ParameterError("the figures draw runs, not an ensemble: plot run_dataset(ens, k) (or a dict of "
                                 "them), or write the ensemble's report (grainview.app.ensemble_report)")
        from .plot import PlotAccessor

        return PlotAccessor(self._ds)
