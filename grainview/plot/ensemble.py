"""Figures of an ensemble: a quantity against shear strain, mean and spread over seeds."""

from __future__ import annotations

from ._docs import fill_doc
from ._style import EPS_Q_LABEL, sample_colour

__all__ = ["seed_bands"]


@fill_doc
def seed_bands(stats, ax=None, label: str = "", units: str = "1"):
    """Draw :func:`grainview.analysis.ensemble.seed_statistics` binned on eps_q: mean and spread per group.

    Per group the mean as a line and mean +- one standard deviation as a band (none where a
    bin has a single seed), the number of seeds in the legend. A group named after a shape
    ("pentagon", "disk") has that shape's colour in every figure
    (:func:`grainview.plot._style.sample_colour`), whatever order the groups come in.

    Parameters
    ----------
    stats : xarray.Dataset
        The result of :func:`grainview.analysis.ensemble.seed_statistics` with ``eps_q_bins``: ``mean``,
        ``std``, ``n`` over (group, eps_q_bin).
    {ax}
    label : str, default ""
        The quantity's symbol, the y-axis label.
    units : str, default "1"
        Its units, appended to the label unless dimensionless.

    Returns
    -------
    {returns_axes}
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(5, 3.5), constrained_layout=True)
    x = stats["eps_q_bin"].values
    for group in stats["group"].values:
        s = stats.sel(group=group)
        mean, std, n = s["mean"].values, s["std"].values, s["n"].values
        seeds = int(n.max()) if n.size else 0
        (line,) = ax.plot(x, mean, marker="o", ms=3, color=sample_colour(ax, str(group)),
                          label=f"{group} ({seeds} seeds)")
        ax.fill_between(x, mean - std, mean + std, color=line.get_color(), alpha=0.25,
                        lw=0)
    ax.set_xlabel(EPS_Q_LABEL)
    ax.set_ylabel(label if units in ("", "1", None) else f"{label} ({units})")
    ax.legend(fontsize=8, title="mean $\\pm$ std over seeds", title_fontsize=8)
    return ax
