"""The shared docstring fragments (grainview/analysis/_docs.py, grainview/plot/_docs.py) render
into whole numpydoc entries, indented as the placeholder was, in the functions and in ds.grain."""

import pytest

from grainview.plot import plot_force_pdf
from grainview.plot._docs import FRAGMENTS, build_docstring, fill_doc


def test_a_rendered_figure_docstring_reads_whole():
    doc = plot_force_pdf.__doc__
    assert "{" + "data}" not in doc and "{" + "walls}" not in doc
    assert """
    Parameters
    ----------
    data : xarray.Dataset, dict or list
        One dataset of the contract, or several to compare on the same axes as ``{label: ds}``
        or ``[(label, ds), ...]``.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default: new axes on a new figure).
    label : str, optional
        Legend label of a single dataset (None: no legend entry), so that successive calls on
        the same axes build a comparison.
    scale : {"log-linear", "log-log"}, default "log-linear"
""" in doc
    assert """
    walls : bool, default False
        Include the particle–wall contacts (default: particle–particle only).
    fit : bool, default True
""" in doc
    assert """
    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.
""" in doc


def test_placeholders_take_their_indentation_and_only_whole_lines():
    @fill_doc
    def f():
        """Draws.

        Parameters
        ----------
        {walls}
        bins : int
            Not a fragment: {walls} inside a line stays as written.
        """

    assert f.__doc__ == """Draws.

        Parameters
        ----------
        walls : bool, default False
            Include the particle–wall contacts (default: particle–particle only).
        bins : int
            Not a fragment: {walls} inside a line stays as written.
        """
    assert build_docstring(None) is None
    assert all(not text.startswith(" ") for text in FRAGMENTS.values())


def test_an_unknown_fragment_is_an_error():
    with pytest.raises(KeyError, match="docstring fragment {wals}"):
        build_docstring("Draws.\n\n    {wals}\n")


def test_the_analysis_entries_render_in_the_function_and_in_the_accessor():
    import xarray as xr

    from grainview.analysis import _docs
    from grainview.analysis.force_pdf import pooled_force_pdf

    near = """
    near : float, optional
        Which pairs are contacts (:func:`grainview.analysis.contacts.in_network`): None (default) the
        force-bearing ones, f_n > 0; a gap threshold in m adds the pairs with gap <= ``near``
        (they carry f_n = 0); ``np.inf`` every pair the file holds.
"""
    ds = """
    ds : xarray.Dataset
        A dataset of the contract (docs/schema.md), eager or chunked along ``time``.
"""
    assert near in pooled_force_pdf.__doc__ and ds in pooled_force_pdf.__doc__
    assert xr.Dataset.grain.pooled_force_pdf.__doc__ == pooled_force_pdf.__doc__
    assert "{" + "near}" not in pooled_force_pdf.__doc__
    assert set(_docs.FRAGMENTS) <= set(FRAGMENTS)  # the figures use the analysis's entries too
