"""The readers' registry: one :class:`Reader` record per code whose output grainview reads.

Everything that offers a reader comes from its record: ``grainview convert NAME`` (its help,
description and own arguments, :class:`Argument`), ``grainview.open_dataset(path,
format=NAME)`` and ``xr.open_dataset(path, engine=NAME)`` (the xarray backend, registered in
pyproject.toml's ``xarray.backends`` entry points), and docs/formats.md's table of readers
(tests/grainview/test_reader_registry.py keeps them agreeing).

Adding a reader is one module and one entry: the module holds ``open_NAME(path, ...)`` (an
in-memory dataset of the contract), ``convert_NAME(out, path, ..., overwrite, compress,
progress)`` (a file written as it reads) and its xarray backend; the entry is one record in
:data:`READERS`. A package outside grainview gives its reader one ``xarray.backends`` entry
point: a backend class with a ``reader`` attribute holding its :class:`Reader`
(:class:`grainview.formats.backends.ReaderBackend` does the opening), found by
:func:`readers`.

Loading this module imports neither xarray nor a reader.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass, field

__all__ = ["Argument", "Backend", "Convert", "Reader", "READERS", "readers", "reader", "load"]


def load(target: str):
    """The object a ``"module:attribute"`` string names."""
    module, _, attribute = target.partition(":")
    return getattr(importlib.import_module(module), attribute)


@dataclass(frozen=True)
class Argument:
    """One argument of a reader's ``convert`` subcommand, before the options every reader has.

    Parameters
    ----------
    flags : tuple of str
        argparse's names: ``("run",)`` for a positional argument, ``("--x-period",)``.
    settings : dict
        argparse's ``add_argument`` keywords (``help``, ``required``, ``type``, ``default``...).
    keyword : str, optional
        The conversion function's parameter that takes the value (default: argparse's ``dest``).
    parse : str, optional
        ``"module:function"`` applied to the value before the conversion (a
        :class:`~grainview.contract.errors.GrainviewError` for a value it cannot read); None
        passes it on as parsed.
    default_from : str, optional
        ``"module:function"`` whose ``keyword`` parameter's default is the argument's default
        (``"{:g}"`` in the help then shows it).
    """

    flags: tuple
    settings: dict = field(default_factory=dict)
    keyword: str | None = None
    parse: str | None = None
    default_from: str | None = None

    @property
    def dest(self) -> str:
        """argparse's name for the value."""
        return self.settings.get("dest") or self.flags[0].lstrip("-").replace("-", "_")


@dataclass(frozen=True)
class Convert:
    """What ``grainview convert NAME`` offers and calls.

    Parameters
    ----------
    function : str
        ``"module:function"`` of the conversion: ``function(out, **arguments, overwrite=,
        compress=[, progress=])`` returns the snapshots written.
    help, description : str
        The subcommand's line in ``grainview convert --help`` and its own description.
    arguments : tuple of Argument
        The reader's own arguments, in the order ``--help`` lists them.
    fixed : dict
        Keywords always passed to ``function`` (a peer engine's name).
    progress : bool
        Whether the subcommand has ``--progress`` (the function a ``progress`` keyword).
    notes : bool
        Whether the reader's warnings are printed as ``note:`` lines after the conversion
        (every one, repeated ones too), rather than as they come.
    written : str
        What the final line counts: "snapshots from LAMMPS".
    """

    function: str
    help: str
    description: str
    arguments: tuple = ()
    fixed: dict = field(default_factory=dict)
    progress: bool = True
    notes: bool = False
    written: str = "snapshots"


@dataclass(frozen=True)
class Backend:
    """What ``xr.open_dataset(path, engine=NAME, **options)`` offers
    (:class:`grainview.formats.backends.ReaderBackend`).

    Parameters
    ----------
    target : str
        ``"module:Class"`` of the backend: the ``xarray.backends`` entry point.
    options : tuple of str
        The opener's keywords that the backend passes on (xarray's ``open_dataset_parameters``
        after the path and ``drop_variables``).
    description, url : str
        xarray's line for the backend, and the code's home.
    needs : dict
        Option -> what is said (after "engine='NAME' needs ") when it is not given.
    """

    target: str
    options: tuple
    description: str
    url: str = ""
    needs: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Reader:
    """One reader of another code's output.

    Parameters
    ----------
    name : str
        The format's name: ``convert NAME``, ``format=NAME``, ``engine=NAME``.
    opener : str
        ``"module:function"``: ``function(path, **options)`` returns the in-memory dataset.
    backend : Backend
        Its xarray backend (the ``xarray.backends`` entry point).
    convert : Convert
        Its ``convert`` subcommand.
    """

    name: str
    opener: str
    backend: Backend
    convert: Convert


def _peer(name: str, version: str, backend: str, description: str) -> Reader:
    """A peer engine of the cross-check (``benchmarks/crosscheck``): its raw snapshots."""
    return Reader(name, f"grainview.formats.peers:open_{name}", Backend(
        f"grainview.formats.backends:{backend}", ("sample",),
        f"{description} runs of grainview's cross-check (raw snapshots) as a grainview dataset",
        needs={"sample": "sample=<the cross-check sample's .npz>"}), Convert(
        "grainview.formats.peers:convert_peer", f"a {version} run of the cross-check (raw snapshots)",
        f"A {version} run of the cross-check harness (benchmarks/crosscheck/): the engine's folder of raw snapshots "
        "(snap_*.npz, meta.json) and the sample it started from (docs/formats.md).",
        (Argument(("raw",), {"help": "the engine's folder of raw snapshots"}, keyword="raw_dir"),
         Argument(("--sample",), {"required": True, "help": "the cross-check sample's .npz the engine started from"})),
        fixed={"engine": name}, progress=False, written=f"snapshots from {name}"))


READERS = {reader.name: reader for reader in (
    Reader("lammps", "grainview.formats.lammps:open_lammps", Backend(
        "grainview.formats.backends:LammpsBackend", ("contacts", "walls", "log", "time_step", "columns", "inertia"),
        "LAMMPS 2D granular dumps (particles, pairs, walls) as a grainview dataset", "https://github.com/lammps/lammps",
        {"contacts": "contacts=<the pairs' dump local> besides the particles' dump"}), Convert(
        "grainview.formats.lammps:convert_lammps", "a LAMMPS 2D granular run (dump custom + dump local)",
        "A LAMMPS 2D granular run: the particles' dump custom (id radius mass x y, optionally vx vy omegaz), the "
        "pairs' dump local (compute property/local patom1 patom2; compute pair/local fx fy fz p1 p2 p3), "
        "optionally the walls' dump custom of fix wall/gran ... contacts arrays, and the log (time step and the "
        "computes' definitions). Contacts: touching pairs with a compressive normal force (docs/formats.md).",
        (Argument(("--particles",), {"required": True, "help": "the particles' dump custom"}),
         Argument(("--contacts",), {"required": True, "help": "the pairs' dump local"}),
         Argument(("--walls",), {"help": "the walls' dump custom (id and f_ID[1..8] of fix wall/gran ... contacts; "
                                 "default: none, no wall contacts)"}),
         Argument(("--log",), {"help": "the run's log.lammps or input script: time step and compute definitions "
                               "(default: none; then --time-step is needed)"}),
         Argument(("--time-step",), {"type": float, "help": "the time step in s (default: the log's)"}),
         Argument(("--columns",), {"help": "which dump local column holds each quantity, e.g. "
                                   "patom1=c_pairs[1],patom2=c_pairs[2],fx=c_forces[2],fy=c_forces[3],p1=c_forces[5],"
                                   "p2=c_forces[6] (default: from the log or the columns' own names)"},
                  parse="grainview.formats.lammps:parse_columns"),
         Argument(("--inertia",), {"choices": ("auto", "disc", "sphere"), "default": "auto",
                                   "help": "moments of inertia m r^2/2 (disc) or 2 m r^2/5 (sphere); auto: as the "
                                   "log's fix nve/sphere says, disc without a log (default: auto)"})),
        written="snapshots from LAMMPS")),
    Reader("lmgc90", "grainview.formats.lmgc90:open_lmgc90", Backend(
        "grainview.formats.backends:Lmgc90Backend", ("x_period",),
        "LMGC90 2D rigid runs (DATBOX and OUTBOX text files) as a grainview dataset",
        "https://git-xen.lmgc.univ-montp2.fr/lmgc90/lmgc90_user"), Convert(
        "grainview.formats.lmgc90:convert_lmgc90", "an LMGC90 2D rigid run (DATBOX + OUTBOX text files)",
        "An LMGC90 2D rigid run: its folder holding DATBOX/BODIES.DAT and BULK_BEHAV.DAT (RBDY2 bodies with one "
        "DISKx, convex POLYG or JONCx contactor) and OUTBOX/DOF.OUT.n with Vloc_Rloc.OUT.n (DKDKx, DKJCx, PLPLx, "
        "PLJCx, DKPLx). Contacts: body pairs with a compressive normal force; two points on a pair make a double "
        "contact (docs/formats.md).",
        (Argument(("run",), {"help": "the run folder (holding DATBOX/ and OUTBOX/)"}),
         Argument(("--x-period",), {"type": float, "default": None, "metavar": "L",
                                    "help": "the run's period along x in m, as its script gave "
                                    "chipy.SetPeriodicCondition(xperiod=L) (no output file records it; default: a run "
                                    "bounded by walls)"})),
        written="snapshots from LMGC90")),
    Reader("mercurydpm", "grainview.formats.mercurydpm:open_mercurydpm", Backend(
        "grainview.formats.backends:MercuryDpmBackend", ("fstat", "restart", "units"),
        "MercuryDPM 2D runs (.data, .fstat, .restart) as a grainview dataset", "https://www.mercurydpm.org"), Convert(
        "grainview.formats.mercurydpm:convert_mercurydpm", "a MercuryDPM 2D run (.data + .fstat + .restart)",
        "A MercuryDPM 2D run: its .data (particles), .fstat (contacts, each pair written from both sides) and "
        ".restart (dimensions, masses, walls). MercuryDPM has no units of its own: say which (--units). "
        "Contacts: overlapping pairs with a compressive normal force, one per pair (docs/formats.md).",
        (Argument(("data",), {"help": "the run's .data file"}),
         Argument(("--fstat",), {"help": "the run's .fstat file (default: beside the .data, same name)"}),
         Argument(("--restart",), {"help": "the run's .restart file (default: beside the .data, same name)"}),
         Argument(("--units",), {"required": True, "help": "si (the run is in m, kg, s), or "
                                 "length=L,mass=M,time=T: the SI value of one length, mass and time unit of "
                                 "the run (m, kg, s)"}, parse="grainview.formats.mercurydpm:parse_units")),
        notes=True, written="snapshots from MercuryDPM")),
    Reader("pegs", "grainview.formats.pegs:open_pegs", Backend(
        "grainview.formats.backends:PegsBackend", ("positions", "metres_per_pixel", "force_unit_n", "frame_interval_s",
                                                   "thickness_m", "density_kg_m3"),
        "PeGS2 photoelastic adjacency lists and particle positions as a grainview dataset",
        "https://github.com/jekollmer/PEGS",
        {"positions": "positions=<particle_positions.txt or the *_centers.txt files> besides the adjacency list"}),
        Convert(
        "grainview.formats.pegs:convert_pegs", "a photoelastic experiment solved by PeGS2 (adjacency list + positions)",
        "A photoelastic experiment solved by PeGS2: its adjacency lists (rows frame, id1, id2, tangential force, "
        "normal force; id2 -1 a wall) and the disks (particle_positions.txt of particleTrack, or the *_centers.txt "
        "of particleDetect), in pixels. The scale and the force unit are required (docs/formats.md).",
        (Argument(("adjacency",), {"nargs": "+", "help": "Adjacency_list.txt, or the frames' *_Adjacency.txt"}),
         Argument(("--positions",), {"nargs": "+", "required": True,
                                     "help": "particle_positions.txt, or the frames' *_centers.txt"}),
         Argument(("--metres-per-pixel",), {"type": float, "required": True,
                                            "help": "the image scale, m per pixel (PeGS2's metersperpixel)"}),
         Argument(("--force-unit-n",), {"type": float, "required": True,
                                        "help": "newtons per force unit of the adjacency list (1 when PeGS2's fsigma "
                                        "is calibrated in N)"}),
         Argument(("--frame-interval",), {"type": float, "help": "time between frames, s (default: {:g})"},
                  keyword="frame_interval_s", default_from="grainview.formats.pegs:convert_pegs"),
         Argument(("--thickness",), {"type": float, "help": "the disks' thickness, m (default: {:g}; stresses are "
                                     "per this thickness)"},
                  keyword="thickness_m", default_from="grainview.formats.pegs:convert_pegs"),
         Argument(("--density",), {"type": float, "help": "the disks' density for their masses, kg/m^3 (not "
                                   "measured; default: {:g})"},
                  keyword="density_kg_m3", default_from="grainview.formats.pegs:convert_pegs")),
        notes=True, written="frames from PeGS2")),
    _peer("box2d", "Box2D 2.3", "Box2dBackend", "Box2D"),
    _peer("pymunk", "pymunk", "PymunkBackend", "pymunk"),
)}
"""Format name -> its :class:`Reader`, in the order ``grainview convert --help`` lists them."""


def _installed() -> dict:
    """The readers of other packages: ``xarray.backends`` entry points whose class carries a
    :class:`Reader` as ``reader`` (each loaded to look; grainview's own are left alone)."""
    from importlib.metadata import entry_points

    ours = {reader.backend.target for reader in READERS.values()}
    found = {}
    for point in entry_points(group="xarray.backends"):
        if point.name in READERS or point.value in ours:
            continue
        try:
            declared = getattr(point.load(), "reader", None)
        except Exception:  # another package's backend that does not load here: not a reader of ours
            continue
        if isinstance(declared, Reader) and declared.name == point.name:
            found[point.name] = declared
    return found


def readers(installed: bool = True) -> dict:
    """:data:`READERS`, and with ``installed`` the readers of other packages' entry points
    (:func:`_installed`), by name."""
    return {**READERS, **_installed()} if installed else dict(READERS)


def reader(name: str) -> Reader | None:
    """The reader of format ``name`` (this package's first, then the entry points'), or None."""
    return READERS.get(name) or _installed().get(name)
