"""Figures of Azema, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007), drawn from any
dataset of the contract (docs/schema.md).

One pure function per figure, ``plot_<name>(data, ax=None, **kw)``, returning the matplotlib
Axes (or the Figure of a two-panel figure). ``data`` is one dataset, or several to compare on
the same axes as ``{label: ds}`` or ``[(label, ds), ...]``; a single dataset takes ``label=``
so that successive calls on the same axes build a comparison too::

    from grainview.plot import plot_q_over_p, save_figure
    ax = plot_q_over_p({"pentagons": pentagons, "disks": disks})
    save_figure(ax.figure, "out/fig03_q_over_p")        # fig03_q_over_p.png and .pdf

The same functions are methods of :class:`PlotAccessor` (``ds.grain.plot.q_over_p()``).

============  =========================================  ======================
paper figure  function                                   module
============  =========================================  ======================
3             plot_q_over_p                              macroscopic
4             plot_volumetric_strain                     macroscopic
5             plot_stress_dilatancy                      macroscopic
6a, 6b        plot_coordination, plot_persistence        texture
7             plot_connectivity_pdf                      texture
8             plot_orientation_pdf                       texture
9             plot_fabric_anisotropy                     texture
10            plot_angular_forces (normal/tangential)    forces
11            plot_force_anisotropies (a_n, a_t)         forces
12            plot_harmonic_prediction                   macroscopic
13            plot_force_chains                          maps
14            plot_force_pdfs (plot_force_pdf)           forces
15, 16        plot_xi_stress, plot_xi_anisotropies       forces
17            plot_force_classes                         maps
18            plot_partial_q_over_p                      macroscopic
19            plot_contact_proportions                   forces
20            plot_type_transitions                      forces
21            plot_joint_connectivity                    texture
22            plot_partial_fabric_anisotropy             texture
23            plot_force_pdfs_by_kind                    forces
24            plot_contact_kinds                         maps
25            plot_strong_weak_proportions               forces
============  =========================================  ======================
"""

from __future__ import annotations

import functools

import xarray as xr

from ._docs import fill_doc as _fill_doc
from ._style import save_figure
from .forces import (plot_angular_forces, plot_contact_proportions, plot_force_anisotropies,
                     plot_force_anisotropy, plot_force_pdf, plot_force_pdf_by_kind, plot_force_pdfs,
                     plot_force_pdfs_by_kind, plot_normal_force, plot_normal_force_polar,
                     plot_strong_weak_proportion, plot_strong_weak_proportions, plot_tangential_force,
                     plot_tangential_force_polar, plot_type_transitions, plot_xi_anisotropies, plot_xi_anisotropy,
                     plot_xi_stress)
from .chains import (animate_chains, plot_chain_fractions, plot_chain_lengths, plot_chain_lifetimes,
                     plot_chain_map)
from .fields import plot_field_maps, plot_field_profiles, plot_shear_band
from .topology import plot_betti_curves, plot_cycle_counts, plot_network_topology, plot_persistence_diagram
from .macroscopic import (plot_harmonic_prediction, plot_partial_q_over_p, plot_q_over_p,
                          plot_stress_dilatancy, plot_volumetric_strain)
from .movies import animate
from .maps import (plot_connectivity_map, plot_contact_kinds, plot_force_chains, plot_force_classes,
                   plot_particle_map, plot_particles, plot_rattler_map, plot_rotation_map)
from .texture import (plot_connectivity_pdf, plot_coordination, plot_fabric_anisotropy,
                      plot_joint_connectivity, plot_orientation_pdf, plot_partial_fabric_anisotropy,
                      plot_persistence)

FIGURES = {
    "02": plot_particles, "03": plot_q_over_p, "04": plot_volumetric_strain, "05": plot_stress_dilatancy,
    "06a": plot_coordination, "06b": plot_persistence, "07": plot_connectivity_pdf,
    "08": plot_orientation_pdf, "09": plot_fabric_anisotropy, "10": plot_angular_forces,
    "11": plot_force_anisotropies, "12": plot_harmonic_prediction, "13": plot_force_chains,
    "14": plot_force_pdfs, "15": plot_xi_stress, "16": plot_xi_anisotropies, "17": plot_force_classes,
    "18": plot_partial_q_over_p, "19": plot_contact_proportions, "20": plot_type_transitions,
    "21": plot_joint_connectivity, "22": plot_partial_fabric_anisotropy, "23": plot_force_pdfs_by_kind,
    "24": plot_contact_kinds, "25": plot_strong_weak_proportions,
}
"""Paper figure number -> the function drawing it. The packing (2), the maps (13, 17, 24) and
the P(m_s, m_d) map (21) draw one sample per call; the others accept several."""


def _delegate(func):
    @functools.wraps(func)
    def method(self, *args, **kwargs):
        return func(self._ds, *args, **kwargs)
    return method


@_fill_doc
class PlotAccessor:
    """The figures of one dataset: ``ds.grain.plot.q_over_p(ax=ax, label="pentagons")``
    (:attr:`grainview.accessor.GrainAccessor.plot`), or ``PlotAccessor(ds).q_over_p(...)``.

    Each method is the function ``plot_<name>`` of this package applied to the dataset;
    ``dir`` lists those methods only.

    Parameters
    ----------
    {ds_short}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Figs. 3-25 (the table of the module docstring).
    """

    def __init__(self, ds: xr.Dataset):
        self._ds = ds

    def __dir__(self):
        """The figure methods only, for ``dir`` and tab completion.

        Returns
        -------
        list of str
            The public names of the accessor, sorted.
        """
        return sorted(name for name in dir(type(self)) if not name.startswith("_"))

    # macroscopic (Figs. 3, 4, 5, 12, 18)
    q_over_p = _delegate(plot_q_over_p)
    volumetric_strain = _delegate(plot_volumetric_strain)
    stress_dilatancy = _delegate(plot_stress_dilatancy)
    harmonic_prediction = _delegate(plot_harmonic_prediction)
    partial_q_over_p = _delegate(plot_partial_q_over_p)
    # texture (Figs. 6, 7, 8, 9, 21, 22)
    coordination = _delegate(plot_coordination)
    persistence = _delegate(plot_persistence)
    connectivity_pdf = _delegate(plot_connectivity_pdf)
    orientation_pdf = _delegate(plot_orientation_pdf)
    fabric_anisotropy = _delegate(plot_fabric_anisotropy)
    joint_connectivity = _delegate(plot_joint_connectivity)
    partial_fabric_anisotropy = _delegate(plot_partial_fabric_anisotropy)
    # forces (Figs. 10, 11, 14, 15, 16, 19, 20, 23, 25)
    normal_force = _delegate(plot_normal_force)
    normal_force_polar = _delegate(plot_normal_force_polar)
    tangential_force_polar = _delegate(plot_tangential_force_polar)
    tangential_force = _delegate(plot_tangential_force)
    angular_forces = _delegate(plot_angular_forces)
    force_anisotropy = _delegate(plot_force_anisotropy)
    force_anisotropies = _delegate(plot_force_anisotropies)
    force_pdf = _delegate(plot_force_pdf)
    force_pdfs = _delegate(plot_force_pdfs)
    force_pdf_by_kind = _delegate(plot_force_pdf_by_kind)
    force_pdfs_by_kind = _delegate(plot_force_pdfs_by_kind)
    xi_stress = _delegate(plot_xi_stress)
    xi_anisotropy = _delegate(plot_xi_anisotropy)
    xi_anisotropies = _delegate(plot_xi_anisotropies)
    contact_proportions = _delegate(plot_contact_proportions)
    type_transitions = _delegate(plot_type_transitions)
    strong_weak_proportion = _delegate(plot_strong_weak_proportion)
    strong_weak_proportions = _delegate(plot_strong_weak_proportions)
    # maps (Figs. 13, 17, 24)
    particles = _delegate(plot_particles)
    force_chains = _delegate(plot_force_chains)
    force_classes = _delegate(plot_force_classes)
    contact_kinds = _delegate(plot_contact_kinds)
    # per-particle maps: connectivity, rattlers, rotation, displacement
    particle_map = _delegate(plot_particle_map)
    connectivity_map = _delegate(plot_connectivity_map)
    rattler_map = _delegate(plot_rattler_map)
    rotation_map = _delegate(plot_rotation_map)
    # force chains (Peters et al. 2005; grainview.analysis.force_chains)
    chain_map = _delegate(plot_chain_map)
    chain_fractions = _delegate(plot_chain_fractions)
    chain_lengths = _delegate(plot_chain_lengths)
    chain_lifetimes = _delegate(plot_chain_lifetimes)
    # coarse-grained fields (grainview.analysis.coarse_graining)
    field_maps = _delegate(plot_field_maps)
    field_profiles = _delegate(plot_field_profiles)
    # topology of the force network (grainview.analysis.network_topology)
    persistence_diagram = _delegate(plot_persistence_diagram)
    betti_curves = _delegate(plot_betti_curves)
    cycle_counts = _delegate(plot_cycle_counts)
    network_topology = _delegate(plot_network_topology)
    # movies
    animate = _delegate(animate)
    animate_chains = _delegate(animate_chains)


__all__ = ["PlotAccessor", "save_figure", "FIGURES", "animate", *(f.__name__ for f in FIGURES.values()),
           "plot_particles", "plot_particle_map", "plot_connectivity_map", "plot_rattler_map", "plot_rotation_map",
           "plot_normal_force_polar", "plot_tangential_force_polar", "plot_tangential_force",
           "plot_force_anisotropy", "plot_normal_force", "plot_xi_anisotropy", "plot_strong_weak_proportion",
           "plot_force_pdf", "plot_force_pdf_by_kind", "plot_chain_map", "plot_chain_fractions", "plot_chain_lengths",
           "plot_chain_lifetimes", "animate_chains", "plot_field_maps", "plot_field_profiles", "plot_shear_band",
           "plot_persistence_diagram", "plot_betti_curves", "plot_cycle_counts", "plot_network_topology"]
