"""``grainview info`` in under a second: a file's summary read with netCDF4 and numpy alone.

Importing xarray, pandas and dask takes about a second on its own, longer than the whole
summary of a study's file. So the summary that ``grainview info`` prints is read here with
netCDF4, computed with the pure array functions of :mod:`grainview.analysis.arrays` (the same physics
as the accessors) and formatted by :func:`grainview.app.summary.summary_lines` (the same lines as
the report's index). The checks made on the way: the file opens as netCDF, it is a grainview
file, its structure and units follow the contract (:func:`grainview.contract.schema.structure_problems`,
:func:`grainview.contract.schema.unit_problems`), a netCDF-3 file is neither shorter than its fixed data
and records need nor longer by records its header does not count, no incomplete snapshot comes
before complete ones, the polygons' ``vertices`` (where the file has them) follow the contract's
rules for shapes (:func:`grainview.contract.shapes.shape_problems`), and the values the summary
reads are sound: times increasing strictly,
finite forces, normal forces >= 0 (:mod:`grainview.contract.file_checks`, the words of
:func:`grainview.contract.validation.validate`); a stored chunk that the netCDF library refuses
to read (a compressed file's chunk that fails its checksum) is one line naming the file. With
``grainview info --check``, every stored chunk of every variable is read first
(:func:`grainview.contract.file_checks.damaged_chunks`), a file without
``grainview_schema_version`` is a problem, and every value is checked by
:func:`grainview.contract.validation.validate`.
"""

from __future__ import annotations

import os

import numpy as np

from ..contract.errors import FileFormatError, SchemaError
from ..contract.file_checks import (COUNT_OUT_OF_RANGE, MISSING_SCHEMA_VERSION, checked_variables, damaged_chunks,
                                    damaged_snapshots, force_problems, foreign_file_problems, order_problems)
from ..contract.schema import complete_snapshots, missing_units, structure_problems, unit_problems
from ..contract.shapes import particle_area, regular_polygons, shape_problems
from ..contract.writer import netcdf3_data_bytes

__all__ = ["read_facts", "describe_file"]


def _netcdf3_data(nc) -> tuple[int, int, int]:
    """``(fixed, record, n_records)``: bytes of a netCDF-3 file's fixed-size variables and of
    one record (:func:`grainview.contract.writer.netcdf3_data_bytes`), and the header's record count."""
    fixed, record = [], []
    for var in nc.variables.values():
        is_record = bool(var.dimensions) and nc.dimensions[var.dimensions[0]].isunlimited()
        shape = var.shape[1:] if is_record else var.shape
        (record if is_record else fixed).append(var.dtype.itemsize * int(np.prod(shape, dtype=np.int64)))
    fixed_bytes, record_bytes = netcdf3_data_bytes(fixed, record)
    n_records = len(nc.dimensions["time"]) if "time" in nc.dimensions else 0
    return fixed_bytes, record_bytes, n_records


def _check_netcdf3_size(nc, source) -> None:
    """Refuse a netCDF-3 file shorter than its data need (cut short) or longer by whole records
    than its header counts (:func:`grainview.contract.file_checks.hidden_records`). The header's own
    size is not known to netCDF4: a file longer than its data by two records or more is
    measured exactly (:func:`grainview.contract.io.open_dataset`'s check, with scipy), others cannot
    hide records."""
    from ..contract.file_checks import HIDDEN_RECORDS_TOLERATED

    fixed, record, n_records = _netcdf3_data(nc)
    needed, size = fixed + n_records * record, os.path.getsize(source)
    if size < needed:
        raise FileFormatError(f"{source}: truncated file ({size} bytes, its data need at least {needed})")
    if record and (size - needed) // record > HIDDEN_RECORDS_TOLERATED:
        from ..contract.netcdf3 import check_netcdf3_length

        check_netcdf3_length(source)


def read_facts(path, check=False) -> tuple[dict, dict]:
    """The summary's numbers of the file ``path`` and its global attributes.

    Parameters
    ----------
    path : str or path-like
        A netCDF file of the contract (netCDF-3 or compressed).
    check : bool, default False
        Also read every stored chunk of every variable first, so that a compressed file's
        chunk whose checksum does not match is found wherever it is
        (:func:`grainview.contract.file_checks.damaged_chunks`), and count a missing
        ``grainview_schema_version`` as a problem (``grainview info --check``).

    Returns
    -------
    facts : dict
        What :func:`grainview.app.summary.summary_lines` reads: ``n_vertices``, ``regular``
        (which polygons are regular, :func:`grainview.contract.shapes.regular_polygons`), ``n_walls``,
        ``n_slots``, ``snapshots`` (complete ones), ``time`` (s), ``contact_count``,
        ``solid_fraction``, ``eps_1`` and ``eps_q`` of the last snapshot (log strains against
        the first, docs/conventions.md §6; the particles' areas from their shapes,
        :func:`grainview.contract.shapes.particle_area`) and ``q_over_p`` per snapshot (q/p of the stress
        sigma = (1/V) sum_c f^c (x) l^c over every pair the file holds, paper Eq. M), plus
        ``missing_units``; for a periodic file ``cell`` (its flags, tilt, shear and how the
        positions are stored, :func:`cell_line`).
    attrs : dict
        The file's global attributes.

    Raises
    ------
    FileFormatError
        Not a readable netCDF file, a netCDF-3 file cut short or whose header hides records, an
        incomplete snapshot before complete ones; stored data the netCDF library refuses (a
        chunk that fails its checksum), in one line naming the file and the variables.
    SchemaError
        Not a grainview file; the structure or the units differ from the contract's (with
        ``check``, also: no ``grainview_schema_version``); the
        ``vertices`` break the contract's rules for shapes
        (:func:`grainview.contract.shapes.shape_problems`); times
        that do not increase strictly, non-finite forces or negative normal forces.
    """
    import netCDF4

    from ..analysis.arrays.strain import log_strain
    from ..contract.cell import unwrap_tilt
    from ..analysis.arrays.stress import stress_tensor
    from ..analysis.arrays.tensors import principal

    source = os.fspath(path)
    if not os.path.exists(source):
        raise FileFormatError(f"{source}: no such file")
    try:
        nc = netCDF4.Dataset(source)
    except (OSError, RuntimeError, ValueError) as exc:
        raise FileFormatError(f"{source}: not a readable netCDF file ({exc})") from exc
    with nc:
        nc.set_auto_maskandscale(False)
        sizes = {name: len(dim) for name, dim in nc.dimensions.items()}
        variables = {name: (var.dimensions, var.dtype) for name, var in nc.variables.items()
                     if var.dtype is not str}
        units = {name: (var.getncattr("units") if "units" in var.ncattrs() else None)
                 for name, var in nc.variables.items()}
        foreign = foreign_file_problems(variables)
        if check and not foreign and not nc.data_model.startswith("NETCDF3"):  # netCDF-3 has no checksums
            damaged = damaged_chunks(nc.variables)
            if damaged:
                raise FileFormatError(f"{source}: " + "; ".join(damaged) + " (the file is damaged)")
        unversioned = [MISSING_SCHEMA_VERSION] if check and "grainview_schema_version" not in nc.ncattrs() else []
        problems = foreign or structure_problems(variables, sizes) + unit_problems(units) + unversioned
        if problems:
            raise SchemaError(problems, source)
        netcdf3 = nc.data_model.startswith("NETCDF3")
        if netcdf3:
            _check_netcdf3_size(nc, source)
        attrs = {k: nc.getncattr(k) for k in nc.ncattrs()}
        v = checked_variables(nc.variables, source)  # a damaged chunk: one line naming the file
        radius, n_vertices = np.asarray(v["radius"][:], float), np.asarray(v["n_vertices"][:])
        vertices = np.asarray(v["vertices"][:], float) if "vertices" in v else None
        if vertices is not None:
            problems = shape_problems(radius, n_vertices, vertices)
            if problems:
                raise SchemaError(problems, source)
        facts = {"n_vertices": n_vertices, "regular": regular_polygons(radius, n_vertices, vertices),
                 "n_walls": sizes.get("wall", 0),
                 "n_slots": sizes["contact"], "missing_units": missing_units(units),
                 "size": os.path.getsize(source), "format": "netCDF-3" if netcdf3 else "netCDF-4, compressed"}
        complete = complete_snapshots(v) if "time" in v and sizes.get("time", 0) else np.zeros(0, bool)
        snapshots = damaged_snapshots(complete, source)
        facts["snapshots"] = snapshots
        if not snapshots:
            return facts, attrs
        k = slice(0, snapshots)
        count = np.asarray(v["contact_count"][k])
        facts.update(time=np.asarray(v["time"][k], dtype=float), contact_count=count)
        problems = order_problems("time", facts["time"], " s")
        if "step" in v:
            problems += order_problems("step", np.asarray(v["step"][k]))
        outside = int(((count < 0) | (count > sizes["contact"])).sum())
        if outside:
            problems.append(COUNT_OUT_OF_RANGE.format(count=outside, slots=sizes["contact"]))
        else:
            occupied = np.arange(sizes["contact"])[None, :] < count[:, None]
            fn, ft = np.asarray(v["fn"][k]), np.asarray(v["ft"][k])
            problems += force_problems(fn, ft, v["i"][k], v["j"][k], occupied)
        if problems:
            raise SchemaError(problems, source)
        box_min, box_max = np.asarray(v["box_min"][k]), np.asarray(v["box_max"][k])
        length, height = box_max[:, 0] - box_min[:, 0], box_max[:, 1] - box_min[:, 1]
        if "cell" in v and "periodic" in v:
            tilt = unwrap_tilt(np.asarray(v["cell"][k], float)[:, 1, 0], length)
            facts["cell"] = {"periodic": np.asarray(v["periodic"][:]).astype(bool), "tilt": tilt,
                             "gamma": (tilt - tilt[0]) / height, "positions": attrs.get("cell_positions", "wrapped")}
        solid = float(particle_area(radius, n_vertices, vertices).sum())
        with np.errstate(all="ignore"):  # a box of no size gives an infinite fraction, not a warning
            facts["solid_fraction"] = solid / (length * height)
        if snapshots > 1:
            eps_1, eps_2 = log_strain(height[-1], height[0]), log_strain(length[-1], length[0])
            facts.update(eps_1=float(eps_1), eps_q=float(eps_1 - eps_2))
            volume = length * height * float(attrs.get("thickness_m", 1.0))
            with np.errstate(all="ignore"):  # a NaN normal or branch gives a NaN q/p, not a warning
                sigma = stress_tensor(fn, ft, v["normal"][k], v["branch"][k], occupied, volume)
                s1, s2, _ = principal(sigma)
                facts["q_over_p"] = (s1 - s2) / (s1 + s2)
    return facts, attrs


def cell_line(cell: dict) -> str:
    """The line ``grainview info`` gives a periodic cell: which vectors repeat, the tilt's range,
    the simple shear gamma = (tilt - tilt_0) / h at the last snapshot (the tilt made continuous
    across flips, :func:`grainview.contract.cell.unwrap_tilt`) and how the positions are stored."""
    along = {(True, True): "along x and along the cell's second vector (biperiodic)",
             (True, False): "along x (walls bound it in y)",
             (False, True): "along the cell's second vector (walls bound it in x)"}[tuple(bool(p) for p in
                                                                                    cell["periodic"])]
    tilt = cell["tilt"]
    return (f"periodic cell: repeats {along}; tilt {tilt.min():.4g} .. {tilt.max():.4g} m, shear gamma "
            f"{cell['gamma'][-1]:.4g} at the last snapshot; positions {cell['positions']}")


def describe_file(path, check=False) -> tuple[list, dict]:
    """The lines ``grainview info`` prints for ``path`` (:func:`read_facts`, formatted by
    :func:`grainview.app.summary.summary_lines`, then the file's size and format, and notes on
    variables without units and on a missing schema version) and the file's global attributes;
    ``check``: as for :func:`read_facts` (``grainview info --check``)."""
    from .summary import summary_lines

    facts, attrs = read_facts(path, check=check)
    lines = summary_lines(facts, attrs)
    size = facts["size"]
    scaled, unit = next(((size / 1024**p, u) for p, u in ((3, "GiB"), (2, "MiB"), (1, "KiB"))
                         if size >= 1024**p), (size, "bytes"))
    if "cell" in facts:
        lines.append(cell_line(facts["cell"]))
    lines.append(f"file: {scaled:.1f} {unit} ({size:,} bytes), {facts['format']}")
    if facts["missing_units"]:
        lines.append(f"note: {len(facts['missing_units'])} variable(s) carry no units attribute and are read in the "
                     f"contract's units (docs/schema.md): {', '.join(facts['missing_units'])}")
    if "grainview_schema_version" not in attrs:
        lines.append("note: the file has no grainview_schema_version attribute: which version of the contract it "
                     "follows is unknown ('grainview info --check' refuses it)")
    return lines, attrs
