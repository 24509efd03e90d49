"""The figures only draw: no analysis function is defined under grainview/plot/.

Every function (public or private) of a module of grainview/plot/ either returns what it drew (its numpydoc
``Returns`` names a matplotlib type: Axes, Figure, lines) or is one of the drawing helpers listed
here, each with what it is for. Anything that computes a result from a dataset belongs to a topic
module of grainview/analysis/ (and to ``ds.grain``), where the figures call it."""

import ast
import re
from pathlib import Path

from grainview.plot._docs import build_docstring

PLOT = Path(__file__).resolve().parents[2] / "grainview" / "plot"

DRAWING_HELPERS = {
    # which data a figure draws, as the figures take it
    "datasets": "one dataset, a dict or a list of pairs as (label, ds) pairs",
    "single_dataset": "the one (label, ds) of a figure that draws one sample",
    "snapshot_index": "the snapshot a map draws",
    "eps_q": "the x axis of every evolution",
    "values": "the numbers of a result, to hand to matplotlib",
    # axes, labels, legends, colours
    "get_axes": "the axes to draw on", "tidy_polar": "polar axes' ticks", "new_figure": "a figure of n panels",
    "format_units": "a unit in an axis label", "axis_label": "a symbol with its unit", "units_of": "a result's unit",
    "set_labels": "axis labels", "finish": "legend and title", "radian_ticks": "ticks in multiples of pi",
    "series_label": "a legend entry", "legend_in_first": "one legend for several panels",
    "shape_key": "the colour key of a sample's shape", "sample_colour": "a sample's colour",
    "draw_evolutions": "curves against eps_q", "same_scale": "panels sharing one y range",
    "draw_band": "a shear band's lines", "full_turn": "a polar curve closed over [0, 2 pi)",
    "map_axes": "a map's axes and frame", "contact_segments": "the contact lines of a map",
    "force_linewidths": "line widths from forces", "width_force": "the force a line width stands for",
    "newtons": "a force in words", "per_metre": "a force per metre of thickness in words",
    "contact_collection": "the contact lines drawn on a map",
    # captions and files
    "describe_figure": "a figure's caption", "sampling_note": "a caption line", "interval_note": "a caption line",
    "strain_note": "a caption line",
    "add_caption": "a caption under a figure", "save_figure": "PNG and PDF files of a figure",
    "frame_title": "a movie frame's title", "save_frames": "a movie's frames written",
    "animate": "a movie of the maps", "animate_chains": "a movie of the force chains",
    # the figures' own docstrings
    "build_docstring": "shared numpydoc entries put in place", "fill_doc": "the same, as a decorator",
}
"""The public functions of grainview/plot/ that draw, label or save without returning a
matplotlib object, and what each is for."""

PRIVATE_HELPERS = {
    "_delegate": "a figure as a method of ds.grain.plot", "_used_colours": "the colours already on the axes",
    "_chains_of": "the snapshot of chains a map draws", "_fields_of": "the snapshot of fields a map draws",
    "_names": "the field names a figure accepts", "_label": "a field's axis label",
    "_frame": "the box or cell drawn around a map", "_polar": "a polar force profile drawn",
    "_cartesian_profile": "a force profile drawn against theta", "_pdf": "the pooled pdf a figure draws",
    "_draw_pdf": "a pdf's bins drawn", "_draw_fit": "a pdf's exponential fit drawn", "_pdf_axes": "a pdf's scales",
    "_outside_note": "a panel's note of contacts out of range", "_xi": "a profile against xi drawn",
    "_angles": "phi and psi as the stress-dilatancy figure draws them (the analysis's)",
    "_partial_q_over_p": "q/p by contact kind as a figure draws it (the analysis's)",
    "_cell_of": "a periodic map's cell", "_cell_corners": "a periodic map's cell corners",
    "_cell_outline": "a periodic map's cell outline", "_cell_images": "the particle images a periodic map draws",
    "_network": "the contact network drawn on a map", "_clip_to_cell": "an artist clipped to the cell",
    "_digits": "a number in a legend", "_legend": "a map's legend", "_writer": "a movie's writer",
    "_result": "the persistence result a figure draws", "_with_particles": "a result carrying its particles",
}
"""The private functions of grainview/plot/ that return no matplotlib object, and what each is
for: a private helper is checked as a public one is, so that no analysis hides behind an
underscore."""


def _returns(func: ast.FunctionDef) -> str:
    """The first line of a function's numpydoc Returns section ('' without one), its shared
    fragments in place."""
    match = re.search(r"Returns\n-------\n(.*)", build_docstring(ast.get_docstring(func)) or "")
    return match.group(1) if match else ""


def analysis_functions(source: str) -> list:
    """The top-level functions of ``source``, public or private, that return no matplotlib object
    and are not listed helpers (:data:`DRAWING_HELPERS`, :data:`PRIVATE_HELPERS`): analysis
    that belongs to grainview/analysis/."""
    return [node.name for node in ast.parse(source).body
            if isinstance(node, ast.FunctionDef) and "matplotlib" not in _returns(node)
            and node.name not in DRAWING_HELPERS and node.name not in PRIVATE_HELPERS]


def test_the_check_sees_an_analysis_function():
    source = '''
def plot_thing(ds, ax=None):
    """Draws.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.
    """

def thing_profile(ds):
    """Computes.

    Returns
    -------
    xarray.DataArray
        The profile.
    """

def _private(ds):
    return ds

def _delegate(func):
    return func
'''
    assert analysis_functions(source) == ["thing_profile", "_private"]  # a private one too


def test_no_analysis_function_is_defined_under_plot():
    modules = sorted(PLOT.glob("*.py"))
    assert len(modules) >= 10
    found = {path.name: analysis_functions(path.read_text()) for path in modules}
    assert {name: funcs for name, funcs in found.items() if funcs} == {}


def test_every_listed_helper_is_still_there():
    """The list is of functions that exist: a helper removed or moved leaves it."""
    defined = {node.name for path in PLOT.glob("*.py") for node in ast.parse(path.read_text()).body
               if isinstance(node, ast.FunctionDef)}
    assert set(DRAWING_HELPERS) - defined == set()
    assert set(PRIVATE_HELPERS) - defined == set()
