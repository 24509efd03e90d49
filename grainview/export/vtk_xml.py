"""VTK's XML file formats, written as ParaView (VTK) and OVITO both read them.

Three kinds of files (VTK's "VTK File Formats", XML section):

* PolyData (``.vtp``): points and their vertex, line and polygon cells, with point and cell
  data arrays;
* a multi-block collection (``.vtm``): named blocks, each a ``.vtp`` file beside it;
* a ParaView collection (``.pvd``): files on a time axis.

Data arrays are written uncompressed, little-endian, ``format="binary"``: base64 of one
UInt64 byte count followed by the values, the two encoded together. This is the subset that
OVITO's VTP readers accept (they refuse compressed and appended arrays, VTK's own writers'
default, and a count encoded apart from the values); VTK's readers read it as well. Floats are
Float64, integers and booleans Int64. meshio, the project's VTK writer before, writes
unstructured grids (``.vtu``) only, which OVITO does not take as particles.
"""

from __future__ import annotations

import base64
import xml.etree.ElementTree as ElementTree

import numpy as np

__all__ = ["polydata", "multiblock", "collection", "write_xml"]

_HEADER = {"type": "PolyData", "version": "1.0", "byte_order": "LittleEndian", "header_type": "UInt64"}


def _data_array(parent, name: str, values) -> None:
    """Append a ``<DataArray>`` of ``values`` (shape (n,) or (n, components)) to ``parent``."""
    values = np.asarray(values)
    floating = values.dtype.kind == "f"
    raw = np.ascontiguousarray(values, dtype="<f8" if floating else "<i8").tobytes()
    element = ElementTree.SubElement(parent, "DataArray", type="Float64" if floating else "Int64", Name=name,
                                     format="binary")
    if values.ndim > 1:
        element.set("NumberOfComponents", str(values.shape[1]))
    element.text = base64.b64encode(np.uint64(len(raw)).astype("<u8").tobytes() + raw).decode("ascii")


def _cells(piece, tag: str, sizes) -> None:
    """Append the ``connectivity`` and ``offsets`` of consecutive cells of ``sizes`` points."""
    sizes = np.asarray(sizes, dtype=np.int64)
    cells = ElementTree.SubElement(piece, tag)
    _data_array(cells, "connectivity", np.arange(sizes.sum(), dtype=np.int64))
    _data_array(cells, "offsets", np.cumsum(sizes))


def polydata(points, *, verts: bool = False, lines=None, polys=None, point_data=None,
             cell_data=None) -> ElementTree.ElementTree:
    """A VTK PolyData file: points, and vertex, line or polygon cells of consecutive points.

    Parameters
    ----------
    points : array_like, (P, 2) or (P, 3)
        Point coordinates (z = 0 added to 2D points).
    verts : bool, default False
        One vertex cell per point.
    lines, polys : array_like of int, optional
        Points per line or per polygon cell, in order: cell c is made of the points that
        follow those of cell c - 1 (the lines' or polygons' points listed one cell after the
        other).
    point_data, cell_data : dict of str to array_like, optional
        Data arrays by name, one row per point or per cell (vectors as (n, components)).

    Returns
    -------
    xml.etree.ElementTree.ElementTree
        The file's XML tree (write it with :func:`write_xml`).
    """
    points = np.asarray(points, dtype=float)
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    # only the cell kinds given are counted (VTK takes a missing count as 0): an empty file of
    # lines would otherwise count as many vertices as points, as a file of particles does in OVITO
    counts = {kind: len(cells) for kind, cells in (("Verts", points if verts else None), ("Lines", lines),
                                                     ("Polys", polys)) if cells is not None}
    root = ElementTree.Element("VTKFile", _HEADER)
    piece = ElementTree.SubElement(ElementTree.SubElement(root, "PolyData"), "Piece", NumberOfPoints=str(len(points)),
                                   **{f"NumberOf{kind}": str(n) for kind, n in counts.items()})
    for tag, data in (("PointData", point_data), ("CellData", cell_data)):
        element = ElementTree.SubElement(piece, tag)
        for name, values in (data or {}).items():
            _data_array(element, name, values)
    _data_array(ElementTree.SubElement(piece, "Points"), "Points", points)
    if verts:
        _cells(piece, "Verts", np.ones(len(points), dtype=np.int64))
    if lines is not None:
        _cells(piece, "Lines", lines)
    if polys is not None:
        _cells(piece, "Polys", polys)
    return ElementTree.ElementTree(root)


def multiblock(blocks) -> ElementTree.ElementTree:
    """A VTK multi-block file of named blocks, each a file.

    Parameters
    ----------
    blocks : iterable of (str, str or None)
        (block name, file name relative to the ``.vtm`` file), in order; None for an empty
        block (no file).

    Returns
    -------
    xml.etree.ElementTree.ElementTree
    """
    root = ElementTree.Element("VTKFile", dict(_HEADER, type="vtkMultiBlockDataSet"))
    group = ElementTree.SubElement(root, "vtkMultiBlockDataSet")
    for index, (name, file) in enumerate(blocks):
        ElementTree.SubElement(group, "DataSet", index=str(index), name=name, **({} if file is None else {"file": file}))
    return ElementTree.ElementTree(root)


def collection(entries) -> ElementTree.ElementTree:
    """A ParaView collection (``.pvd``) of files on a time axis.

    Parameters
    ----------
    entries : iterable of (float, str)
        (time in s, file name relative to the ``.pvd`` file), in order.

    Returns
    -------
    xml.etree.ElementTree.ElementTree
    """
    root = ElementTree.Element("VTKFile", type="Collection", version="0.1")
    group = ElementTree.SubElement(root, "Collection")
    for time, name in entries:
        ElementTree.SubElement(group, "DataSet", timestep=repr(float(time)), group="", part="0", file=name)
    return ElementTree.ElementTree(root)


def write_xml(tree: ElementTree.ElementTree, path) -> None:
    """Write ``tree`` to ``path`` with an XML declaration (UTF-8)."""
    tree.write(path, xml_declaration=True, encoding="utf-8")
