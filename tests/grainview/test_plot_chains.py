"""The force-chain figures draw what grainview.analysis.force_chains computes: the chain map's colours and
links on the hand-made column, the fractions' curves, the lengths' pdf, the lifetimes, the movie."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.collections import EllipseCollection, LineCollection  # noqa: E402

from grainview.contract.errors import ParameterError  # noqa: E402
from grainview.analysis.force_chains import force_chains  # noqa: E402
from grainview.plot import PlotAccessor  # noqa: E402
from grainview.plot.chains import (animate_chains, plot_chain_fractions, plot_chain_lengths,  # noqa: E402
                                   plot_chain_lifetimes, plot_chain_map)
from grainview.analysis.strain import strains  # noqa: E402

from .test_force_chains import column_among_pairs, series  # noqa: E402


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def three():
    """Three snapshots: the column, the turned column, no chain (the column below the mean)."""
    return series(column_among_pairs(), column_among_pairs(rotation=0.4), column_among_pairs(load=0.2))


def test_the_map_colours_the_column_and_draws_its_four_links():
    ds = column_among_pairs()
    ax = plot_chain_map(ds)
    disks = [c for c in ax.collections if isinstance(c, EllipseCollection)][0]
    np.testing.assert_array_equal(disks.get_array(), [1] * 5 + [0] * 6)  # chain 0, then no chain
    links = [c for c in ax.collections if isinstance(c, LineCollection) and c.get_gid() == "chains"][0]
    segments = np.asarray(links.get_segments())
    assert segments.shape == (4, 2, 2)
    np.testing.assert_allclose(segments[:, 1] - segments[:, 0], [[0.0, 0.02]] * 4, atol=1e-15)  # along the column
    assert ax.get_xlabel() == "$x$ (m)" and ax.get_ylabel() == "$y$ (m)"
    assert "1 chains" in ax.get_title() and "45% of the particles" in ax.get_title()


def test_the_map_takes_precomputed_chains_of_the_same_dataset(three):
    chains = force_chains(three)
    ax = plot_chain_map(three, time=2, chains=chains)
    links = [c for c in ax.collections if isinstance(c, LineCollection) and c.get_gid() == "chains"][0]
    assert len(links.get_segments()) == 0
    with pytest.raises(ParameterError, match="chains has 1 snapshots, the dataset 3"):
        plot_chain_map(three, chains=chains.isel(time=[0]))


def test_the_fractions_are_the_computed_ones(three):
    ax = plot_chain_fractions(three)
    out = force_chains(three)
    np.testing.assert_allclose(ax.lines[0].get_ydata(), out.deviator_fraction.values)
    np.testing.assert_allclose(ax.lines[1].get_ydata(), out.pressure_fraction.values)
    np.testing.assert_allclose(ax.lines[2].get_ydata(), out.particle_fraction.values)
    np.testing.assert_allclose(ax.lines[0].get_xdata(), strains(three)["eps_q"].values)
    assert ax.get_xlabel() == r"$\varepsilon_q$"
    # a contribution, not a share: the legend and the axis say so, and the line at 1 is "all"
    assert ax.get_legend_handles_labels()[1][0].startswith("contribution to q")
    assert ax.get_ylabel() == "carried by the force chains (1: all)"


def test_the_lengths_pdf_and_the_lifetimes(three):
    ax = plot_chain_lengths(three, time="all")
    np.testing.assert_array_equal(ax.lines[0].get_xdata(), [5])  # two chains of 5 particles
    np.testing.assert_array_equal(ax.lines[0].get_ydata(), [1.0])
    assert ax.get_xlabel() == "chain length $L$ (particles)"
    # the column's track lives 2 snapshots but is censored (seen in the first): nothing to draw
    ax = plot_chain_lifetimes(three)
    assert not ax.lines
    five = series(*[column_among_pairs(load=0.2)] + [column_among_pairs()] * 3 + [column_among_pairs(load=0.2)])
    ax = plot_chain_lifetimes(five)
    np.testing.assert_array_equal(ax.lines[0].get_ydata()[:3], [1.0, 1.0, 1.0])  # one chain, 3 snapshots
    assert ax.get_xlabel() == "lifetime $n$ (snapshots)"


def test_the_plot_accessor_draws_them(three):
    acc = PlotAccessor(three)
    assert type(acc).chain_map.__wrapped__ is plot_chain_map
    assert type(acc).animate_chains.__wrapped__ is animate_chains


def test_the_movie_is_written_once_and_not_over_a_file(tmp_path, three):
    path = tmp_path / "chains.gif"
    assert animate_chains(three, path, progress=False) == str(path)
    assert path.read_bytes()[:6] == b"GIF89a"
    with pytest.raises(ParameterError, match="exists; pass overwrite=True"):
        animate_chains(three, path, progress=False)
    with pytest.raises(ParameterError, match=".gif or .mp4"):
        animate_chains(three, tmp_path / "chains.avi", progress=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["chains.gif"]
