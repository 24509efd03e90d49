"""The MercuryDPM reader on periodic and Lees-Edwards runs that MercuryDPM itself wrote.

tests/data/mercurydpm/periodic/ holds three runs of the driver Periodic2D.cpp (made by
make_fixtures.py --periodic with the kernel that build_mercurydpm.sh builds): ``Periodic2D``
(100 disks jammed in a cell periodic in x and y: two PeriodicBoundary), ``LeesEdwards2D`` (the
same packing sheared by a LeesEdwardsBoundary whose shift grows as t and passes half the cell's
width), ``Channel2D`` (40 disks under gravity between a floor and a lid, periodic in x) and
``Tilted2D`` (the jammed packing in a fixed tilted cell: the PeriodicBoundary across y shifts
its images by 2 in x, ``setPlanewiseShift``).
Every expected number is computed here from the files' text by a plain parse (its own minimum
images, its own cell from the .restart's boundary lines), never with the reader.
"""

from __future__ import annotations

import importlib.util
import math
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import grainview
from grainview.contract.errors import FileFormatError
from grainview.formats.mercurydpm import convert_mercurydpm, open_mercurydpm

HERE = Path(__file__).resolve().parents[1] / "data" / "mercurydpm"
DATA = HERE / "periodic"
RUNS = ("Periodic2D", "LeesEdwards2D", "Channel2D", "Tilted2D")


def files(name, folder=DATA):
    return folder / f"{name}.data", folder / f"{name}.fstat", folder / f"{name}.restart"


def read(name, folder=DATA):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the note on tensile pairs (tested in test_format_mercurydpm.py)
        return open_mercurydpm(files(name, folder)[0], units="si")


@pytest.fixture(scope="module")
def datasets():
    return {name: read(name) for name in RUNS}


# --- the files' text, parsed by hand -------------------------------------------------------------

def plain_data(path):
    """[(time, bounds, rows)] of a 2D .data file."""
    lines = Path(path).read_text().splitlines()
    out, k = [], 0
    while k < len(lines):
        head = [float(v) for v in lines[k].split()]
        n = int(head[0])
        out.append((head[1], head[2:], [[float(v) for v in line.split()] for line in lines[k + 1:k + 1 + n]]))
        k += 1 + n
    return out


def plain_fstat(path):
    """[(time, rows)] of an .fstat file."""
    out = []
    for line in Path(path).read_text().splitlines():
        if line.startswith("#"):
            values = line[1:].split()
            if len(values) == 2:
                out.append((float(values[0]), []))
            continue
        out[-1][1].append([float(v) for v in line.split()])
    return out


def plain_restart(path):
    """The .restart's time step, time and periodic boundary lines as {key: [numbers]}."""
    clock, boundaries = None, []
    for line in Path(path).read_text().splitlines():
        tokens = line.split()
        if tokens and tokens[0] == "timeStep":
            clock = float(tokens[1]), float(tokens[3])
        if tokens and tokens[0] in ("PeriodicBoundary", "LeesEdwardsBoundary"):
            record, key = {"type": tokens[0]}, None
            for token in tokens[1:]:
                try:
                    record.setdefault(key, []).append(float(token))
                except ValueError:
                    key = token
            boundaries.append(record)
    return clock, boundaries


def hand_cell(name, time, bounds, folder=DATA):
    """(xlo, xhi, ylo, yhi, tilt, periodic x, periodic y) at a snapshot: the boundaries' bounds
    (the .data header's along a bounded direction); a Lees-Edwards tilt s + v (t - dt - T)
    (at t = 0: s - v T) brought by whole widths to [-l/2, l/2]."""
    (dt, written), boundaries = plain_restart(files(name, folder)[2])
    xlo, ylo, xhi, yhi = bounds
    tilt, px, py = 0.0, False, False
    for b in boundaries:
        if b["type"] == "LeesEdwardsBoundary":
            xlo, xhi, ylo, yhi = b["left"][0], b["right"][0], b["down"][0], b["up"][0]
            shift = b["shift"][0] + b["vel"][0] * ((time - dt if time > 0 else time) - written)
            tilt = shift - (xhi - xlo) * round(shift / (xhi - xlo))
            px = py = True
        elif b["normal"][:2] == [1.0, 0.0]:
            xlo, xhi, px = b["distanceLeft"][0], b["distanceRight"][0], True
        else:  # across y; its shift's x component shifts the images in x (a tilted cell)
            ylo, yhi, py, tilt = b["distanceLeft"][0], b["distanceRight"][0], True, b["shift"][0]
    return xlo, xhi, ylo, yhi, tilt, px, py


def nearest_image(dx, dy, cell):
    """The shortest of (dx, dy) + m a + n b, a = (l, 0), b = (tilt, h), over the periodic
    directions, by trying the whole numbers around the rounded ones."""
    xlo, xhi, ylo, yhi, tilt, px, py = cell
    l, h = xhi - xlo, yhi - ylo
    n0 = round(dy / h) if py else 0
    m0 = round((dx - n0 * tilt) / l) if px else 0
    best = None
    for n in (range(n0 - 2, n0 + 3) if py else (0,)):
        for m in (range(m0 - 2, m0 + 3) if px else (0,)):
            cx, cy = dx - m * l - n * tilt, dy - n * h
            if best is None or cx * cx + cy * cy < best[0] * best[0] + best[1] * best[1]:
                best = (cx, cy)
    return best


def by_hand(name, folder=DATA):
    """Per snapshot: the cell, the particle pairs {(lo, hi): (force by lo on hi, branch x_hi -
    x_lo, fstat normal on hi, overlap, radii)} and the wall contacts [(force on the wall, arm from
    the centre to the contact point)]; overlapping, compressive contacts only."""
    data, fstat = plain_data(files(name, folder)[0]), plain_fstat(files(name, folder)[1])
    out = []
    for (time, bounds, particles), (time_f, rows) in zip(data, fstat):
        assert time == time_f
        cell = hand_cell(name, time, bounds, folder)
        n = len(particles)
        pairs, walls = {}, []
        for t, p, other, cx, cy, cz, overlap, _, fn, ft, nx, ny, nz, tx, ty, tz in rows:
            p, other = int(p), int(other)
            force = (fn * nx + ft * tx, fn * ny + ft * ty)  # on P; for a wall line, on the wall
            x = particles[p]
            if not (overlap > 0 and fn > 0):
                continue
            if other < 0:
                arm = nearest_image(cx - x[0], cy - x[1], cell)
                walls.append((force, arm))
            elif p > other:  # the line of the higher index: the force on it from the lower one
                y = particles[other]
                branch = nearest_image(x[0] - y[0], x[1] - y[1], cell)
                pairs[(other, p)] = (force, branch, (nx, ny), overlap, (y[4], x[4]), (x[0] - y[0], x[1] - y[1]))
        out.append(dict(time=time, cell=cell, pairs=pairs, walls=walls, n=n))
    return out


# --- the runs ------------------------------------------------------------------------------------

def test_the_fixtures_are_real_mercurydpm_runs_in_periodic_cells():
    for name in RUNS:
        restart = files(name)[2].read_text()
        assert restart.startswith(f"MercuryDPM 1.0 name {name}")
        (dt, written), boundaries = plain_restart(files(name)[2])
        end = 2.0 if name == "Tilted2D" else 6.0
        assert dt == 0.001 and written == pytest.approx(end, abs=2e-3)
        kinds = [b["type"] for b in boundaries]
        assert kinds == {"Periodic2D": ["PeriodicBoundary"] * 2, "LeesEdwards2D": ["LeesEdwardsBoundary"],
                         "Channel2D": ["PeriodicBoundary"], "Tilted2D": ["PeriodicBoundary"] * 2}[name]
        hand = by_hand(name)
        times = [0, 2, 2.001] if name == "Tilted2D" else [0, 2, 4, 6]  # MercuryDPM's last write at t >= 2
        assert [round(h["time"], 6) for h in hand] == times
        assert all(h["pairs"] for h in hand)
    (_, written), (lees,) = plain_restart(files("LeesEdwards2D")[2])
    assert lees["vel"] == [1.0] and lees["shift"][0] == pytest.approx(written)  # shift v t, v = 1
    # contacts across the boundary in x, and in y where it is periodic (in every snapshot but the
    # channel's first: its disks start on a grid, a row touching its neighbours in places only)
    for name in RUNS:
        for h in by_hand(name)[name == "Channel2D":]:
            xlo, xhi, ylo, yhi, *_ = h["cell"]
            raw = np.array([pair[5] for pair in h["pairs"].values()])
            assert np.any(np.abs(raw[:, 0]) > (xhi - xlo) / 2), name
            assert np.any(np.abs(raw[:, 1]) > (yhi - ylo) / 2) == (name != "Channel2D"), name


@pytest.mark.parametrize("name", RUNS)
def test_every_snapshot_equals_a_minimum_image_hand_computation(datasets, name):
    """Stress (1/V) sum f (x) l with V = l h (1 m thick), fabric and coordination of every
    snapshot, from the files' text with this file's own cell and minimum images, to 1e-12."""
    equals_the_hand_computation(datasets[name], name)


def equals_the_hand_computation(ds, name, folder=DATA):
    hand = by_hand(name, folder)
    assert ds.sizes["time"] == len(hand)
    stress, fabric, z = ds.grain.stress_tensor().values, ds.grain.fabric_tensor().values, ds.grain.coordination()
    for k, h in enumerate(hand):
        xlo, xhi, ylo, yhi, tilt, px, py = h["cell"]
        np.testing.assert_array_equal(ds["cell"].values[k], [[xhi - xlo, 0.0], [tilt, yhi - ylo]])
        np.testing.assert_array_equal(ds["box_min"].values[k], [xlo, ylo])
        np.testing.assert_array_equal(ds["box_max"].values[k], [xhi, yhi])
        moment, fab = np.zeros((2, 2)), np.zeros((2, 2))
        for force, branch, normal, *_ in h["pairs"].values():
            moment += np.outer(force, branch)
            normal = np.array(normal) / math.hypot(*normal)  # the contract's normal: MercuryDPM's, as written
            fab += np.outer(normal, normal) / len(h["pairs"])
        for force, arm in h["walls"]:
            moment += np.outer(force, arm)
        volume = (xhi - xlo) * (yhi - ylo)
        scale = max(np.abs(moment).max(), 1e-300) / volume
        np.testing.assert_allclose(stress[k], moment / volume, rtol=1e-12, atol=1e-12 * scale)
        if h["pairs"]:
            np.testing.assert_allclose(fabric[k], fab, rtol=1e-12, atol=1e-14)
            touched = {i for pair in h["pairs"] for i in pair}
            assert float(z["z"][k]) == pytest.approx(2 * len(h["pairs"]) / len(touched), rel=1e-12)
        count = int(ds["contact_count"][k])
        n = ds.sizes["particle"]
        assert int((ds["j"].values[k, :count] < n).sum()) == len(h["pairs"])
        assert int((ds["j"].values[k, :count] >= n).sum()) == len(h["walls"])


@pytest.mark.parametrize("name", RUNS)
def test_no_branch_is_longer_than_the_particles_allow_and_the_file_validates(datasets, name, tmp_path):
    ds = datasets[name]
    n = ds.sizes["particle"]
    radius = ds["radius"].values
    for k in range(ds.sizes["time"]):
        count = int(ds["contact_count"][k])
        i, j = ds["i"].values[k, :count], ds["j"].values[k, :count]
        branch = ds["branch"].values[k, :count]
        pair = j < n
        length = np.hypot(branch[:, 0], branch[:, 1])
        assert np.all(length[pair] <= radius[i[pair]] + radius[j[pair]]), name
        assert np.all(length[~pair] <= radius[i[~pair]] * (1 + 1e-9)), name
        # the contact point is on both particles (the image of j nearest i)
        point = ds["point"].values[k, :count]
        xi = ds["position"].values[k][i]
        assert np.all(np.hypot(*(point - xi).T) <= radius[i] * (1 + 1e-9))
    grainview.validate(ds)
    assert ds.attrs["grainview_schema_version"] == "3.0" and ds.attrs["cell_positions"] == "wrapped"
    out = tmp_path / "run.nc"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        convert_mercurydpm(out, files(name)[0], units="si")
    with grainview.open_dataset(out) as back:
        grainview.validate(back)
        for var in ("position", "branch", "point", "fn", "ft", "box_min", "box_max", "cell", "periodic"):
            np.testing.assert_array_equal(back[var].values, ds[var].values)
        assert back.attrs["cell_positions"] == "wrapped" and back.attrs["grainview_schema_version"] == "3.0"


def test_the_cell_and_the_positions(datasets):
    assert datasets["Periodic2D"]["periodic"].values.tolist() == [1, 1]
    assert datasets["LeesEdwards2D"]["periodic"].values.tolist() == [1, 1]
    assert datasets["Channel2D"]["periodic"].values.tolist() == [1, 0]
    assert datasets["Tilted2D"]["periodic"].values.tolist() == [1, 1]
    np.testing.assert_array_equal(datasets["Tilted2D"]["cell"].values[:, 1], [[2.0, 9.5]] * 3)
    assert "LeesEdwardsBoundary" in datasets["LeesEdwards2D"].attrs["mercurydpm_cell"]
    tilt = datasets["LeesEdwards2D"]["cell"].values[:, 1, 0]
    width = datasets["LeesEdwards2D"]["cell"].values[0, 0, 0]
    assert tilt[2] > 0 and tilt[3] < 0 and abs(tilt).max() <= width / 2  # the shift passed half the width
    np.testing.assert_array_equal(datasets["Periodic2D"]["cell"].values[:, 1, 0], 0.0)
    for name, ds in datasets.items():
        hand = by_hand(name)
        for k, (time, bounds, rows) in enumerate(plain_data(files(name)[0])):
            xlo, xhi, ylo, yhi, tilt, px, py = hand[k]["cell"]
            written = np.array([row[:2] for row in rows])
            stored = ds["position"].values[k]
            # wrapped into the cell: each the file's position moved by whole widths in x (MercuryDPM
            # keeps them in its rectangle; a tilted cell is a parallelogram)
            np.testing.assert_array_equal(stored[:, 1], written[:, 1])
            moved = (stored[:, 0] - written[:, 0]) / (xhi - xlo)
            np.testing.assert_allclose(moved, np.round(moved), atol=1e-12)
            s = (stored[:, 0] - xlo - (stored[:, 1] - ylo) / (yhi - ylo) * tilt) / (xhi - xlo)
            assert np.all((s >= -1e-12) & (s < 1 + 1e-12)), name


def test_the_lees_edwards_shift_is_the_one_of_the_force_computation():
    """A pair across the sheared boundary was computed on a ghost particle shifted by the shift
    of the step that began at t - dt (at t = 0, MercuryDPM's initial force computation: the
    shift at 0): its overlap and normal, written by MercuryDPM, match the branch through the
    cell of s + v (t - dt - T) to the files' 10 digits, and not through the shift one step
    later (or, at t = 0, earlier), off by v dt = 1e-3."""
    hand = by_hand("LeesEdwards2D")
    (dt, written), (lees,) = plain_restart(files("LeesEdwards2D")[2])
    crossing = 0
    for h in hand:
        xlo, xhi, ylo, yhi, tilt, px, py = h["cell"]
        late = (xlo, xhi, ylo, yhi, tilt + lees["vel"][0] * dt * (1 if h["time"] > 0 else -1), px, py)
        data = {round(t, 6): rows for t, _, rows in plain_data(files("LeesEdwards2D")[0])}[round(h["time"], 6)]
        for (lo, hi), (force, branch, normal, overlap, radii, _) in h["pairs"].items():
            dy = data[hi][1] - data[lo][1]
            if abs(dy) < (yhi - ylo) / 2:
                continue  # not across the top or the bottom
            crossing += 1
            assert math.hypot(*branch) == pytest.approx(sum(radii) - overlap, abs=1e-8)
            # MercuryDPM's normal on the higher index points from the lower one to it
            assert np.hypot(*(np.array(branch) / math.hypot(*branch) - normal)) < 1e-8
            other = nearest_image(data[hi][0] - data[lo][0], dy, late)
            assert abs(math.hypot(*other) - (sum(radii) - overlap)) > 1e-6
    assert crossing >= 3


def test_positions_velocities_and_the_model_are_the_files(datasets):
    for name, ds in datasets.items():
        for k, (time, bounds, rows) in enumerate(plain_data(files(name)[0])):
            rows = np.array(rows)
            np.testing.assert_array_equal(ds["velocity"].values[k], rows[:, 2:4])
            np.testing.assert_array_equal(ds["radius"].values, rows[:, 4])
            assert float(ds["time"][k]) == time


# --- bad input: one line each -------------------------------------------------------------------

def edited(tmp_path, name, suffix, edit):
    folder = tmp_path / name
    folder.mkdir()
    for path in files(name):
        text = path.read_text()
        if path.suffix == suffix:
            text = edit(text)
            assert text != path.read_text()
        (folder / path.name).write_text(text)
    return folder / f"{name}.data"


def _boundary_line(text, kind):
    return next(line for line in text.splitlines() if line.startswith(kind))


def _outside(text):
    lines = text.split("\n")
    row = lines[1].split()
    row[0] = "25"
    lines[1] = " ".join(row)
    return "\n".join(lines)


def _with_periodic_boundary(text):
    line = _boundary_line(text, "LeesEdwardsBoundary")
    extra = "PeriodicBoundary id 1 normal 1 0 0 scaleFactor 1 distanceLeft 0 distanceRight 9.5 shift 9.5 0 0"
    return text.replace("Boundaries 1\n" + line, "Boundaries 2\n" + line + "\n" + extra)


def _cut_boundaries(text):
    first = _boundary_line(text, "PeriodicBoundary")
    return text.replace("Boundaries 2\n", "Boundaries 12\n").replace(first + "\n", first + "\n", 1).replace(
        "\nParticles ", "\n...\nParticles ", 1)


def _without_x(text):
    line = _boundary_line(text, "PeriodicBoundary id 1")
    return text.replace("Boundaries 2\n", "Boundaries 1\n").replace(line + "\n", "")


BAD = [
    ("another periodic boundary", "Periodic2D", ".restart",
     lambda t: t.replace("\nPeriodicBoundary id 1", "\nAngledPeriodicBoundary id 1", 1),
     "AngledPeriodicBoundary; the reader takes a periodic cell from PeriodicBoundary and LeesEdwardsBoundary only"),
    ("a slanted normal", "Periodic2D", ".restart",
     lambda t: t.replace("PeriodicBoundary id 0 normal 1 0 0", "PeriodicBoundary id 0 normal 0.6 0.8 0", 1),
     "normal 0.6 0.8 0; expected a cell periodic along x"),
    ("a shift that is not the width", "Channel2D", ".restart",
     lambda t: t.replace(" shift 8.4 0 0", " shift 8.5 0 0", 1), "shift 8.5 0 0 for the width 8.4"),
    ("two boundaries across x", "Periodic2D", ".restart",
     lambda t: t.replace("normal 0 1 0 scaleFactor 1 distanceLeft 0 distanceRight 9.5 shift 0 9.5 0",
                         "normal 1 0 0 scaleFactor 1 distanceLeft 0 distanceRight 9.5 shift 9.5 0 0", 1),
     "a second periodic boundary across x"),
    ("Lees-Edwards with a periodic boundary", "LeesEdwards2D", ".restart", _with_periodic_boundary,
     "a second periodic boundary across x"),
    ("boundaries cut with ...", "Periodic2D", ".restart", _cut_boundaries,
     "'Boundaries 12' lists 2 of them and '...'"),
    ("a tilt without x periodic", "Tilted2D", ".restart", _without_x,
     "shifted in x by 2 but no PeriodicBoundary in x; a shifted .tilted. cell is read only when periodic in x and y"),
    ("a boundary across x shifting in y", "Periodic2D", ".restart",
     lambda t: t.replace(" shift 9.5 0 0", " shift 9.5 1 0", 1), "shift 9.5 1 0 for the width 9.5"),
    ("a centre far outside the cell", "Periodic2D", ".data", _outside,
     r"particle 0 at \(25, .*lies outside the periodic cell along x"),
    ("a Lees-Edwards boundary without its shift", "LeesEdwards2D", ".restart",
     lambda t: t.replace(" vel ", " velocity ", 1), "expected 'vel' with 1 finite number"),
]


@pytest.mark.parametrize("label, name, suffix, edit, message", BAD, ids=[b[0] for b in BAD])
def test_bad_input_is_refused_in_one_line(tmp_path, label, name, suffix, edit, message):
    data = edited(tmp_path, name, suffix, edit)
    with pytest.raises(FileFormatError, match=message) as caught:
        read(name, data.parent)
    assert "\n" not in str(caught.value)
    done = subprocess.run([sys.executable, "-m", "grainview", "convert", "mercurydpm", str(data), "--units", "si",
                           "--out", str(tmp_path / "out.nc"), "--progress", "off"], capture_output=True, text=True)
    assert done.returncode != 0 and done.stderr.strip().count("\n") == 0, done.stderr
    assert not (tmp_path / "out.nc").exists()


# --- a fresh run (with MercuryDPM built) ----------------------------------------------------------

def _make_fixtures():
    spec = importlib.util.spec_from_file_location("mercurydpm_make_fixtures", HERE / "make_fixtures.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.slow
@pytest.mark.skipif(_make_fixtures().find_driver(name="Periodic2D") is None,
                    reason="MercuryDPM's Periodic2D is not built (tests/data/mercurydpm/build_mercurydpm.sh)")
def test_the_driver_writes_the_committed_fixtures_again(tmp_path):
    make = _make_fixtures()
    for mode, name in make.PERIODIC.items():
        make.run_periodic(tmp_path, mode, seed=1)
        for path in files(name):
            assert (tmp_path / path.name).read_bytes() == path.read_bytes(), path.name


@pytest.mark.slow
@pytest.mark.skipif(_make_fixtures().find_driver(name="Periodic2D") is None,
                    reason="MercuryDPM's Periodic2D is not built (tests/data/mercurydpm/build_mercurydpm.sh)")
@pytest.mark.parametrize("mode", ["periodic", "lees", "channel", "tilted"])
def test_a_fresh_periodic_run_converts_and_equals_the_hand_computation(tmp_path, mode):
    """MercuryDPM runs Periodic2D anew with a seed no other test has seen: the run converts,
    passes `grainview info --check`, and every snapshot equals the hand computation."""
    make = _make_fixtures()
    data = make.run_periodic(tmp_path, mode, seed=97)
    out = tmp_path / "fresh.nc"
    done = subprocess.run([sys.executable, "-m", "grainview", "convert", "mercurydpm", str(data), "--units", "si",
                           "--out", str(out), "--progress", "off"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    check = subprocess.run([sys.executable, "-m", "grainview", "info", str(out), "--check"], capture_output=True,
                           text=True)
    assert check.returncode == 0 and "valid" in check.stdout, check.stdout + check.stderr
    with grainview.open_dataset(out, chunks=None) as fresh:
        equals_the_hand_computation(fresh, make.PERIODIC[mode], tmp_path)
