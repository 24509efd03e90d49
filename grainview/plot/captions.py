"""What each figure of the report plots, in one sentence, and the notes some figures need
beside their samples' provenance: how independent the pooled snapshots of a distribution are
(Fig. 8), and the snapshot interval that transition counts depend on (Fig. 20).

The report (:func:`grainview.app.report.write_figures`) puts :func:`describe_figure`'s sentence
first in every caption, then one provenance line per sample, then the notes.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ..analysis.strain import RESIDUAL_STRAIN

DESCRIPTIONS = {
    "02": "The packing at the end of the isotropic compaction (the first snapshot), particles to scale in the box",
    "03": "Shear stress ratio q/p = (sigma_1 - sigma_2)/(sigma_1 + sigma_2) against the shear strain "
          "eps_q = eps_1 - eps_2 since the first snapshot (the paper's cumulative shear strain: the sum of signed "
          "increments, so it decreases where the sample narrows faster than it shortens)",
    "04": "Cumulative volumetric strain eps_p (dilation positive) against eps_q",
    "05": "Stress-dilatancy diagram: dilatancy angle psi (sin psi = eps_p/eps_q) against friction angle phi "
          "(sin phi = q/p), one point per snapshot with eps_q >= 0.02; dotted: guides of slope 1 through phi_0, "
          "the median of phi - psi (not fits)",
    "06a": "Coordination number z of the force-bearing network (rattlers left out, a double contact counted once) "
           "against eps_q",
    "06b": "Share gamma of the first snapshot's force-bearing contacts present at each snapshot (not necessarily "
           "without interruption) against eps_q",
    "07": "P(c): share of the particles (rattlers left out) with exactly c force-bearing contacts, averaged over "
          "the residual state",
    "08": "P(theta): probability density of the directions theta of the contact normals (rad^-1), contacts pooled "
          "over the residual state; polar plot over the full turn",
    "09": "Fabric anisotropy a' (signed: > 0 along the major principal stress) against eps_q",
    "10": "Mean normal force <f_n>(theta) (a) and mean tangential force <f_t>(theta) with its sign (b) of the "
          "contacts of direction theta, both divided by the mean normal force <f_n>, residual state; both panels "
          "on one y scale (the paper draws polar plots)",
    "11": "Force anisotropies a_n (a) and a_t (b), signed against the major principal stress, against eps_q",
    "12": "q/p (wide pale band) and its harmonic predictions (a' + a_n + a_t)/2 (dashed) and "
          "(a' + a_n + a_t)/(2 + a' a_n) (thin solid) against eps_q; the legend gives each curve's mean over the "
          "residual state",
    "13": "Normal-force network of one snapshot: each force-bearing contact between particles a segment joining "
          "their centres, of width proportional to f_n (forces per m of thickness)",
    "14": "Probability density P of the normal forces f_n/<f_n>, contacts pooled over the residual state: (a) "
          "log-linear, with an exponential fit of the strong forces (f_n > <f_n>), (b) log-log; bars: counting "
          "errors",
    "15": "Shear stress q(xi)/p carried by the contacts with f_n < xi <f_n>, against the cutoff xi, residual "
          "state (dotted: xi = 1, the mean force)",
    "16": "Fabric anisotropy a'(xi) of the contacts with f_n < xi <f_n>, against the cutoff xi, residual state: "
          "(a) every cutoff, (b) the weak forces on a logarithmic axis (the paper's inset)",
    "17": "Force classes of one snapshot: very weak, weak and strong contacts between particles (thresholds in "
          "the legend)",
    "18": "Shear stress of the simple contacts (q_s/p), of the double contacts (q_d/p) and of all contacts (q/p) "
          "against eps_q, each divided by the p of the whole sample",
    "19": "Shares of simple and double contacts, k_s and k_d (solid), and their shares of the normal force, "
          "f_s and f_d (dashed), against eps_q",
    "20": "Cumulative shares Delta gamma of the contacts that turned from simple to double (s->d) and from double "
          "to simple (d->s) between successive snapshots, against eps_q",
    "21": "P(m_s, m_d): share of the particles (rattlers left out) with m_s simple and m_d double contacts, "
          "averaged over the residual state",
    "22": "Fabric anisotropies a'_s and a'_d of the simple and double contacts (partial fabric tensors normalised "
          "by the number of all contacts) against eps_q",
    "23": "Probability density of f_n/<f_n> for the simple and for the double contacts, each normalised over its "
          "own kind, <f_n> the mean over all contacts, residual state: (a) log-linear, (b) log-log",
    "24": "Normal-force network of one snapshot by contact kind, simple and double, of width proportional to f_n "
          "(forces per m of thickness)",
    "25": "Shares of all contacts that are strong, f_n > <f_n> (a), and weak, f_n <= <f_n> (b), for the simple "
          "(k_s) and the double (k_d) contacts, against eps_q",
}
"""Paper figure number -> what the report's figure plots, the first line of its caption (no
final full stop: the report's index joins a caption's lines with semicolons)."""


STRAIN_FIGURES = ("03", "04", "06a", "06b", "09", "11", "12", "18", "19", "20", "22", "25")
"""The report's figures drawn against eps_q: their captions carry :func:`strain_note`."""


def describe_figure(number: str) -> str:
    """What figure ``number`` ("03", "06a", ...) of the report plots, in one sentence.

    Parameters
    ----------
    number : str
        A key of :data:`grainview.plot.FIGURES`.

    Returns
    -------
    str
        The sentence of :data:`DESCRIPTIONS` (empty for an unknown number).
    """
    return DESCRIPTIONS.get(number, "")


def sampling_note(label: str, ds: xr.Dataset, residual_strain: float = RESIDUAL_STRAIN) -> str:
    """A caption line saying how independent the residual snapshots pooled by a distribution
    are (:func:`grainview.analysis.persistence.pooled_contacts`): contacts last over many snapshots, so pooling T snapshots
    does not average T independent configurations, and the spikes of a finely binned
    distribution (Fig. 8) are those of a few long-lived contacts counted T times.

    Parameters
    ----------
    label : str
        The sample's label.
    ds : xarray.Dataset
        The sample's dataset.
    residual_strain : float, default 0.3
        Where the residual state starts (eps_q).

    Returns
    -------
    str
        The caption line.
    """
    from ..analysis.persistence import pooled_contacts
    from ..analysis.snapshots import residual_snapshots

    res = residual_snapshots(ds, residual_strain)
    distinct, per_snapshot = pooled_contacts(res)
    worth = distinct / per_snapshot if per_snapshot > 0 else float("nan")
    return (f"{label}: the {res.sizes['time']} snapshots pooled hold only {distinct} different contacts "
            f"({worth:.1f} times the {per_snapshot:.0f} of one): contacts last over many snapshots, so the spikes "
            "of P(theta) are a few long-lived contacts counted in every snapshot, not a texture of the packing")


def strain_note(label: str, ds: xr.Dataset) -> str:
    """A caption line for a figure drawn against eps_q, when eps_q decreases somewhere.

    eps_q = eps_1 - eps_2 is the paper's shear strain, the net strain since the first snapshot
    (its signed increments summed), not a path length: it decreases where the sample narrows
    faster than it shortens, and a curve against it folds back there. The line says how many
    times it decreases from a snapshot to the next and names the largest fall, from the largest
    eps_q reached before it.

    Parameters
    ----------
    label : str
        The sample's label.
    ds : xarray.Dataset
        The sample's dataset.

    Returns
    -------
    str
        The caption line, or "" when eps_q never decreases.
    """
    from ._style import eps_q

    strain = eps_q(ds)
    strain = strain[np.isfinite(strain)]
    if strain.size < 2:
        return ""
    reached = np.maximum.accumulate(strain)
    fall = reached - strain
    k = int(np.argmax(fall))
    if not fall[k] > 0:
        return ""
    steps = int(np.count_nonzero(np.diff(strain) < 0))
    where = "from one snapshot to the next" if steps == 1 else f"between {steps} pairs of successive snapshots"
    return (f"{label}: eps_q decreases {where}, most from {reached[k]:.4f} to {strain[k]:.4f} (the sample narrowed "
            "faster than it shortened; eps_q is the net shear strain, not a path length), so curves against eps_q "
            "fold back there")


def interval_note(label: str, ds: xr.Dataset) -> str:
    """A caption line giving the interval between successive snapshots, on which the
    cumulative transition shares of Fig. 20 depend: a change of type and back between two
    snapshots is not seen, so a longer interval counts fewer transitions.

    Parameters
    ----------
    label : str
        The sample's label.
    ds : xarray.Dataset
        The sample's dataset.

    Returns
    -------
    str
        The caption line: the median interval in s, in time steps when the file says, and in eps_q.
    """
    from ._style import eps_q

    time = np.asarray(ds["time"].values, float)
    if time.size < 2:
        return f"{label}: one snapshot, no interval"
    dt = float(np.median(np.diff(time)))
    d_eps = float(np.median(np.diff(eps_q(ds))))
    every = ds.attrs.get("snapshot_every")
    steps = f" ({int(every)} time steps)" if every is not None else ""
    return (f"{label}: snapshots every {dt:.3g} s{steps}, d eps_q = {d_eps:.2g}; Delta gamma counts the changes "
            "seen from one snapshot to the next, so a change and its reversal within one interval are not "
            "counted and Delta gamma depends on the interval")


__all__ = ["DESCRIPTIONS", "describe_figure", "sampling_note", "interval_note"]
