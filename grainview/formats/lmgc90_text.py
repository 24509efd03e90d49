"""LMGC90's 2D text files, parsed into plain Python and numpy: the file layer of the LMGC90 reader.

A 2D rigid LMGC90 run keeps its model in ``DATBOX/`` and writes its results into ``OUTBOX/``:

* ``DATBOX/BODIES.DAT``: one ``$bdyty`` block per body (``RBDY2 <number>``), with its bulk
  (``PLAIN ... behav <name> avrd= .. gyrd= ..``: the area is ``pi avrd^2`` and the moment of
  inertia ``m gyrd^2``), its node (``NO3xx ... coo1= coo2= coo3=``, the reference position)
  and its contactors (``DISKx ... byrd=``, ``JONCx ... axe1= axe2=``, ``POLYG ...
  nb_vertex= n`` followed by n lines ``coo1= coo2=``: the vertices relative to the body's
  node, in its reference frame);
* ``DATBOX/BULK_BEHAV.DAT``: the bulk behaviours (``<name> RIGID Umas= <density>``) and the
  gravity (``grv1= grv2= grv3=``);
* ``OUTBOX/DOF.OUT.n``: a ``$steps <step> time= <t>`` header, then per body ``$bdyty``,
  ``RBDY2 <number>``, ``$nodty``, ``NO3xx 1 X(1)= X(2)= X(3)=`` (displacement from the
  reference position and rotation) and ``V(1)= V(2)= V(3)=`` (velocity) (written by
  ``mod_RBDY2`` ``write_out_dof``);
* ``OUTBOX/Vloc_Rloc.OUT.n``: the same header, then one ``$icdan <family> <n>`` block per
  candidate-antagonist entry: a title line naming the columns (``cdbdy numbr cdtac numbr ...
  behav anbdy numbr antac numbr ... sttus iadj``), the data line under it, and the lines
  ``rlt/H rln/H rls/H``, ``vlt vln vls``, ``gapTT``, ``n(1) n(2) n(3)``, ``coo1 coo2 coo3``,
  optional internal variables, a blank line (written by ``write_out_Vloc_Rloc`` of
  ``mod_DKDKx``, ``mod_DKJCx``, ``mod_PLPLx``, ``mod_PLJCx``, ``mod_DKPLx``).

Numbers are Fortran's: ``0.1234567D+01``, and ``0.1234567+100`` for three-digit exponents.
Every function refuses a file it cannot read in one line (:class:`grainview.contract.errors.FileFormatError`).
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, field

import numpy as np

from ..contract.errors import FileFormatError
from .checks import input_file, input_folder

__all__ = ["Body", "Contactor", "DofSnapshot", "VlocEntry", "VlocSnapshot", "fortran_float", "read_bodies",
           "read_bulk_behav", "read_dof", "read_vloc_rloc", "output_files"]

_NUMBER = r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[DdEe][-+]?\d+|[-+]\d{3})?"
# a value ends its field: digits followed by anything but a blank are a damaged number, not a shorter one
_KEY_VALUE = re.compile(r"([A-Za-z][A-Za-z0-9_()/]*)\s*=\s*(" + _NUMBER + r")(?!\S)")
_STEPS = re.compile(r"^\$steps\s+(\d+)\s+time=\s*(" + _NUMBER + r")\s*$")
_VLOC_LABELS = {"rlt/H": "rlt", "rln/H": "rln", "vlt =": "vlt", "vln =": "vln", "gapTT": "gap", "n(1)=": "n1",
                "n(2)=": "n2", "coo1=": "x", "coo2=": "y"}
_VLOC_VALUE = re.compile("(" + "|".join(re.escape(k) for k in _VLOC_LABELS) + r"|rlt  |rln  )\s*("
                         + _NUMBER + r")(?!\S)")


def fortran_float(text: str) -> float:
    """A number as Fortran writes it (``0.1234567D+01``, ``-0.5E-03``, ``0.1234567+100``).

    Raises
    ------
    ValueError
        ``text`` is not a number.
    """
    text = text.strip().replace("D", "E").replace("d", "e")
    match = re.fullmatch(r"([-+]?(?:\d+\.\d*|\.\d+))([-+]\d{3})", text)
    if match:  # Fortran drops the exponent letter of a three-digit exponent
        text = match.group(1) + "E" + match.group(2)
    return float(text)


LARGEST_BODY = 2**31 - 1
"""The largest body number read (LMGC90 numbers its bodies with default Fortran integers)."""


def body_number(text: str, where: str) -> int:
    """A body number, 1 .. :data:`LARGEST_BODY`; one line for anything else.

    Raises
    ------
    FileFormatError
        ``text`` is not an integer in that range.
    """
    try:
        number = int(text)
    except ValueError:
        number = None
    if number is None or not 1 <= number <= LARGEST_BODY:
        raise FileFormatError(f"{where}: body number {text.strip()[:30]!r}; expected an integer from 1 to "
                              f"{LARGEST_BODY}")
    return number


def _values(line: str) -> dict:
    """``key= value`` pairs of a line, values as floats."""
    return {key: fortran_float(value) for key, value in _KEY_VALUE.findall(line)}


@dataclass
class Contactor:
    """One contactor of a body: ``kind`` (``DISKx``, ``POLYG``, ``JONCx``...), ``color``, its
    numeric parameters (``byrd``, ``axe1``...) and, for a polygon, its vertices (n, 2) relative to
    the body's node in the reference frame, m."""

    kind: str
    color: str
    values: dict
    vertices: list = field(default_factory=list)


@dataclass
class Body:
    """One body of ``BODIES.DAT``: its model (``RBDY2``), number, bulk behaviour name, ``avrd``
    and ``gyrd`` (m), reference position ``reference`` (3,) (x, y in m, rotation in rad) and
    contactors."""

    model: str
    number: int
    behav: str = ""
    avrd: float = float("nan")
    gyrd: float = float("nan")
    reference: np.ndarray | None = None
    contactors: list = field(default_factory=list)


def _lines(path):
    path = input_file(path, "an LMGC90 text file")
    try:
        with open(path, encoding="ascii", errors="strict") as fh:
            return fh.read().splitlines()
    except UnicodeDecodeError:
        with open(path, "rb") as fh:
            if fh.read(3) == b"\xef\xbb\xbf":
                raise FileFormatError(f"{path}: a byte-order mark at its start (an editor's; LMGC90 writes none): save "
                                      "the file without it") from None
        raise FileFormatError(f"{path}: not a text file (an LMGC90 text file holds ASCII only)") from None


def read_bodies(path) -> list:
    """The bodies of an LMGC90 ``BODIES.DAT``, in file order.

    Returns
    -------
    list of Body

    Raises
    ------
    FileFormatError
        Not a BODIES.DAT (no ``$bdyty`` block), a block without its node or bulk, a number
        that does not parse, a truncated block, a body number defined twice.
    """
    path = os.fspath(path)
    bodies, body, section = [], None, None
    for number, line in enumerate(_lines(path), start=1):
        where = f"{path}: line {number}"
        text = line.strip()
        if not text or text.startswith("!"):
            continue
        if text.startswith("$"):
            tag = text.split()[0]
            if tag == "$bdyty":
                if body is not None:
                    raise FileFormatError(f"{where}: a $bdyty block before the previous one ended with $$$$$$ "
                                          "(a truncated or damaged BODIES.DAT)")
                body, section = Body(model="", number=-1), "bdyty"
            elif tag == "$$$$$$":
                if body is None:
                    raise FileFormatError(f"{where}: $$$$$$ outside a $bdyty block")
                _check_body(body, path)
                bodies.append(body)
                body, section = None, None
            elif body is not None:
                section = tag[1:]
            continue
        if body is None:
            continue
        try:
            if section == "bdyty":
                model, index = text.split()[:2]
                body.model, body.number, section = model, body_number(index, where), None
            elif section == "blmty":
                tokens = text.split()
                if "behav" in tokens:
                    body.behav = tokens[tokens.index("behav") + 1]
                values = _values(text)
                body.avrd, body.gyrd = values.get("avrd", body.avrd), values.get("gyrd", body.gyrd)
            elif section == "nodty":
                values = _values(text)
                body.reference = np.array([values["coo1"], values["coo2"], values.get("coo3", 0.0)])
            elif section == "tacty":
                tokens = text.split()
                if tokens[0].startswith("coo1") or tokens[0].startswith("coo2"):
                    if not body.contactors:
                        raise FileFormatError(f"{where}: a vertex line before any contactor")
                    values = _values(text)
                    body.contactors[-1].vertices.append((values["coo1"], values["coo2"]))
                else:
                    color = tokens[tokens.index("color") + 1] if "color" in tokens else ""
                    body.contactors.append(Contactor(kind=tokens[0], color=color, values=_values(text)))
        except (ValueError, KeyError, IndexError):
            raise FileFormatError(f"{where}: cannot read {text[:60]!r} (section ${section} of a BODIES.DAT)") from None
    if body is not None:
        raise FileFormatError(f"{path}: the last $bdyty block has no closing $$$$$$ (a truncated BODIES.DAT)")
    if not bodies:
        raise FileFormatError(f"{path}: no $bdyty block (not an LMGC90 BODIES.DAT)")
    numbers = [body.number for body in bodies]
    if len(set(numbers)) != len(numbers):
        twice = next(number for k, number in enumerate(numbers) if number in numbers[:k])
        raise FileFormatError(f"{path}: body {twice} is defined twice; expected each body number once")
    return bodies


def _check_body(body, path):
    where = f"{path}: body {body.number}"
    if body.number < 0:
        raise FileFormatError(f"{path}: a $bdyty block without its '<model> <number>' line")
    if body.reference is None:
        raise FileFormatError(f"{where}: no $nodty node (its reference position)")
    for tact in body.contactors:
        if tact.kind == "POLYG":
            expected = tact.values.get("nb_vertex", -1)
            if not (math.isfinite(expected) and expected == int(expected) and 3 <= expected <= 2**31):
                raise FileFormatError(f"{where}: POLYG with nb_vertex= {expected:g}; expected a vertex count >= 3")
            expected = int(expected)
            if expected != len(tact.vertices):
                raise FileFormatError(f"{where}: POLYG with nb_vertex= {expected} but {len(tact.vertices)} vertex "
                                      "lines (a truncated BODIES.DAT)")


_BULK_KEYS = ("grv1", "grv2", "grv3", "Umas")
"""The values the reader takes from a BULK_BEHAV.DAT: each must be a number where it is given."""


def read_bulk_behav(path) -> tuple:
    """Densities of the rigid bulk behaviours and the gravity of an LMGC90 ``BULK_BEHAV.DAT``.

    Returns
    -------
    (dict, numpy.ndarray)
        behaviour name -> density (``Umas``, kg m-2 per unit thickness in 2D: a 2D body's mass is
        density x area), and the gravity (3,), m s-2 (zeros when the file has none).
    """
    path = os.fspath(path)
    density, gravity, name = {}, np.zeros(3), None
    for number, line in enumerate(_lines(path), start=1):
        text = line.strip()
        if not text or text.startswith("!"):
            continue
        try:
            values = _values(text)
            tokens = text.split()
            if any(re.search(rf"\b{key}\s*=", text) and key not in values for key in _BULK_KEYS):
                raise ValueError("a value that is not a number")
            if "grv1" in values:
                gravity = np.array([values.get(f"grv{k}", 0.0) for k in (1, 2, 3)])
                continue
            if not text.startswith("$") and not tokens[0].endswith("=") and "=" not in tokens[0]:
                name = tokens[0]
            if "Umas" in values and name is not None:
                density[name] = values["Umas"]
        except (ValueError, IndexError):
            raise FileFormatError(f"{path}: line {number}: cannot read {text[:60]!r} (a BULK_BEHAV.DAT)") from None
    if not density:
        raise FileFormatError(f"{path}: no behaviour with a density (Umas=): not an LMGC90 BULK_BEHAV.DAT")
    return density, gravity


def _one_record(lines, start, path):
    """Refuse a file holding several ``$steps`` records (LMGC90's append mode)."""
    later = [k for k in range(start, len(lines)) if lines[k].startswith("$steps")]
    if later:
        raise FileFormatError(f"{path}: line {later[0] + 1}: a second '$steps' record; the reader takes one snapshot "
                              "per file (DOF.OUT.n, Vloc_Rloc.OUT.n), not files written in append mode")


def _header(lines, path):
    for k, line in enumerate(lines):
        text = line.strip()
        if not text or text.startswith("!"):
            continue
        match = _STEPS.match(text)
        if match is None:
            raise FileFormatError(f"{path}: expected a '$steps <step> time= <t>' header, found {text[:60]!r} "
                                  "(not an LMGC90 OUTBOX file)")
        step = int(match.group(1))
        if step > 2**63 - 1:
            raise FileFormatError(f"{path}: line {k + 1}: step {step}; expected an integer below 2^63")
        return step, fortran_float(match.group(2)), k + 1
    raise FileFormatError(f"{path}: an empty file (no '$steps' header)")


@dataclass
class DofSnapshot:
    """One ``DOF.OUT`` record: the step, the time (s), the bodies' numbers (B,) and their
    displacements and rotations ``X`` (B, 3) and velocities ``V`` (B, 3)."""

    step: int
    time: float
    numbers: np.ndarray
    X: np.ndarray
    V: np.ndarray


def read_dof(path) -> DofSnapshot:
    """An LMGC90 ``DOF.OUT.n`` file (rigid 2D bodies, ``NO3xx`` nodes).

    Raises
    ------
    FileFormatError
        No ``$steps`` header, a body block without its ``X`` or ``V`` line, a file that ends
        inside a block or before its closing ``!---`` line (truncated), a deformable body, a
        body written twice.
    """
    path = os.fspath(path)
    lines = _lines(path)
    step, time, start = _header(lines, path)
    _one_record(lines, start, path)
    numbers, X, V, lines_of = [], [], [], []
    k, finished = start, False
    while k < len(lines):
        text = lines[k].strip()
        if text.startswith("!"):  # a rule under the header, and two after the last body
            if numbers:
                finished = True
                break
            k += 1
            continue
        if text != "$bdyty":
            if text:
                cut = " (a truncated DOF.OUT)" if k == len(lines) - 1 else ""
                raise FileFormatError(f"{path}: line {k + 1}: expected $bdyty, found {text[:60]!r}{cut}")
            k += 1
            continue
        block = [lines[m].strip() for m in range(k + 1, min(k + 6, len(lines)))]
        if len(block) < 5 or block[4] != "$$$$$$":
            raise FileFormatError(f"{path}: line {k + 1}: a body block cut short (a truncated DOF.OUT)")
        try:
            model, number = block[0].split()[:2]
            if model != "RBDY2" or not block[2].startswith("NO3xx"):
                raise FileFormatError(f"{path}: line {k + 2}: body {number} is a {model} with {block[2][:5]} nodes; "
                                      "only 2D rigid bodies (RBDY2, NO3xx) can be read")
            x, v = _values(block[2]), _values(block[3])
            numbers.append(body_number(number, f"{path}: line {k + 2}"))
            lines_of.append(k + 2)
            X.append([x["X(1)"], x["X(2)"], x["X(3)"]])
            V.append([v["V(1)"], v["V(2)"], v["V(3)"]])
        except (ValueError, KeyError):
            raise FileFormatError(f"{path}: line {k + 2}: cannot read the body block (expected RBDY2 <number>, "
                                  "$nodty, NO3xx 1 X(1)= X(2)= X(3)=, V(1)= V(2)= V(3)=)") from None
        k += 6
    if not finished:
        raise FileFormatError(f"{path}: no closing '!---' line after the bodies (a truncated DOF.OUT)")
    seen = {}
    for number, line in zip(numbers, lines_of):
        if number in seen:
            raise FileFormatError(f"{path}: line {line}: a second block of body {number} (the first at line "
                                  f"{seen[number]}); expected each body once")
        seen[number] = line
    return DofSnapshot(step, time, np.array(numbers, np.int64), np.array(X, float).reshape(-1, 3),
                       np.array(V, float).reshape(-1, 3))


@dataclass
class VlocEntry:
    """One ``$icdan`` entry of a ``Vloc_Rloc.OUT`` file (one contact point).

    ``family`` is the contact family (``PLPLx``...), ``cd``/``an`` the candidate's and the
    antagonist's body numbers, ``cd_kind``/``an_kind`` their contactor types, ``behav`` the
    contact law's name, ``status`` its status (``stick``, ``slide``, ``noctc``...); ``rlt``,
    ``rln`` the mean forces over the step (impulse / H, N), ``gap`` (m), ``normal`` (2,) and
    ``point`` (2,) as LMGC90 wrote them; ``index`` the entry's number in its family (``$icdan
    <family> <index>``) and ``line`` the line of its ``$icdan``."""

    family: str
    cd: int
    an: int
    cd_kind: str
    an_kind: str
    behav: str
    status: str
    rlt: float
    rln: float
    gap: float
    normal: tuple
    point: tuple
    index: int = -1
    line: int = 0


@dataclass
class VlocSnapshot:
    """One ``Vloc_Rloc.OUT`` record: the step, the time (s) and the entries."""

    step: int
    time: float
    entries: list


def read_vloc_rloc(path) -> VlocSnapshot:
    """An LMGC90 ``Vloc_Rloc.OUT.n`` file.

    Raises
    ------
    FileFormatError
        No ``$steps`` header; an entry whose data line does not match its title line, or that
        lacks one of ``rlt/H rln/H``, ``gapTT``, ``n(1) n(2)``, ``coo1 coo2`` (a truncated file);
        impulses written without ``/H`` (the smooth method, not read).
    """
    path = os.fspath(path)
    lines = _lines(path)
    step, time, start = _header(lines, path)
    _one_record(lines, start, path)
    starts = [k for k in range(start, len(lines)) if lines[k].startswith("$icdan")]
    entries = []
    for n, k in enumerate(starts):
        end = starts[n + 1] if n + 1 < len(starts) else len(lines)
        entries.append(_entry(lines[k:end], path, k + 1, last=n + 1 == len(starts)))
    stray = [k for k in range(start, starts[0] if starts else len(lines))
             if lines[k].strip() and not lines[k].strip().startswith("!")]
    if stray:
        raise FileFormatError(f"{path}: line {stray[0] + 1}: expected $icdan, found {lines[stray[0]].strip()[:60]!r}")
    return VlocSnapshot(step, time, entries)


def _entry(block, path, line, last):
    where = f"{path}: line {line}"
    head = block[0].split()
    if len(head) < 2 or len(block) < 3:
        raise FileFormatError(f"{where}: an $icdan entry cut short (a truncated Vloc_Rloc.OUT)")
    family = head[1]
    # the title names the columns of the data line under it (PLPLx's title is cut before its
    # last two columns, sttus and iadj)
    title, data = block[1].split(), block[2].split()
    if not {"cdbdy", "cdtac", "behav", "anbdy", "antac"} <= set(title) or len(data) < len(title) or \
            len(data) > len(title) + 2:
        cut = "a truncated Vloc_Rloc.OUT" if last else "a damaged Vloc_Rloc.OUT"
        raise FileFormatError(f"{where}: {family} entry: its data line {block[2].strip()[:60]!r} does not match its "
                              f"title line ({cut})")
    if block[-1].strip() or len(block) < 9:
        cut = "a truncated Vloc_Rloc.OUT" if last else "a damaged Vloc_Rloc.OUT"
        raise FileFormatError(f"{where}: {family} entry cut short: no blank line after it ({cut})")
    found = {}
    for text in block[3:]:
        for label, value in _VLOC_VALUE.findall(text):
            if label in ("rlt  ", "rln  "):
                raise FileFormatError(f"{where}: {family} entry: forces written as {label.strip()!r}, not "
                                      "'rlt/H': output of the smooth method, which the reader does not read")
            found[_VLOC_LABELS[label]] = fortran_float(value)
    missing = [label for label, name in _VLOC_LABELS.items() if name not in found]
    if missing:
        cut = "a truncated Vloc_Rloc.OUT" if last else "a damaged Vloc_Rloc.OUT"
        raise FileFormatError(f"{where}: {family} entry without {', '.join(m.strip(' =') for m in missing)} ({cut})")
    try:
        int(data[title.index("cdbdy") + 1]), int(data[title.index("anbdy") + 1])
    except ValueError:
        raise FileFormatError(f"{where}: {family} entry: body numbers {block[2].strip()[:60]!r} do not parse "
                              "(more than 99999 bodies?)") from None
    cd = body_number(data[title.index("cdbdy") + 1], f"{where}: {family} entry")
    an = body_number(data[title.index("anbdy") + 1], f"{where}: {family} entry")
    index = int(head[2]) if len(head) > 2 and head[2].isdigit() else -1
    return VlocEntry(family=family, cd=cd, an=an, cd_kind=data[title.index("cdtac")],
                     an_kind=data[title.index("antac")], behav=data[title.index("behav")],
                     status=data[title.index("sttus")] if "sttus" in title else data[-2], rlt=found["rlt"],
                     rln=found["rln"], gap=found["gap"],
                     normal=(found["n1"], found["n2"]), point=(found["x"], found["y"]), index=index, line=line)


def output_files(outbox) -> list:
    """The snapshots of an OUTBOX: ``(n, DOF.OUT.n, Vloc_Rloc.OUT.n)`` for every n, in order.

    Raises
    ------
    FileFormatError
        No ``DOF.OUT.n`` at all, a ``DOF.OUT.n`` without its ``Vloc_Rloc.OUT.n`` (or the
        reverse), two files of one snapshot (``DOF.OUT.2`` and ``DOF.OUT.02``).
    """
    outbox = input_folder(outbox, "an LMGC90 run's OUTBOX/, where it writes its results")
    found = {"DOF.OUT": {}, "Vloc_Rloc.OUT": {}}
    for name in sorted(os.listdir(outbox)):
        match = re.fullmatch(r"(DOF\.OUT|Vloc_Rloc\.OUT)\.(\d+)", name)
        if match:
            kind, n = match.group(1), int(match.group(2))
            if n in found[kind]:
                raise FileFormatError(f"{outbox}: {found[kind][n]} and {name} are both snapshot {n}; expected one "
                                      f"{kind} file per snapshot")
            found[kind][n] = name
    if not found["DOF.OUT"]:
        raise FileFormatError(f"{outbox}: no DOF.OUT.n file (write them with chipy.WriteOut or WriteOutDof)")
    for one, other in (("DOF.OUT", "Vloc_Rloc.OUT"), ("Vloc_Rloc.OUT", "DOF.OUT")):
        alone = sorted(set(found[one]) - set(found[other]))
        if alone:
            raise FileFormatError(f"{outbox}: {found[one][alone[0]]} has no {other}.{alone[0]} (every snapshot needs "
                                  "both)")
    return [(n, os.path.join(outbox, found["DOF.OUT"][n]), os.path.join(outbox, found["Vloc_Rloc.OUT"][n]))
            for n in sorted(found["DOF.OUT"])]
