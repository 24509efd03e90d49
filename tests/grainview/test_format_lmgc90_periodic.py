"""The LMGC90 reader on a periodic run that LMGC90 itself wrote: tests/data/lmgc90/periodic/
holds the DATBOX and OUTBOX of gen_sample.py's ``periodic`` scene run by command.py (30
pentagons and 10 disks thrown sideways under gravity between a floor and a lid, periodic in x
with period 10 m: ``chipy.SetPeriodicCondition(xperiod=10)``), made by make_fixtures.py periodic
with the LMGC90 that build_lmgc90.sh builds.

Every expected number comes from a plain parse of the files in this file (Fortran's fixed
columns; its own minimum images in x), never from the reader.
"""

from __future__ import annotations

import importlib.util
import math
import re
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import grainview
from grainview.contract.errors import FileFormatError, ParameterError
from grainview.formats.lmgc90 import convert_lmgc90, open_lmgc90

DATA = Path(__file__).resolve().parents[1] / "data" / "lmgc90"
RUN = DATA / "periodic"
PERIOD = 10.0  # gen_sample.PERIOD, command.py's SetPeriodicCondition


def number(text):
    return float(text.strip().replace("D", "E"))


def plain_bodies(run):
    """{body number: (contactor type, reference x, y, axe2 of a JONCx)} of BODIES.DAT."""
    out, lines = {}, (run / "DATBOX" / "BODIES.DAT").read_text().splitlines()
    for k, line in enumerate(lines):
        if line == "$bdyty":
            body = int(lines[k + 1].split()[1])
            node = lines[k + 5]
            x, y = number(node.split("coo1=")[1][:15]), number(node.split("coo2=")[1][:15])
            kind = lines[k + 7].split()[0]
            axe2 = re.search(r"axe2=\s*(\S+)", lines[k + 7])
            out[body] = (kind, x, y, number(axe2.group(1)) if axe2 else 0.0)
    return out


def plain_dof(path):
    """{body number: (X(1), X(2), X(3))} of a DOF.OUT file (LMGC90's fixed columns)."""
    out, lines = {}, Path(path).read_text().splitlines()
    for k, line in enumerate(lines):
        if line == "$bdyty":
            out[int(lines[k + 1].split()[1])] = tuple(number(lines[k + 3][c:c + 14]) for c in (34, 55, 76))
    return out


def plain_vloc(path):
    """The entries of a Vloc_Rloc.OUT file (LMGC90's fixed columns)."""
    out, lines = [], Path(path).read_text().splitlines()
    for k, line in enumerate(lines):
        if line.startswith("$icdan"):
            title, data = lines[k + 1].split(), lines[k + 2].split()
            rows = lines[k + 3:k + 8]
            value = lambda r, c: number(rows[r][34 + 21 * c:48 + 21 * c])  # noqa: E731
            out.append(dict(cd=int(data[1]), an=int(data[title.index("anbdy") + 1]), rlt=value(0, 0),
                            rln=value(0, 1), n=(value(3, 0), value(3, 1)), point=(value(4, 0), value(4, 1))))
    return out


def nearest_x(dx):
    return dx - PERIOD * round(dx / PERIOD)


def as_stored(force, normal):
    """The contract's force of a contact: its components along the normal as written (LMGC90's
    8 digits: |n| = 1 to about 1e-8) and t = (-n_y, n_x), recombined: fn n + ft t."""
    tangent = (-normal[1], normal[0])
    fn = force[0] * normal[0] + force[1] * normal[1]
    ft = force[0] * tangent[0] + force[1] * tangent[1]
    return (fn * normal[0] + ft * tangent[0], fn * normal[1] + ft * tangent[1])


def by_hand(run=RUN):
    """Per snapshot: the particle pairs {(i, j): (force by i on j, branch, normal from i to j)},
    the wall contacts [(force on the wall, arm)], and the y bounds between the walls' faces."""
    bodies = plain_bodies(run)
    particles = [b for b, v in bodies.items() if v[0] != "JONCx"]
    walls = [b for b, v in bodies.items() if v[0] == "JONCx"]
    index = {b: p for p, b in enumerate(particles)}
    out = []
    for k in range(1, len(list((run / "OUTBOX").glob("DOF.OUT.*"))) + 1):
        dof = plain_dof(run / "OUTBOX" / f"DOF.OUT.{k}")
        at = {b: (bodies[b][1] + dof[b][0], bodies[b][2] + dof[b][1]) for b in bodies}
        faces = sorted((at[w][1] + bodies[w][3], at[w][1] - bodies[w][3]) for w in walls)
        low, high = faces[0][0], faces[1][1]  # the floor's top face, the lid's bottom face
        groups = {}
        for e in plain_vloc(run / "OUTBOX" / f"Vloc_Rloc.OUT.{k}"):
            groups.setdefault((e["cd"], e["an"]) if e["an"] in walls else tuple(sorted((e["cd"], e["an"]))),
                              []).append(e)
        pairs, on_walls = {}, []
        for key, entries in groups.items():
            cd = entries[0]["cd"]
            nx, ny = entries[0]["n"]  # from the antagonist to the candidate
            on_cd = [sum(e["rln"] * e["n"][c] + e["rlt"] * (e["n"][1], -e["n"][0])[c] for e in entries) for c in (0, 1)]
            rln = sum(e["rln"] for e in entries)
            if not rln > 0:
                continue
            if key[1] in walls:  # a particle (candidate) on a wall: the force on the wall, the arm to the point
                point = [sum(e["rln"] * e["point"][c] for e in entries) / rln for c in (0, 1)]
                x = at[cd]
                on_walls.append((as_stored((-on_cd[0], -on_cd[1]), (-nx, -ny)),
                                 (nearest_x(point[0] - x[0]), point[1] - x[1])))
                continue
            lo, hi = sorted(key, key=lambda b: index[b])
            sign = -1.0 if cd == lo else 1.0  # the force of lo on hi: minus the force on lo
            normal = (sign * nx, sign * ny)
            force = as_stored((sign * on_cd[0], sign * on_cd[1]), normal)
            branch = (nearest_x(at[hi][0] - at[lo][0]), at[hi][1] - at[lo][1])
            pairs[(index[lo], index[hi])] = (force, branch, normal, at[hi][0] - at[lo][0])
        out.append(dict(pairs=pairs, walls=on_walls, y=(low, high)))
    return out


@pytest.fixture(scope="module")
def ds():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return open_lmgc90(RUN, x_period=PERIOD)


def test_the_fixture_is_a_real_periodic_lmgc90_run(ds):
    bodies = plain_bodies(RUN)
    assert sum(v[0] == "POLYG" for v in bodies.values()) == 30 and sum(v[0] == "DISKx" for v in bodies.values()) == 10
    assert ds["periodic"].values.tolist() == [1, 0] and ds.attrs["cell_positions"] == "wrapped"
    assert list(ds["wall"].values) == ["bottom", "top"]
    hand = by_hand()
    assert len(hand) == 4
    # LMGC90 moved bodies across the boundary, and contacts cross it
    xs = [np.array([bodies[b][1] + d[0] for b, d in plain_dof(RUN / "OUTBOX" / f"DOF.OUT.{k}").items()
                    if bodies[b][0] != "JONCx"]) for k in range(1, 5)]
    assert all(np.all((x >= 0) & (x <= PERIOD)) for x in xs)
    assert all(any(abs(raw) > PERIOD / 2 for *_, raw in h["pairs"].values()) for h in hand[1:])


def test_every_snapshot_equals_a_minimum_image_hand_computation(ds):
    """Stress (1/V) sum f (x) l with V = 10 m x the height between the walls' faces, fabric
    and coordination of every snapshot, from the files' text, to 1e-12."""
    stress, fabric, z = ds.grain.stress_tensor().values, ds.grain.fabric_tensor().values, ds.grain.coordination()
    for k, h in enumerate(by_hand()):
        low, high = h["y"]
        np.testing.assert_array_equal(ds["box_min"].values[k], [0.0, low])
        np.testing.assert_array_equal(ds["box_max"].values[k], [PERIOD, high])
        np.testing.assert_array_equal(ds["cell"].values[k], [[PERIOD, 0.0], [0.0, high - low]])
        moment, fab = np.zeros((2, 2)), np.zeros((2, 2))
        for force, branch, normal, _ in h["pairs"].values():
            moment += np.outer(force, branch)
            fab += np.outer(normal, normal) / len(h["pairs"])
        for force, arm in h["walls"]:
            moment += np.outer(force, arm)
        volume = PERIOD * (high - low)
        np.testing.assert_allclose(stress[k], moment / volume, rtol=1e-12, atol=1e-12 * np.abs(moment).max() / volume)
        np.testing.assert_allclose(fabric[k], fab, rtol=1e-12, atol=1e-14)
        touched = {i for pair in h["pairs"] for i in pair}
        assert float(z["z"][k]) == pytest.approx(2 * len(h["pairs"]) / len(touched), rel=1e-12)
        count = int(ds["contact_count"][k])
        n = ds.sizes["particle"]
        assert int((ds["j"].values[k, :count] < n).sum()) == len(h["pairs"])
        assert int((ds["j"].values[k, :count] >= n).sum()) == len(h["walls"])


def test_no_branch_is_longer_than_the_particles_allow_and_the_file_validates(ds, tmp_path):
    n = ds.sizes["particle"]
    radius = ds["radius"].values
    for k in range(ds.sizes["time"]):
        count = int(ds["contact_count"][k])
        i, j = ds["i"].values[k, :count], ds["j"].values[k, :count]
        branch = ds["branch"].values[k, :count]
        pair = j < n
        length = np.hypot(branch[:, 0], branch[:, 1])
        # within the contract's 1e-6 of r_i + r_j (DOF.OUT's 8 digits put disks in contact up to
        # 4e-7 apart)
        assert np.all(length[pair] <= (radius[i[pair]] + radius[j[pair]]) * (1 + 1e-6))
        assert np.all(length[~pair] <= radius[i[~pair]] * (1 + 1e-6))
        x = ds["position"].values[k, :, 0]
        assert np.all((x >= 0) & (x < PERIOD))
    grainview.validate(ds)
    out = tmp_path / "run.nc"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        convert_lmgc90(out, RUN, x_period=PERIOD)
    with grainview.open_dataset(out) as back:
        grainview.validate(back)
        for var in ("position", "branch", "point", "fn", "ft", "cell", "periodic"):
            np.testing.assert_array_equal(back[var].values, ds[var].values)
        assert back.attrs["grainview_schema_version"] == "3.0"


def test_without_its_period_the_run_is_refused_or_read_as_bounded(tmp_path):
    """Read as a bounded run, a contact across the boundary is of bodies a period apart: refused."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(FileFormatError, match="the centres are .* apart") as caught:
            open_lmgc90(RUN)
    assert "\n" not in str(caught.value)


@pytest.mark.parametrize("period, error, message", [
    (-1.0, ParameterError, "x_period=-1.0: expected the period in x"),
    ("ten", ParameterError, "x_period='ten': expected the period in x"),
    (3.0, FileFormatError, "lies outside the periodic cell .x from 0 to x_period = 3. by more than its diameter"),
    (10.5, FileFormatError, "the contact of body"),
])
def test_a_wrong_period_is_refused_in_one_line(period, error, message):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(error, match=message) as caught:
            open_lmgc90(RUN, x_period=period)
    assert "\n" not in str(caught.value)


def test_a_wall_across_the_periodic_direction_is_refused():
    with pytest.raises(FileFormatError, match="a vertical JONCx, stands across x, the periodic direction") as caught:
        open_lmgc90(DATA / "sample", x_period=10.0)
    assert "\n" not in str(caught.value)


def _lmgc90():
    spec = importlib.util.spec_from_file_location("lmgc90_make_fixtures", DATA / "make_fixtures.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.slow
@pytest.mark.skipif(_lmgc90().find_build() is None,
                    reason="LMGC90 is not built (tests/data/lmgc90/build_lmgc90.sh, or set LMGC90_BUILD)")
def test_a_fresh_periodic_run_equals_the_hand_computation(tmp_path):
    folder = _lmgc90().run(tmp_path / "run", "periodic", seed=97)
    for sub in ("DATBOX", "OUTBOX"):  # what the committed fixture keeps
        assert (folder / sub).is_dir()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fresh = open_lmgc90(folder, x_period=PERIOD)
    grainview.validate(fresh)
    hand = by_hand(folder)
    stress = fresh.grain.stress_tensor().values
    for k, h in enumerate(hand):
        low, high = h["y"]
        moment = sum((np.outer(f, b) for f, b, *_ in h["pairs"].values()), np.zeros((2, 2)))
        moment += sum((np.outer(f, a) for f, a in h["walls"]), np.zeros((2, 2)))
        volume = PERIOD * (high - low)
        np.testing.assert_allclose(stress[k], moment / volume, rtol=1e-12, atol=1e-12 * np.abs(moment).max() / volume)
    shutil.rmtree(folder)


def test_the_command_line_and_the_xarray_engine_take_the_period(tmp_path, capsys):
    import xarray as xr

    from grainview.app.cli import main

    out = tmp_path / "periodic.nc"
    assert main(["convert", "lmgc90", str(RUN), "--x-period", str(PERIOD), "--out", str(out), "--progress", "off"]) == 0
    written = grainview.open_dataset(out)
    np.testing.assert_array_equal(written["periodic"].values, [1, 0])
    by_engine = xr.open_dataset(RUN, engine="lmgc90", x_period=PERIOD)
    np.testing.assert_array_equal(by_engine["cell"].values, written["cell"].values)
    np.testing.assert_array_equal(by_engine["branch"].values, written["branch"].values)
