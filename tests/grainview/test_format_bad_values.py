"""Bad values in other codes' files, made by mutating the project's own fixtures (tests/data/): each
reader refuses a value that is not finite or is absurd (grainview.formats.checks) in one line
naming the file, the line or entry and the quantity, or writes the file and says in one note
what it left out; a folder or a looping link where a file belongs is called what it is. Through
the command line: exit code 2, one line on stderr, no numpy warning, nothing written."""

from __future__ import annotations

import re
import shutil
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import grainview
from grainview.app.cli import main
from grainview.contract.errors import FileFormatError
from grainview.formats import lammps_dump
from grainview.formats.checks import Limits
from grainview.formats.convert import remove_dead_temporaries
from grainview.formats.lammps import convert_lammps, open_lammps
from grainview.formats.lmgc90 import open_lmgc90
from grainview.formats.peers import convert_peer

DATA = Path(__file__).resolve().parents[1] / "data"
LAMMPS, LMGC90, MERCURY, PEGS, PEERS = (DATA / name for name in ("lammps", "lmgc90", "mercurydpm", "pegs", "peers"))
LAMMPS_FILES = {"particles": "dump.particles", "contacts": "dump.contacts", "walls": "dump.walls", "log": "log.lammps"}


# --- running the command line ------------------------------------------------------------------

def _refused(argv, capsys, out):
    """``grainview ARGV`` in this process: exit code 2, one line on stderr and nothing else (no
    numpy warning, no traceback), ``out`` not written, no hidden file left beside it."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        code = main([str(a) for a in argv])
    stdout, stderr = capsys.readouterr()
    lines = stderr.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("grainview: error: "), (code, stderr)
    assert not caught, [str(w.message) for w in caught]
    assert not Path(out).exists()
    assert [p.name for p in Path(out).parent.iterdir() if p.name.startswith(".")] == []
    return lines[0]


def _converts(argv, capsys, out):
    """``grainview ARGV`` in this process: exit code 0, stderr empty; returns stdout."""
    code = main([str(a) for a in argv])
    stdout, stderr = capsys.readouterr()
    assert code == 0 and stderr == "", stderr
    assert Path(out).exists()
    return stdout


# --- LAMMPS -------------------------------------------------------------------------------------

def _lammps(tmp_path, name="run", **edits):
    """A copy of the LAMMPS fixtures in ``tmp_path/name`` with ``edits`` (file key -> function of
    the text) applied; returns {key: path}."""
    folder = tmp_path / name
    folder.mkdir()
    files = {}
    for key, file in LAMMPS_FILES.items():
        text = (LAMMPS / file).read_text()
        (folder / file).write_text(edits[key](text) if key in edits else text)
        files[key] = folder / file
    return files


def _lammps_argv(files, out):
    return ["convert", "lammps", "--particles", files["particles"], "--contacts", files["contacts"], "--walls",
            files["walls"], "--log", files["log"], "--out", out, "--progress", "off"]


def _row(text, step, column, value, pick=lambda values: True):
    """``text`` (a dump) with ``column`` of the first row of the snapshot at ``step`` for which
    ``pick(values)`` holds set to ``value``; returns (text, the row's line number)."""
    lines = text.split("\n")
    start = lines.index(str(step), lines.index("ITEM: TIMESTEP")) + 8  # the rows follow the ATOMS/ENTRIES line
    assert lines[start - 1].startswith("ITEM: ")
    for k in range(start, len(lines)):
        values = lines[k].split()
        if pick(values):
            values[column] = value
            lines[k] = " ".join(values)
            return "\n".join(lines), k + 1
    raise AssertionError("no such row")


def _edit(step, column, value, pick=lambda values: True, where=None):
    """An edit for :func:`_lammps`, recording the edited line in ``where`` (a dict)."""
    def edit(text):
        text, line = _row(text, step, column, value, pick)
        if where is not None:
            where["line"] = line
        return text
    return edit


TOUCHING = lambda values: float(values[1]) == 1.0  # noqa: E731  (a walls row whose f_floor[1] flag is set)


@pytest.mark.parametrize("key, column, value, pick, message", [
    # c_pairs[1] c_pairs[2] c_forces[1] (dist) c_forces[2] (fx) ...: fx is the 4th value of a pairs row
    ("contacts", 3, "nan", lambda v: True, "fx = nan; expected a finite force"),
    ("contacts", 3, "1e308", lambda v: True, "fx = 1e+308; expected a finite force of at most"),
    # id type radius mass x y ...: x is the 5th value of a particles row
    ("particles", 4, "1e308", lambda v: True, "x = 1e+308; expected a finite coordinate within 1e+06 particle "
                                              "diameters"),
    ("particles", 4, "nan", lambda v: True, "x = nan; expected a finite coordinate"),
    # id f_floor[1] (touching) f_floor[2] (fx) f_floor[3] (fy) ...
    ("walls", 3, "nan", TOUCHING, "f_floor[3] = nan; expected a finite force"),
])
def test_lammps_refuses_a_value_that_is_not_finite_or_absurd(tmp_path, capsys, key, column, value, pick, message):
    """A NaN force was read as tensile and its pairs dropped under that warning, 1e308 stored as
    fn 9.9e307, an atom at x = 1e308 stored with no message, NaN x called 'a wall that is not an
    x or y plane'; now each is refused in one line naming the dump, the step, the line and the
    column."""
    where = {}
    files = _lammps(tmp_path, **{key: _edit(40000, column, value, pick, where)})
    out = tmp_path / "run.nc"
    line = _refused(_lammps_argv(files, out), capsys, out)
    assert line.startswith(f"grainview: error: {files[key]}: step 40000: line {where['line']}: {message}"), line
    with pytest.raises(FileFormatError, match=re.escape(f"line {where['line']}: {message}")):
        open_lammps(files["particles"], files["contacts"], files["walls"], log=files["log"])


def test_lammps_names_the_dump_whose_rows_outnumber_its_count(tmp_path, capsys):
    """220 rows under a count of 219: the particles dump is named, not the walls dump whose
    atom 220 the particles seemed to lack."""
    files = _lammps(tmp_path, particles=lambda t: t.replace("ITEM: NUMBER OF ATOMS\n220\n",
                                                           "ITEM: NUMBER OF ATOMS\n219\n", 1))
    out = tmp_path / "run.nc"
    line = _refused(_lammps_argv(files, out), capsys, out)
    assert line == (f"grainview: error: {files['particles']}: line 229: snapshot 0 (step 0): more rows than the 219 "
                    "announced (a damaged dump)")


def test_lammps_stops_reading_at_the_end_of_the_file(tmp_path, monkeypatch):
    """A count of a billion rows in the last snapshot: one line as soon as the file ends, not a
    read per announced row after its end (which hung, its memory growing)."""
    last = "ITEM: TIMESTEP\n60000\nITEM: NUMBER OF ATOMS\n"
    files = _lammps(tmp_path, particles=lambda t: t.replace(last + "220\n", last + "1000000000\n"))
    real_open = open

    class Counting:
        """The dump, refusing to be read on past its end more than a few times."""

        def __init__(self, *args, **kwargs):
            self.fh, self.after_end = real_open(*args, **kwargs), 0

        def readline(self):
            line = self.fh.readline()
            self.after_end += not line
            assert self.after_end < 10, "read on after the end of the file"
            return line

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.fh.close()

    monkeypatch.setattr(lammps_dump, "open", Counting, raising=False)
    with pytest.raises(FileFormatError, match=r"snapshot 3 \(step 60000\): 1000000000 rows announced, 220 found "
                                              r"\(a truncated dump\)"):
        list(lammps_dump.iter_dump(files["particles"]))


def test_the_command_line_gives_a_warning_as_one_note(tmp_path, capsys):
    """A tensile wall contact left out: one 'note:' line on stdout, nothing on stderr (it was
    Python's UserWarning report, with the source file's path and line)."""
    files = _lammps(tmp_path)
    text = files["walls"].read_text()
    lines = text.split("\n")
    last = max(k for k, line in enumerate(lines) if line == "ITEM: TIMESTEP")
    for k in range(last + 9, len(lines)):
        values = lines[k].split()
        if values and TOUCHING(values):
            values[3] = repr(-float(values[3]))
            lines[k] = " ".join(values)
            break
    files["walls"].write_text("\n".join(lines))
    out = tmp_path / "run.nc"
    stdout = _converts(_lammps_argv(files, out), capsys, out)
    notes = [line for line in stdout.splitlines() if line.startswith("note: ")]
    assert len(notes) == 1 and "1 touching pair(s) over 4 snapshot(s) had a tensile normal force" in notes[0]


def test_a_contract_problem_found_at_the_end_names_the_users_file(tmp_path, capsys):
    """A box whose bounds are swapped passes the reader and fails the final contract check of
    the written file: the error names the file asked for (not written), not the hidden
    temporary file that is removed, whose 'info --check' advice could not be followed."""
    files = _lammps(tmp_path, particles=lambda t: t.replace(
        "0.0000000000000000e+00 1.4999999999999999e-01\n", "1.4999999999999999e-01 0.0000000000000000e+00\n"))
    out = tmp_path / "run.nc"
    line = _refused(_lammps_argv(files, out), capsys, out)
    assert line.startswith(f"grainview: error: {out}: not written: the run read breaks the grainview data "
                           "contract: box_min, box_max: 4 snapshot(s) where the box is not finite with box_max "
                           "above"), line
    assert f".{out.name}." not in line and "info --check" not in line


def test_a_folder_or_a_looping_link_is_called_what_it_is(tmp_path, capsys):
    files = _lammps(tmp_path)
    out = tmp_path / "run.nc"
    files["contacts"].unlink()
    files["contacts"].mkdir()
    line = _refused(_lammps_argv(files, out), capsys, out)
    assert line == f"grainview: error: {files['contacts']}: a folder, not a file (expected a LAMMPS text dump)"
    files["contacts"].rmdir()
    files["contacts"].symlink_to(files["contacts"].name)  # a link to itself
    line = _refused(_lammps_argv(files, out), capsys, out)
    assert line == (f"grainview: error: {files['contacts']}: a symbolic link that loops back on itself (expected a "
                    "LAMMPS text dump)")


# --- LMGC90 -------------------------------------------------------------------------------------

def _lmgc90(tmp_path, run="sample", **edits):
    """A copy of an LMGC90 fixture run with ``edits`` (file path in the run -> function of the
    text) applied."""
    folder = tmp_path / run
    shutil.copytree(LMGC90 / run, folder)
    for name, edit in edits.items():
        path = folder / name
        path.write_text(edit(path.read_text()))
    return folder


def _lmgc90_argv(folder, out):
    return ["convert", "lmgc90", folder, "--out", out, "--progress", "off"]


def _first_dkdk_rln(text, value):
    """The first DKDKx entry's rln/H set to ``value``."""
    start = text.index("$icdan  DKDKx")
    head, tail = text[:start], text[start:]
    return head + re.sub(r"rln/H[ -]\d\.\d{7}D[-+]\d\d", f"rln/H{value}", tail, count=1)


def test_lmgc90_reports_tensile_contacts_it_leaves_out(tmp_path, capsys):
    """A pair with a negative rln/H was dropped without a word (the other readers say so); now
    one note counts it, and that pair alone is missing."""
    folder = _lmgc90(tmp_path, **{"OUTBOX/Vloc_Rloc.OUT.4": lambda t: _first_dkdk_rln(t, "-0.5372579D+05")})
    out = tmp_path / "run.nc"
    stdout = _converts(_lmgc90_argv(folder, out), capsys, out)
    assert ("note: 1 contact(s) over 4 snapshot(s) had a tensile normal force (rln/H < 0, which the contract's "
            "fn >= 0 cannot hold) and were left out of the contacts") in stdout.splitlines()
    with pytest.warns(UserWarning, match="1 contact"):
        pulled = open_lmgc90(folder)
    original = open_lmgc90(LMGC90 / "sample")
    assert int(pulled["contact_count"][-1]) == int(original["contact_count"][-1]) - 1
    assert (pulled["fn"].values[pulled["fn"].notnull().values] > 0).all()


def test_lmgc90_refuses_an_absurd_displacement(tmp_path, capsys):
    folder = _lmgc90(tmp_path, **{"OUTBOX/DOF.OUT.3": lambda t: t.replace("X(1)= ", "X(1)= 0.1D+309 #", 1)
                                  .replace(" #0.1413414D+00", "")})
    assert "X(1)= 0.1D+309  X(2)" in (folder / "OUTBOX/DOF.OUT.3").read_text()
    out = tmp_path / "run.nc"
    line = _refused(_lmgc90_argv(folder, out), capsys, out)
    assert line.startswith(f"grainview: error: {folder / 'OUTBOX/DOF.OUT.3'}: body 1: X(1) = 1e+308; expected a "
                           "finite length of at most 1e+06 particle diameters"), line


def test_lmgc90_refuses_a_repeated_entry(tmp_path, capsys):
    """The first $icdan block written twice was read as a double contact with twice the force."""
    def repeat(text):
        start = text.index("$icdan")
        end = text.index("$icdan", start + 1)
        return text[:end] + text[start:end] + text[end:]

    folder = _lmgc90(tmp_path, **{"OUTBOX/Vloc_Rloc.OUT.4": repeat})
    out = tmp_path / "run.nc"
    line = _refused(_lmgc90_argv(folder, out), capsys, out)
    assert line == (f"grainview: error: {folder / 'OUTBOX/Vloc_Rloc.OUT.4'}: line 16: a second '$icdan DKDKx 1' (the "
                    "first at line 7); each entry is written once")


@pytest.mark.parametrize("file", ["DATBOX/BODIES.DAT", "OUTBOX/DOF.OUT.2", "OUTBOX/Vloc_Rloc.OUT.2"])
def test_lmgc90_refuses_a_body_number_too_large_for_an_integer(tmp_path, capsys, file):
    """A body number of 23 digits raised numpy's OverflowError (a 22-line traceback), through
    open_dataset and xr.open_dataset too."""
    def renumber(text):
        if file.endswith("BODIES.DAT"):
            return text.replace(" RBDY2      1\n", " RBDY2      99999999999999999999999\n", 1)
        if "DOF" in file:
            return text.replace(" RBDY2        1\n", " RBDY2        99999999999999999999999\n", 1)
        return re.sub(r"RBDY2 +(\d+)  DISKx", "RBDY2 99999999999999999999999  DISKx", text, count=1)

    folder = _lmgc90(tmp_path, **{file: renumber})
    assert "99999999999999999999999" in (folder / file).read_text()
    out = tmp_path / "run.nc"
    line = _refused(_lmgc90_argv(folder, out), capsys, out)
    assert "body number '99999999999999999999999'; expected an integer from 1 to 2147483647" in line, line
    assert str(folder / file) in line
    for opener in (lambda: grainview.open_dataset(folder, format="lmgc90"),
                   lambda: xr.open_dataset(folder, engine="lmgc90")):
        with pytest.raises(FileFormatError, match="body number '99999999999999999999999'"):
            opener()


def test_lmgc90_calls_a_folder_where_a_file_belongs_a_folder(tmp_path, capsys):
    folder = _lmgc90(tmp_path)
    (folder / "OUTBOX/DOF.OUT.2").unlink()
    (folder / "OUTBOX/DOF.OUT.2").mkdir()
    out = tmp_path / "run.nc"
    line = _refused(_lmgc90_argv(folder, out), capsys, out)
    assert line == (f"grainview: error: {folder / 'OUTBOX/DOF.OUT.2'}: a folder, not a file (expected an LMGC90 text "
                    "file)")


# --- MercuryDPM ---------------------------------------------------------------------------------

def _mercury(tmp_path, **edits):
    folder = tmp_path / "mercury"
    folder.mkdir()
    for suffix in ("data", "fstat", "restart"):
        text = (MERCURY / f"Settle2D.{suffix}").read_text()
        (folder / f"Settle2D.{suffix}").write_text(edits[suffix](text) if suffix in edits else text)
    return folder / "Settle2D.data"


def _mercury_argv(data, out):
    return ["convert", "mercurydpm", data, "--units", "si", "--out", out, "--progress", "off"]


def _set(text, line, column, value):
    """``text`` with value ``column`` of line ``line`` (1-based) replaced."""
    lines = text.split("\n")
    values = lines[line - 1].split()
    values[column] = value
    lines[line - 1] = " ".join(values)
    return "\n".join(lines)


def test_mercurydpm_refuses_a_position_of_1e308(tmp_path, capsys):
    data = _mercury(tmp_path, data=lambda t: _set(t, 36, 0, "1e308"))  # the second snapshot's third particle
    out = tmp_path / "run.nc"
    line = _refused(_mercury_argv(data, out), capsys, out)
    assert line == (f"grainview: error: {data}: t = 5 (line 34): line 36: x = 1e+308; expected a finite coordinate "
                    "within 1e+06 particle diameters (1.19e+06 m) of the sample's middle")


def test_mercurydpm_refuses_a_force_of_1e308(tmp_path, capsys):
    """On a wall contact's line (written once: a particle pair's two lines would disagree)."""
    fstat = (MERCURY / "Settle2D.fstat").read_text().split("\n")
    line_number = next(k + 1 for k, line in enumerate(fstat) if not line.startswith("#") and line.split()[2] == "-1")
    data = _mercury(tmp_path, fstat=lambda t: _set(t, line_number, 8, "1e308"))
    out = tmp_path / "run.nc"
    line = _refused(_mercury_argv(data, out), capsys, out)
    assert f"Settle2D.fstat: t = 5 (line 4): line {line_number}: fn = 1e+308; expected a finite force of at most" \
        in line, line


def test_mercurydpm_calls_a_looping_link_what_it_is(tmp_path, capsys):
    data = _mercury(tmp_path)
    fstat = data.with_suffix(".fstat")
    fstat.unlink()
    fstat.symlink_to(fstat.name)
    out = tmp_path / "run.nc"
    line = _refused(_mercury_argv(data, out), capsys, out)
    assert line == (f"grainview: error: {fstat}: a symbolic link that loops back on itself (expected MercuryDPM's "
                    ".fstat file)")


# --- PeGS2 --------------------------------------------------------------------------------------

def _pegs(tmp_path, adjacency=None, positions=None):
    folder = tmp_path / "pegs"
    folder.mkdir()
    for name, edit in (("Adjacency_list.txt", adjacency), ("particle_positions.txt", positions)):
        text = (PEGS / name).read_text()
        (folder / name).write_text(edit(text) if edit else text)
    return folder / "Adjacency_list.txt", folder / "particle_positions.txt"


def _pegs_argv(adjacency, positions, out):
    return ["convert", "pegs", adjacency, "--positions", positions, "--metres-per-pixel", "4.375e-5",
            "--force-unit-n", "1", "--out", out, "--progress", "off"]


def _csv(text, line, column, value):
    lines = text.split("\n")
    values = lines[line - 1].split(",")
    values[column] = value
    lines[line - 1] = ",".join(values)
    return "\n".join(lines)


@pytest.mark.parametrize("which, column, expected", [
    ("positions", 2, "particle_positions.txt: line 3: x = 1e+308; expected a finite coordinate within 1e+06 particle "
                     "diameters"),
    ("adjacency", 4, "Adjacency_list.txt: frame 1, ids 12 and 3: normal force = 1e+308; expected a finite force of "
                     "at most"),
])
def test_pegs_refuses_a_value_of_1e308(tmp_path, capsys, which, column, expected):
    edit = lambda t: _csv(t, 3, column, "1e308")  # noqa: E731
    adjacency, positions = _pegs(tmp_path, **{which: edit})
    out = tmp_path / "run.nc"
    line = _refused(_pegs_argv(adjacency, positions, out), capsys, out)
    assert expected in line, line


def test_pegs_refuses_an_empty_adjacency_list(tmp_path, capsys):
    """It gave a frame of 0 contacts and no word."""
    adjacency, positions = _pegs(tmp_path, adjacency=lambda t: "")
    out = tmp_path / "run.nc"
    line = _refused(_pegs_argv(adjacency, positions, out), capsys, out)
    assert line == (f"grainview: error: {adjacency}: no contact at all (an empty adjacency list); expected rows frame, "
                    "id1, id2, tangential force, normal force")


def test_pegs_notes_a_frame_without_contacts(tmp_path, capsys):
    """A second frame of the same disks with no row in the adjacency list: written without
    contacts, with one note naming it."""
    def second_frame(text):
        rows = [line for line in text.splitlines() if line.strip()]
        return text + "\n".join("2" + row[row.index(","):] for row in rows) + "\n"

    adjacency, positions = _pegs(tmp_path, positions=second_frame)
    out = tmp_path / "run.nc"
    stdout = _converts(_pegs_argv(adjacency, positions, out), capsys, out)
    assert (f"note: 1 frame(s) of {positions} (frame 2) have no row in {adjacency} and are written without "
            "contacts") in stdout.splitlines()
    assert len([line for line in stdout.splitlines() if line.startswith("note: ")]) == 1, stdout  # said once
    assert grainview.open_dataset(out, chunks=None)["contact_count"].values[1] == 0


def test_pegs_calls_a_folder_where_a_file_belongs_a_folder(tmp_path, capsys):
    adjacency, positions = _pegs(tmp_path)
    positions.unlink()
    positions.mkdir()
    out = tmp_path / "run.nc"
    line = _refused(_pegs_argv(adjacency, positions, out), capsys, out)
    assert line == f"grainview: error: {positions}: a folder, not a file (expected PeGS2's particle positions)"


# --- Box2D and pymunk (the cross-check's raw snapshots) -------------------------------------------

def _peer(tmp_path, edit=None):
    folder = tmp_path / "box2d"
    shutil.copytree(PEERS / "box2d", folder)
    if edit is not None:
        path = folder / "snap_000003.npz"
        with np.load(path) as data:
            arrays = {k: data[k].copy() for k in data.files}
        edit(arrays)
        np.savez(path, **arrays)
    return folder


@pytest.mark.parametrize("name, value, expected", [
    ("position", 1e308, "particle 4: position = 1e+308; expected a finite coordinate within 1e+06 particle diameters"),
    ("force", np.nan, "contact 2: force = nan; expected a finite force"),
    ("velocity", np.inf, "particle 4: velocity = inf; expected a finite speed below the speed of light"),
])
def test_the_peers_reader_refuses_a_value_that_is_not_finite_or_absurd(tmp_path, name, value, expected):
    def spoil(arrays):
        arrays[name][2 if name == "force" else 4, 0] = value

    folder = _peer(tmp_path, spoil)
    out = tmp_path / "run.nc"
    with pytest.raises(FileFormatError) as info:
        convert_peer(out, folder, PEERS / "sample.npz", engine="box2d")
    assert str(info.value).startswith(f"{folder / 'snap_000003.npz'}: {expected}"), str(info.value)
    assert not out.exists() and [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_the_peers_reader_calls_a_folder_where_the_sample_belongs_a_folder(tmp_path):
    folder = _peer(tmp_path)
    with pytest.raises(FileFormatError, match=re.escape(f"{folder}: a folder, not a file (expected a cross-check "
                                                        "sample)")):
        convert_peer(tmp_path / "run.nc", folder, folder, engine="box2d")


# --- what "absurd" means ------------------------------------------------------------------------

def test_the_limits_follow_the_sample():
    """A coordinate is measured from the sample's middle, a force against a stress on the
    largest diameter; radii spanning more than a million-fold and impossible densities are
    refused."""
    limits = Limits([0.01, 0.02], thickness=1.0, where="f")
    limits.check([[1000.0, 1000.0], [1000.04, 1000.0]], ("x", "y"), "position", "f")  # far from 0 m, not absurd
    limits.check([[1000.0 + 3e4, 0.0]], ("x", "y"), "position", "f", centre=[1000.0, 0.0])
    with pytest.raises(FileFormatError, match="row 1: x = 50000; expected a finite coordinate within 1e\\+06 "
                                              "particle diameters \\(4e\\+04 m\\)"):
        limits.check([[5e4, 0.0]], ("x", "y"), "position", "f", centre=[0.0, 0.0])
    limits.check([3.9e10], "fn", "force", "f")
    with pytest.raises(FileFormatError, match="row 1: fn = 4.1e\\+10; expected a finite force of at most 4e\\+10 N"):
        limits.check([4.1e10], "fn", "force", "f")
    with pytest.raises(FileFormatError, match="fn = 4.1e\\+07; expected a finite force"):
        limits.check([4.1e7], "fn", "force", "f", scale=1e3)  # in kN
    with pytest.raises(FileFormatError, match="largest at most 1e\\+06 times the smallest"):
        Limits([1e-7, 1.0])
    with pytest.raises(FileFormatError, match="particle 0: mass = 1e\\+20 kg"):
        Limits([0.01], mass=[1e20])


# --- interrupted conversions --------------------------------------------------------------------

# The conversion, run through the command line in another process, holds still in the middle of
# its snapshots (after writing two, before checking the third): it touches ``paused`` and sleeps,
# so that the signal reaches it there whatever the machine's speed or load.
_PAUSED_CONVERSION = """
import sys, time
from pathlib import Path
import grainview.formats.convert as convert
from grainview.app.cli import main

paused, checked, count = Path(sys.argv[1]), convert.check_snapshot, [0]

def check_snapshot(*args, **kwargs):
    if count[0] == 2:
        paused.touch()
        time.sleep(120)
    count[0] += 1
    return checked(*args, **kwargs)

convert.check_snapshot = check_snapshot
sys.exit(main(sys.argv[2:]))
"""


def _hidden(folder):
    return sorted(p.name for p in Path(folder).iterdir() if p.name.startswith("."))


def _start_and_stop(argv, paused, signum):
    """Start ``grainview ARGV`` (a conversion) held in the middle of its snapshots, send
    ``signum`` once it is held there; return the process, ended."""
    command = [sys.executable, "-c", _PAUSED_CONVERSION, str(paused), *map(str, argv)]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not paused.exists():
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline
        time.sleep(0.01)
    process.send_signal(signum)
    process.stdout_text, process.stderr_text = process.communicate(timeout=120)
    return process


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGKILL])
def test_an_interrupted_conversion_leaves_nothing(tmp_path, signum):
    """SIGTERM is handled as Ctrl-C: the temporary files are removed before the process ends
    (exit 143). SIGKILL cannot be handled: the next conversion to the same file removes what
    the killed one left, and writes the file."""
    files = _lammps(tmp_path, "run")
    out_folder = tmp_path / "out"
    out_folder.mkdir()
    out = out_folder / "run.nc"
    argv = _lammps_argv(files, out)
    process = _start_and_stop(argv, tmp_path / "paused", signum)
    if signum == signal.SIGTERM:
        assert process.returncode == 143, process.stderr_text
        assert process.stderr_text.strip() == "grainview: terminated (SIGTERM)"
        assert _hidden(out_folder) == [] and not out.exists()
    else:
        assert process.returncode == -signal.SIGKILL
        assert [name for name in _hidden(out_folder) if name.startswith(".run.nc.")]  # what a kill leaves
    done = subprocess.run([sys.executable, "-m", "grainview", *map(str, argv)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert _hidden(out_folder) == [] and out.exists()
    assert xr.open_dataset(out).sizes["time"] == 4  # the fixture's snapshots, all of them


def test_only_dead_processes_temporary_files_are_removed(tmp_path):
    """A live conversion's temporary file, a user's hidden file and another output's are kept."""
    alive = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    dead = int(gone.stdout)
    try:
        names = [f".run.nc.{dead}.lammps", f"..run.nc.{dead}.lammps.{dead}.part", f"..run.nc.{dead}.lammps.writer",
                 f".run.nc.{alive.pid}.lmgc90", f".run.nc.{dead}.backup", f".other.nc.{dead}.pegs", "run.nc"]
        for name in names:
            (tmp_path / name).write_text("x")
        removed = remove_dead_temporaries(tmp_path / "run.nc")
        assert sorted(removed) == sorted(names[:3])
        assert sorted(p.name for p in tmp_path.iterdir()) == sorted(names[3:])
    finally:
        alive.kill()
        alive.wait()


def test_a_conversion_refuses_another_writers_file(tmp_path):
    """A conversion holds its output's writer's lock: a second one to the same file is refused."""
    from grainview.contract.locks import FileLockedError, WriterLock

    files = _lammps(tmp_path)
    out = tmp_path / "run.nc"
    with WriterLock(out):
        with pytest.raises(FileLockedError, match="is being written by"):
            convert_lammps(out, files["particles"], files["contacts"], files["walls"], log=files["log"])
    assert not out.exists()
