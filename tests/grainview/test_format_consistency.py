"""Input that is well formed line by line but impossible as a whole, made by mutating the
project's own fixtures (tests/data/) as tests/grainview/test_format_bad_values.py does: contacts
that cannot exist for the bodies' positions and sizes (grainview.formats.checks.check_contacts),
step indices the contract cannot hold, files cut between rows, pairs written on one side only,
bodies written twice, an output that would replace an input. Each is refused in one line
naming the file, the snapshot and the bodies (exit code 2, nothing written), or written with
one note per kind of thing left out; nothing raises a traceback or a raw numpy warning."""

from __future__ import annotations

import re

import numpy as np
import pytest

import grainview
from grainview.app.cli import main
from grainview.contract.errors import FileFormatError
from grainview.formats.lammps import open_lammps

from .test_format_bad_values import (LAMMPS, MERCURY, PEERS, _converts, _lammps, _lammps_argv, _lmgc90, _lmgc90_argv,
                                     _mercury, _mercury_argv, _peer, _pegs, _pegs_argv, _refused, _set)


# --- LAMMPS -------------------------------------------------------------------------------------

def _snapshot_rows(lines, k):
    """The line indices of the rows of snapshot ``k`` of a dump's lines."""
    start = [n for n, line in enumerate(lines) if line.startswith("ITEM: TIMESTEP")][k]
    return range(start + 9, start + 9 + int(lines[start + 3]))


def _particle(text, k, pick):
    """The row (split) of snapshot ``k`` of a particles dump for which ``pick(rows)`` chooses."""
    lines = text.split("\n")
    return pick([lines[n].split() for n in _snapshot_rows(lines, k)])


def _replace_rows(text, k, edit):
    """``text`` (a dump) with ``edit(values)`` applied to each row of snapshot ``k`` (a row it
    returns None for is kept)."""
    lines = text.split("\n")
    for n in _snapshot_rows(lines, k):
        values = edit(lines[n].split())
        if values is not None:
            lines[n] = " ".join(values)
    return "\n".join(lines)


def test_lammps_refuses_a_wall_contact_of_a_particle_far_from_the_wall(tmp_path, capsys):
    """The walls dump says the highest atom touches the floor (force 5 N at (x, 0)) while it is
    0.09 m up: it was stored as a floor contact with a gap of 18 radii and 'info --check' said
    valid. Now refused, naming the walls dump, the step and the atom."""
    top = _particle((LAMMPS / "dump.particles").read_text(), 3, lambda rows: max(rows, key=lambda v: float(v[5])))

    def on_floor(values):
        if values[0] == top[0]:
            values[1:9] = ["1", "0", "5", "0", top[4], "0", "0", "0"]
            return values
        return None

    files = _lammps(tmp_path, walls=lambda t: _replace_rows(t, 3, on_floor))
    out = tmp_path / "run.nc"
    line = _refused(_lammps_argv(files, out), capsys, out)
    assert line.startswith(f"grainview: error: {files['walls']}: step 60000: the contact of atom {top[0]} and the "
                           "wall of fix floor: the contact point is "), line
    assert f"from the centre of atom {top[0]}, whose radius is" in line and "expected a point on the particle" in line
    with pytest.raises(FileFormatError, match=f"the contact of atom {top[0]} and the wall of fix floor"):
        open_lammps(files["particles"], files["contacts"], files["walls"], log=files["log"])


def test_lammps_refuses_an_overlap_deeper_than_a_radius(tmp_path, capsys):
    """An atom moved onto the centre of a neighbour it is listed with: an overlap of r_i + r_j
    was stored as a contact."""
    lines = (LAMMPS / "dump.contacts").read_text().split("\n")
    first, second = lines[_snapshot_rows(lines, 3)[0]].split()[:2]
    target = _particle((LAMMPS / "dump.particles").read_text(), 3, lambda rows: next(v for v in rows
                                                                                     if v[0] == second))

    def onto(values):
        if values[0] == first:
            values[4:6] = target[4:6]
            return values
        return None

    files = _lammps(tmp_path, particles=lambda t: _replace_rows(t, 3, onto))
    out = tmp_path / "run.nc"
    line = _refused(_lammps_argv(files, out), capsys, out)
    low, high = sorted((int(first), int(second)))
    assert line.startswith(f"grainview: error: {files['contacts']}: step 60000: the contact of atom {low} and atom "
                           f"{high}: an overlap of "), line
    assert "expected an overlap shallower than a radius" in line


def test_lammps_refuses_a_step_the_contract_cannot_hold(tmp_path, capsys):
    """Steps beyond 2^31 - 1 (a long run, reset_timestep) raised OverflowError from the writer
    (a traceback) while open_dataset read them: both now refuse in one line naming it."""
    steps = {"0": "0", "20000": "2147483647", "40000": "2147503647", "60000": "2147523647"}

    def renumber(text):
        lines = text.split("\n")
        for n, line in enumerate(lines):
            if line == "ITEM: TIMESTEP":
                lines[n + 1] = steps[lines[n + 1]]
        return "\n".join(lines)

    files = _lammps(tmp_path, particles=renumber, contacts=renumber, walls=renumber)
    out = tmp_path / "run.nc"
    line = _refused(_lammps_argv(files, out), capsys, out)
    assert line == (f"grainview: error: {files['particles']}: step = 2147503647; expected an integer from 0 to "
                    "2147483647 (the contract stores the step index as a 32-bit integer; renumber the run's steps "
                    "from 0, e.g. LAMMPS's reset_timestep, to read it)")
    with pytest.raises(FileFormatError, match="step = 2147503647; expected an integer from 0 to 2147483647"):
        open_lammps(files["particles"], files["contacts"], files["walls"], log=files["log"])


def test_lammps_refuses_a_run_without_atoms(tmp_path, capsys):
    """Every dump with 0 atoms raised numpy's 'zero-size array' ValueError (a traceback)."""
    def empty(text):
        lines = text.split("\n")
        out, skip = [], 0
        for n, line in enumerate(lines):
            if skip:
                skip -= 1
                continue
            if line.startswith("ITEM: NUMBER OF"):
                out += [line, "0"]
                rows = int(lines[n + 1])
                out += lines[n + 2:n + 7]  # the box and the ATOMS or ENTRIES line
                skip = 1 + 5 + rows
                continue
            out.append(line)
        return "\n".join(out)

    files = _lammps(tmp_path, particles=empty, contacts=empty, walls=empty)
    out = tmp_path / "run.nc"
    line = _refused(_lammps_argv(files, out), capsys, out)
    assert line == (f"grainview: error: {files['particles']}: step 0: no atoms (NUMBER OF ATOMS 0); expected the "
                    "particles of the run in every snapshot")


def test_lammps_refuses_a_dump_cut_inside_its_last_row(tmp_path, capsys):
    """With y last, a dump cut inside the last row's y was read with y = 0.0 for that atom (two
    contacts lost, no word): LAMMPS ends every row with a newline, so a last row without one is
    cut."""
    def y_last(text):
        out, rows, index = [], False, None
        for line in text.split("\n"):
            if line.startswith("ITEM: ATOMS"):
                header = line.split()[2:]
                index = header.index("y")
                header.append(header.pop(index))
                out.append("ITEM: ATOMS " + " ".join(header))
                rows = True
                continue
            if line.startswith("ITEM:"):
                rows = False
            if rows and line.strip():
                values = line.split()
                values.append(values.pop(index))
                line = " ".join(values)
            out.append(line)
        text = "\n".join(out).rstrip("\n")
        return text[:text.rfind(" ") + 4]  # "0.0" of the last y

    files = _lammps(tmp_path, particles=y_last)
    out = tmp_path / "run.nc"
    line = _refused(_lammps_argv(files, out), capsys, out)
    assert line.startswith(f"grainview: error: {files['particles']}: line ") and line.endswith(
        "snapshot 3 (step 60000): the last row ends without a newline (a truncated dump: LAMMPS ends every row with "
        "one, and a cut row may have lost digits)"), line


def test_lammps_refuses_a_log_without_units(tmp_path, capsys):
    """A log without a 'units' command is a run in LAMMPS's default lj units: it was read as SI."""
    files = _lammps(tmp_path, log=lambda t: re.sub(r"(?m)^units.*\n", "", t))
    out = tmp_path / "run.nc"
    line = _refused(_lammps_argv(files, out), capsys, out)
    assert line == (f"grainview: error: {files['log']}: no 'units' command, so the run is in LAMMPS's default units, "
                    "lj (reduced units); only runs in SI units (units si) can be read")


def test_lammps_says_that_without_a_log_si_is_assumed(tmp_path, capsys):
    files = _lammps(tmp_path)
    out = tmp_path / "run.nc"
    argv = _lammps_argv(files, out)
    at = argv.index("--log")
    argv[at:at + 2] = ["--time-step", "5e-6", "--columns", "patom1=c_pairs[1],patom2=c_pairs[2],fx=c_forces[2],"
                       "fy=c_forces[3],p1=c_forces[5],p2=c_forces[6]"]
    stdout = _converts(argv, capsys, out)
    assert ("note: no LAMMPS log given: the run is taken to be in SI units (units si), which only its log can "
            "confirm (log=..., --log)") in stdout.splitlines()


def test_lammps_refuses_a_box_that_does_not_hold_the_particles(tmp_path, capsys):
    """A box 1e-7 m wide in x (the volume of the solid fraction and the stresses) was accepted
    while the particles span 0.15 m."""
    files = _lammps(tmp_path, particles=lambda t: t.replace(
        "ITEM: BOX BOUNDS ff ff pp\n0.0000000000000000e+00 1.4999999999999999e-01\n",
        "ITEM: BOX BOUNDS ff ff pp\n0.07 0.0700001\n"))
    out = tmp_path / "run.nc"
    line = _refused(_lammps_argv(files, out), capsys, out)
    assert line.startswith(f"grainview: error: {files['particles']}: step 0: atom 1 at x = 0.0115147 lies outside "
                           "the box's x range 0.07 .. 0.0700001 (ITEM: BOX BOUNDS); expected the particles inside the "
                           "box"), line


def test_lammps_refuses_a_self_pair_and_notes_a_loaded_pair_that_does_not_touch(tmp_path, capsys):
    """A pair of an atom with itself, and a pair 50 N strong whose disks do not overlap, were
    dropped without a word."""
    lines = (LAMMPS / "dump.contacts").read_text().split("\n")
    rows = _snapshot_rows(lines, 3)
    position = {v[0]: (float(v[4]), float(v[5]), float(v[2])) for v in (
        line.split() for line in (LAMMPS / "dump.particles").read_text().split("\n")[-221:-1])}
    apart = next(n for n in rows if (lambda a, b: np.hypot(a[0] - b[0], a[1] - b[1]) > a[2] + b[2])(
        position[lines[n].split()[0]], position[lines[n].split()[1]]))

    def loaded(text):
        lines = text.split("\n")
        values = lines[apart].split()
        values[3] = "50"
        lines[apart] = " ".join(values)
        return "\n".join(lines)

    files = _lammps(tmp_path, contacts=loaded)
    out = tmp_path / "run.nc"
    stdout = _converts(_lammps_argv(files, out), capsys, out)
    assert ("note: 1 pair(s) over 4 snapshot(s) whose disks do not overlap at the dumped positions carried a force "
            "and were left out of the contacts (LAMMPS's granular pair styles give no force to pairs that do not "
            "touch: positions dumped with too few digits? dump_modify format float %.17g)") in stdout.splitlines()

    def itself(text):
        lines = text.split("\n")
        values = lines[rows[0]].split()
        values[1] = values[0]
        lines[rows[0]] = " ".join(values)
        return "\n".join(lines)

    files = _lammps(tmp_path, "self", contacts=itself)
    out = tmp_path / "self.nc"
    line = _refused(_lammps_argv(files, out), capsys, out)
    assert line.startswith(f"grainview: error: {files['contacts']}: step 60000: line {rows[0] + 1}: a pair of atom "
                           ) and line.endswith("with itself; expected pairs of two atoms"), line


def test_lammps_names_an_atom_written_twice_in_the_walls_dump(tmp_path, capsys):
    """A walls dump listing an atom twice was called 'a wall that is not an x or y plane'."""
    def twice(text):
        lines = text.split("\n")
        rows = _snapshot_rows(lines, 3)
        lines[rows[1]] = lines[rows[0]]
        return "\n".join(lines)

    files = _lammps(tmp_path, walls=twice)
    lines = files["walls"].read_text().split("\n")
    atom = lines[_snapshot_rows(lines, 3)[0]].split()[0]
    out = tmp_path / "run.nc"
    line = _refused(_lammps_argv(files, out), capsys, out)
    assert line == (f"grainview: error: {files['walls']}: step 60000: atom id {atom} appears twice; expected each "
                    "atom once")


@pytest.mark.parametrize("key", ["particles", "log"])
def test_a_conversion_refuses_to_write_over_its_input(tmp_path, capsys, key):
    """`--out dump.particles --overwrite` replaced the dump with the converted file (exit 0)."""
    files = _lammps(tmp_path)
    before = files[key].read_bytes()
    argv = _lammps_argv(files, files[key]) + ["--overwrite"]
    code = main([str(a) for a in argv])
    stderr = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and stderr == [f"grainview: error: {files[key]} is an input of the conversion ({files[key]}); "
                                    "expected another file name for the output, which would replace it"], stderr
    assert files[key].read_bytes() == before
    assert [p.name for p in files[key].parent.iterdir() if p.name.startswith(".")] == []


# --- MercuryDPM ---------------------------------------------------------------------------------

def _fstat_lines():
    return (MERCURY / "Settle2D.fstat").read_text().split("\n")


def _pair_lines(lines, start=0):
    """The 1-based numbers of the two lines of the first particle pair at or after line ``start``."""
    for n in range(start, len(lines) - 1):
        a, b = lines[n].split(), lines[n + 1].split()
        if a and not lines[n].startswith("#") and int(b[1]) == int(a[2]) and int(b[2]) == int(a[1]) >= 0:
            return n + 1, n + 2
    raise AssertionError("no pair")


def test_mercurydpm_refuses_contacts_of_a_particle_far_away(tmp_path, capsys):
    """A particle moved a million metres away kept its .fstat contacts (branches of 1.1e6 m)."""
    data = _mercury(tmp_path, data=lambda t: _set(t, 137, 1, "1.1e6"))  # particle 3 at t = 20
    out = tmp_path / "run.nc"
    line = _refused(_mercury_argv(data, out), capsys, out)
    assert line.startswith(f"grainview: error: {data.with_suffix('.fstat')}: t = 20 (line ") and re.search(
        r": the contact of particle \d+ and particle \d+: the centres are 1\.1e\+06 m apart, the radii sum to ", line) \
        and "particle 3" in line, line


@pytest.mark.parametrize("column, value, message", [
    (6, "3.0", "an overlap of 3 m (gap -3 m), deeper than the radius"),  # 7 radii
    (3, "500", "the contact point is 4"),
])
def test_mercurydpm_refuses_an_impossible_wall_contact(tmp_path, capsys, column, value, message):
    """A wall line's overlap of 3.0 (7 radii) was stored as gap -3.0, a contact point 500 m
    away as it was."""
    lines = _fstat_lines()
    number = next(n + 1 for n, line in enumerate(lines) if n > 700 and not line.startswith("#") and line.split()
                  and int(line.split()[2]) < 0)
    data = _mercury(tmp_path, fstat=lambda t: _set(t, number, column, value))
    out = tmp_path / "run.nc"
    line = _refused(_mercury_argv(data, out), capsys, out)
    assert line.startswith(f"grainview: error: {data.with_suffix('.fstat')}: t = 40 (line 686): the contact of "
                           "particle ") and message in line and "(bottom)" in line, line


def test_mercurydpm_refuses_a_pair_written_on_one_side_only(tmp_path, capsys):
    """One line of a pair in a snapshot before the last: the pair was kept from that side."""
    first, _ = _pair_lines(_fstat_lines(), 700)
    data = _mercury(tmp_path, fstat=lambda t: "\n".join(line for n, line in enumerate(t.split("\n"), start=1)
                                                        if n != first))
    out = tmp_path / "run.nc"
    line = _refused(_mercury_argv(data, out), capsys, out)
    assert line.startswith(f"grainview: error: {data.with_suffix('.fstat')}: t = 40 (line 686): the pair of "
                           "particles ") and "is written on one side only" in line, line


def test_mercurydpm_leaves_out_a_last_snapshot_cut_between_a_pairs_lines(tmp_path, capsys):
    """An .fstat cut at a line boundary in its last snapshot was read with that snapshot's lost
    contacts missing and no word; a cut between the two lines of a pair now shows, and that
    snapshot is left out with a note."""
    first, _ = _pair_lines(_fstat_lines(), 800)
    data = _mercury(tmp_path, fstat=lambda t: "\n".join(t.split("\n")[:first]) + "\n",
                    data=lambda t: t)
    out = tmp_path / "run.nc"
    stdout = _converts(_mercury_argv(data, out), capsys, out)
    assert (f"note: {data.with_suffix('.fstat')}: its last snapshot (t = 40.001, line 791) has 1 particle pair(s) "
            "written on one side only, the mark of a file cut while it was written: that snapshot is left out") \
        in stdout.splitlines(), stdout
    assert grainview.open_dataset(out, chunks=None).sizes["time"] == 9


def test_mercurydpm_refuses_a_pair_whose_lines_disagree_on_the_overlap(tmp_path, capsys):
    """One line of a pair said overlap 2.69, the other 0.0027: one side's values were kept."""
    _, second = _pair_lines(_fstat_lines(), 700)
    data = _mercury(tmp_path, fstat=lambda t: _set(t, second, 6, "2.69"))
    out = tmp_path / "run.nc"
    line = _refused(_mercury_argv(data, out), capsys, out)
    assert "disagree (overlap " in line and "and 2.69, contact points" in line, line


@pytest.mark.parametrize("old, new, message", [
    ("Particles 32", "Particles 32.0", "line 19: 'Particles 32.0'; expected 'Particles <count>', a whole number"),
    ("Walls 4", "Walls four", "line 13: 'Walls four'; expected 'Walls <count>', a whole number"),
    ("Species 1", "Species nan", "line 11: 'Species nan'; expected 'Species <count>', a whole number"),
    ("systemDimensions 2", "systemDimensions nan", "line 10: systemDimensions nan; expected 1, 2 or 3"),
    ("systemDimensions 2", "systemDimensions inf", "line 10: systemDimensions inf; expected 1, 2 or 3"),
    ("particleDimensions 2", "particleDimensions 2.5", "line 10: particleDimensions 2.5; expected 1, 2 or 3"),
    ("Walls 4", "Walls 5", "line 18: expected wall 4 of 'Walls 5' ('<type> id <n> indSpecies <n> ...'), found "
                           "'Boundaries 0' (fewer wall lines than announced?)"),
    ("orientation 0.707106781186548 0 0 -0.707106781186548", "orientation nan 0 0 -0.707106781186548",
     "line 14: wall 0: orientation nan 0 0 -0.707107; expected finite numbers"),
])
def test_mercurydpm_refuses_a_restart_it_cannot_read(tmp_path, capsys, old, new, message):
    """Counts that are not whole numbers and dimensions that are not finite raised ValueError
    or OverflowError (tracebacks); 'particleDimensions 2.5' was read as 2; 'Walls 5' over 4
    wall lines made a wall of 'Boundaries 0'; a NaN orientation renamed the floor."""
    data = _mercury(tmp_path, restart=lambda t: t.replace(old, new, 1))
    out = tmp_path / "run.nc"
    line = _refused(_mercury_argv(data, out), capsys, out)
    assert line == f"grainview: error: {data.with_suffix('.restart')}: {message}"


def test_mercurydpm_refuses_an_absurd_unit(tmp_path, capsys):
    """time=1e300 raised OverflowError (a traceback) computing the unit of force."""
    data = _mercury(tmp_path)
    out = tmp_path / "run.nc"
    argv = _mercury_argv(data, out)
    argv[argv.index("si")] = "length=1,mass=1,time=1e300"
    line = _refused(argv, capsys, out)
    assert line == ("grainview: error: units: time=1e+300: expected the SI value of one unit of the run from 1e-30 to "
                    "1e+30 (s)")


# --- LMGC90 -------------------------------------------------------------------------------------

def _first_entry(text, old, new):
    """The first $icdan entry of a Vloc_Rloc.OUT with ``old`` (a regular expression) replaced."""
    start = text.index("$icdan")
    end = text.index("$icdan", start + 1)
    return text[:start] + re.sub(old, new, text[start:end], count=1) + text[end:]


@pytest.mark.parametrize("old, new, message", [
    (r"gapTT-0\.5546195D-06", "gapTT 0.5000000D+00", "a gap of 0.5 m between bodies in contact; expected a closed "
                                                      "contact"),
    (r"coo1= 0\.4657701D\+01", "coo1= 0.4657701D+03", "the contact point (465.77, 0.801088) m is "),
])
def test_lmgc90_refuses_an_impossible_contact(tmp_path, capsys, old, new, message):
    """A gapTT of +0.5 m under a force of 54 kN and a contact point 460 m away were stored."""
    folder = _lmgc90(tmp_path, **{"OUTBOX/Vloc_Rloc.OUT.4": lambda t: _first_entry(t, old, new)})
    out = tmp_path / "run.nc"
    line = _refused(_lmgc90_argv(folder, out), capsys, out)
    assert line.startswith(f"grainview: error: {folder / 'OUTBOX/Vloc_Rloc.OUT.4'}: the contact of body 4 and body "
                           "12: ") and message in line, line


def _body_block(text, number):
    match = re.search(rf"\$bdyty\n RBDY2 +{number}\n.*?\$\$\$\$\$\$\n", text, re.S)
    return match


def test_lmgc90_refuses_a_body_written_twice_in_dof_out(tmp_path, capsys):
    """Body 1's block written a second time, 0.77 m away: the second silently won."""
    def twice(text):
        match = _body_block(text, 1)
        return text[:match.end()] + match.group(0).replace("X(1)= 0.", "X(1)= 0.9", 1) + text[match.end():]

    folder = _lmgc90(tmp_path, **{"OUTBOX/DOF.OUT.2": twice})
    out = tmp_path / "run.nc"
    line = _refused(_lmgc90_argv(folder, out), capsys, out)
    assert line == (f"grainview: error: {folder / 'OUTBOX/DOF.OUT.2'}: line 14: a second block of body 1 (the first "
                    "at line 8); expected each body once")


def test_lmgc90_refuses_a_body_that_bodies_dat_does_not_have(tmp_path, capsys):
    """A DOF.OUT block of a body BODIES.DAT does not define was ignored without a word."""
    def extra(text):
        match = _body_block(text, 1)
        block = match.group(0).replace(" RBDY2        1\n", " RBDY2      999\n")
        return text[:match.end()] + block + text[match.end():]

    folder = _lmgc90(tmp_path, **{"OUTBOX/DOF.OUT.3": extra})
    out = tmp_path / "run.nc"
    line = _refused(_lmgc90_argv(folder, out), capsys, out)
    assert line == (f"grainview: error: {folder / 'OUTBOX/DOF.OUT.3'}: body 999 is not in "
                    f"{folder / 'DATBOX/BODIES.DAT'} (files of another run?); expected the bodies of BODIES.DAT")


def test_lmgc90_refuses_a_body_number_defined_twice(tmp_path, capsys):
    """Two bodies numbered 2 in BODIES.DAT: an entry on body 2 was called 'not a body'."""
    folder = _lmgc90(tmp_path, **{"DATBOX/BODIES.DAT": lambda t: t.replace(" RBDY2      3\n", " RBDY2      2\n", 1)})
    out = tmp_path / "run.nc"
    line = _refused(_lmgc90_argv(folder, out), capsys, out)
    assert line == (f"grainview: error: {folder / 'DATBOX/BODIES.DAT'}: body 2 is defined twice; expected each body "
                    "number once")


def test_lmgc90_refuses_files_of_one_step_at_two_times(tmp_path, capsys):
    folder = _lmgc90(tmp_path, **{"OUTBOX/Vloc_Rloc.OUT.4": lambda t: t.replace("time= 0.5000000D+01",
                                                                                "time= 0.7000000D+01", 1)})
    out = tmp_path / "run.nc"
    line = _refused(_lmgc90_argv(folder, out), capsys, out)
    assert line == (f"grainview: error: {folder / 'OUTBOX/Vloc_Rloc.OUT.4'}: step 500 at time 7 s, but DOF.OUT.4 has "
                    "step 500 at time 5 s (a snapshot's two files must be of the same step, of the same run)")


def test_lmgc90_names_the_files_of_a_snapshot_as_they_are(tmp_path, capsys):
    """DOF.OUT.02 beside DOF.OUT.2 was ignored; DOF.OUT.04 was looked for as DOF.OUT.4 ('no such
    file')."""
    folder = _lmgc90(tmp_path)
    outbox = folder / "OUTBOX"
    (outbox / "DOF.OUT.4").rename(outbox / "DOF.OUT.04")
    out = tmp_path / "run.nc"
    _converts(_lmgc90_argv(folder, out), capsys, out)
    (outbox / "DOF.OUT.02").write_text((outbox / "DOF.OUT.2").read_text())
    out = tmp_path / "again.nc"
    line = _refused(_lmgc90_argv(folder, out), capsys, out)
    assert line == (f"grainview: error: {outbox}: DOF.OUT.02 and DOF.OUT.2 are both snapshot 2; expected one DOF.OUT "
                    "file per snapshot")


def test_lmgc90_refuses_an_entry_whose_family_is_not_its_bodies(tmp_path, capsys):
    """A DKDKx entry (two disks) on body 1, a POLYG, was read."""
    folder = _lmgc90(tmp_path, **{"OUTBOX/Vloc_Rloc.OUT.4": lambda t: _first_entry(
        t, r"RBDY2      4  DISKx", "RBDY2      1  DISKx")})
    out = tmp_path / "run.nc"
    line = _refused(_lmgc90_argv(folder, out), capsys, out)
    assert line == (f"grainview: error: {folder / 'OUTBOX/Vloc_Rloc.OUT.4'}: line 7: a DKDKx entry (a DISKx on a "
                    "DISKx) on body 1, a POLYG, and body 12, a DISKx in BODIES.DAT (DISKx on DISKx in the entry): "
                    "files of another run?")


def test_lmgc90_refuses_a_step_the_contract_cannot_hold(tmp_path, capsys):
    edit = lambda t: t.replace("$steps      500 ", "$steps      2147483648 ", 1)  # noqa: E731
    folder = _lmgc90(tmp_path, **{"OUTBOX/DOF.OUT.4": edit, "OUTBOX/Vloc_Rloc.OUT.4": edit})
    out = tmp_path / "run.nc"
    line = _refused(_lmgc90_argv(folder, out), capsys, out)
    assert line.startswith(f"grainview: error: {folder / 'OUTBOX/DOF.OUT.4'}: step = 2147483648; expected an integer "
                           "from 0 to 2147483647"), line


# --- PeGS2 --------------------------------------------------------------------------------------

def test_pegs_refuses_a_contact_of_disks_far_apart(tmp_path, capsys):
    """A row joining disks 1 and 2, five diameters apart, was stored as a contact."""
    adjacency, positions = _pegs(tmp_path, adjacency=lambda t: t + "1,1,2,0.001,0.05\n")
    out = tmp_path / "run.nc"
    line = _refused(_pegs_argv(adjacency, positions, out), capsys, out)
    assert line.startswith(f"grainview: error: {adjacency}: frame 1: the contact of id 1 and id 2: the centres are "
                           "0.0242"), line
    assert "expected bodies that touch (centres at most the sum of the radii and 0.5 of the smaller radius apart)" \
        in line


# --- Box2D and pymunk ---------------------------------------------------------------------------

def _peer_argv(folder, out):
    return ["convert", "box2d", folder, "--sample", PEERS / "sample.npz", "--out", out]


def _spoil(name, value, index=0):
    def edit(arrays):
        array = np.asarray(arrays[name]).copy()
        if array.ndim == 0 or np.shape(value) == array.shape and np.ndim(value):
            arrays[name] = np.asarray(value, array.dtype if np.ndim(value) == array.ndim else float)
        else:
            array = array.astype(np.result_type(array, np.asarray(value)))
            array.flat[index] = value
            arrays[name] = array
    return edit


@pytest.mark.parametrize("edit, message", [
    (_spoil("b", 99), "contact 0: b = 99; expected a body index, a particle 0 .. 29 or a wall 30 .. 33"),
    (_spoil("b", 1.5), "contact 0: b = 1.5; expected a body index"),
    (_spoil("n_points", 0), "contact 0: n_points = 0; expected 1 or 2 (the points of the engine's contact manifold)"),
    (_spoil("n_points", 3), "contact 0: n_points = 3; expected 1 or 2"),
    (lambda arrays: arrays["normal"].__setitem__(0, [0.6, 0.6]), "contact 0: normal of length 0.848528; expected a "
                                                                 "unit vector"),
    (lambda arrays: arrays.update(time=np.array([0.0, 1.0])), "time of shape (2,); expected a scalar"),
    (lambda arrays: arrays.update(step=np.array(2**31)), "step = 2147483648; expected an integer from 0 to "
                                                         "2147483647"),
])
def test_the_peers_reader_refuses_a_raw_snapshot_it_cannot_read(tmp_path, capsys, edit, message):
    """An index beyond the bodies raised IndexError, a shape other than the format's TypeError,
    n_points = 0 numpy's divide warning and n_points = 3 'points = nan'; a body index of 1.5
    was cut to 1, a normal of length 2 renormalised; a step beyond 2^31 - 1 OverflowError in
    the writer."""
    folder = _peer(tmp_path, edit)
    out = tmp_path / "run.nc"
    line = _refused(_peer_argv(folder, out), capsys, out)
    assert line.startswith(f"grainview: error: {folder / 'snap_000003.npz'}: {message}"), line


def test_the_peers_reader_refuses_a_wall_contact_point_off_the_particle(tmp_path, capsys):
    """A wall contact's points moved 0.5 m gave a branch of 0.48 m (ten grain sizes)."""
    def move(arrays):
        k = int(np.flatnonzero(arrays["b"] >= 30)[0])
        arrays["points"] = arrays["points"].copy()
        arrays["points"][k] += 0.5

    folder = _peer(tmp_path, move)
    out = tmp_path / "run.nc"
    line = _refused(_peer_argv(folder, out), capsys, out)
    assert re.match(rf"grainview: error: {re.escape(str(folder / 'snap_000003.npz'))}: the contact of particle \d+ "
                    r"and the \w+ wall: the contact point is 0\.\d+ m from the centre of particle", line), line


@pytest.mark.parametrize("damage, message", [
    (lambda path: path.write_bytes(b""), "an empty file, not a raw snapshot of the cross-check (an engine stopped "
                                          "while writing it?)"),
    (lambda path: path.write_bytes(path.read_bytes()[:4000]), "cannot be read as a raw snapshot of the cross-check: "
                                                               "a truncated or damaged .npz"),
    (lambda path: path.write_bytes((lambda b: b[:600] + bytes([b[600] ^ 0xFF]) + b[601:])(path.read_bytes())),
     "cannot be read as a raw snapshot of the cross-check: a truncated or damaged .npz"),
])
def test_the_peers_reader_names_a_damaged_snapshot(tmp_path, capsys, damage, message):
    """An empty, a truncated and a corrupted snapshot raised EOFError and BadZipFile (with a
    ResourceWarning for the file left open)."""
    folder = _peer(tmp_path)
    damage(folder / "snap_000003.npz")
    out = tmp_path / "run.nc"
    line = _refused(_peer_argv(folder, out), capsys, out)
    assert line.startswith(f"grainview: error: {folder / 'snap_000003.npz'}: {message}"), line


def test_the_peers_reader_refuses_a_folder_missing_a_snapshot_or_a_meta_that_is_not_an_object(tmp_path, capsys):
    """A missing middle snapshot was skipped (5 of the 6 meta.json announces); a meta.json
    holding a list raised AttributeError."""
    folder = _peer(tmp_path)
    (folder / "snap_000003.npz").unlink()
    out = tmp_path / "run.nc"
    line = _refused(_peer_argv(folder, out), capsys, out)
    assert line == (f"grainview: error: {folder}: no snap_000003.npz, but snapshots up to snap_000005.npz; expected "
                    "the raw snapshots numbered from 0 without a gap")
    (folder / "snap_000005.npz").rename(folder / "snap_000003.npz")
    line = _refused(_peer_argv(folder, out), capsys, out)
    assert line == f"grainview: error: {folder}: 5 raw snapshots (snap_*.npz), but meta.json announces 6"
    (folder / "meta.json").write_text("[1, 2]")
    line = _refused(_peer_argv(folder, out), capsys, out)
    assert line.startswith(f"grainview: error: {folder / 'meta.json'}: a JSON list; expected an object"), line


def test_a_snapshot_without_contacts_after_many_gets_a_note(tmp_path, capsys):
    """A Vloc_Rloc.OUT cut just after its header (LMGC90 writes no end mark) gave its snapshot 0
    contacts after 77, without a word."""
    def cut(text):
        return text[:text.index("$icdan")]

    folder = _lmgc90(tmp_path, **{"OUTBOX/Vloc_Rloc.OUT.4": cut})
    out = tmp_path / "run.nc"
    stdout = _converts(_lmgc90_argv(folder, out), capsys, out)
    assert ("note: the LMGC90 run: 1 snapshot(s) without a contact right after one with many: snapshot 3 (t = 5 s, "
            "after 77); written as they are (a contact file cut between two entries reads the same: check it)") \
        in stdout.splitlines(), stdout


def test_pegs_notes_two_estimates_of_a_force_far_apart(tmp_path, capsys):
    """The two normal forces fitted for the pair of ids 12 and 3, one made a thousand times the
    other, were averaged without a word."""
    adjacency, positions = _pegs(tmp_path, adjacency=lambda t: t.replace(",0.00947452301345562\n",
                                                                         ",9.47452301345562\n", 1))
    out = tmp_path / "run.nc"
    stdout = _converts(_pegs_argv(adjacency, positions, out), capsys, out)
    assert ("note: 1 particle pair(s) over 1 frame(s) were fitted on both disks with normal forces more than 10 times "
            "apart (e.g. ids 3 and 12: 0.00764624 fitted on id 3, 9.47452 on id 12, in force units); the mean of the "
            "two is stored") \
        in stdout.splitlines(), stdout


def test_a_byte_order_mark_is_called_what_it_is(tmp_path, capsys):
    """A dump or a BODIES.DAT saved with a byte-order mark was 'found '���ITEM: TIMESTEP'' and
    'not a text file'."""
    files = _lammps(tmp_path)
    files["walls"].write_bytes(b"\xef\xbb\xbf" + files["walls"].read_bytes())
    out = tmp_path / "run.nc"
    line = _refused(_lammps_argv(files, out), capsys, out)
    assert line == (f"grainview: error: {files['walls']}: line 1: a byte-order mark before 'ITEM: TIMESTEP' (an "
                    "editor's; LAMMPS writes none): save the dump without it")
    folder = _lmgc90(tmp_path)
    bodies = folder / "DATBOX/BODIES.DAT"
    bodies.write_bytes(b"\xef\xbb\xbf" + bodies.read_bytes())
    line = _refused(_lmgc90_argv(folder, out), capsys, out)
    assert line == (f"grainview: error: {bodies}: a byte-order mark at its start (an editor's; LMGC90 writes none): "
                    "save the file without it")
