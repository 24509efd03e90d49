"""The shared docstring fragments (grainview/analysis/_docs.py, grainview/plot/_docs.py) render
into whole numpydoc entries, indented as the placeholder was, in the functions and in ds.grain;
one ``@fill_doc`` per function renders them all, and the figures name them instead of copying."""

import ast
from pathlib import Path

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


ROOT = Path(__file__).resolve().parents[2]
FRAGMENT_USERS = ("grainview/plot", "grainview/app", "grainview/formats")
"""The folders whose docstrings name the shared entries rather than copy them (the analysis's
own modules and the contract, below the fragments' room, are not read here)."""


def repeated_decorators(source: str) -> list:
    """(line, name) of each function or class of ``source`` that carries the same decorator
    twice: one ``@fill_doc`` renders every fragment, a second hides a copy-paste."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            written = [ast.unparse(d) for d in node.decorator_list]
            if len(written) != len(set(written)):
                found.append((node.lineno, node.name))
    return found


def copied_fragments(source: str) -> list:
    """(name, fragment) of each function or class docstring of ``source`` that holds a shared
    entry of two lines or more written out instead of its ``{name}`` line."""
    shared = {name: _stripped(text) for name, text in FRAGMENTS.items() if text.count("\n") >= 1}
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)) and ast.get_docstring(node):
            doc = _stripped(ast.get_docstring(node))
            found += [(node.name, name) for name, text in shared.items() if text in doc]
    return found


def _stripped(text: str) -> str:
    return "\n".join(line.strip() for line in text.splitlines())


def _modules(folders):
    return sorted(p for folder in folders for p in (ROOT / folder).rglob("*.py") if "__pycache__" not in p.parts)


def test_the_checks_see_a_second_decorator_and_a_copied_entry():
    source = ('@fill_doc\n@fill_doc\ndef twice(ax=None):\n    """Draws.\n\n    Parameters\n    ----------\n'
              '    ax : matplotlib.axes.Axes, optional\n        The axes to draw on (default: new axes on a new '
              'figure).\n    """\n\n@fill_doc\ndef once(ax=None):\n    """Draws.\n\n    {ax}\n    """\n')
    assert repeated_decorators(source) == [(3, "twice")]
    assert copied_fragments(source) == [("twice", "ax")]


def test_no_function_carries_a_decorator_twice():
    found = {p.relative_to(ROOT).as_posix(): lines for p in _modules(("grainview", "solver", "benchmarks"))
             if (lines := repeated_decorators(p.read_text(encoding="utf-8")))}
    assert found == {}


def test_no_fragment_names_another_so_one_pass_renders_all():
    assert [name for name, text in FRAGMENTS.items() if build_docstring(text) != text] == []


def test_the_figures_and_the_application_name_the_shared_entries_instead_of_copying_them():
    found = {p.relative_to(ROOT).as_posix(): copies for p in _modules(FRAGMENT_USERS)
             if (copies := copied_fragments(p.read_text(encoding="utf-8")))}
    assert found == {}
