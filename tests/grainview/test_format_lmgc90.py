"""The LMGC90 reader on what LMGC90 itself wrote: tests/data/lmgc90/ holds two real runs (their
DATBOX and OUTBOX files), made by gen_sample.py and command.py with the LMGC90 that
build_lmgc90.sh builds (make_fixtures.py ran them):

* ``sample``: 36 pentagons and 12 disks settling under gravity in a box of four JONCx walls
  (friction 0.4), snapshots at steps 100, 200 (flowing), 499 and 500 (at rest);
* ``handmade``: bodies at rest whose forces are known by hand (a disk on a floor under a second
  disk, two squares stacked face to face, a square on a floor tilted by 0.2 rad, a disk on a
  square), snapshots at steps 19 and 20.

Every check compares the reader's dataset with numbers taken from the files by a separate,
plain-Python parse (Fortran's fixed columns), with a balance law, or with forces computed by hand.
"""

from __future__ import annotations

import importlib.util
import math
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import grainview
from grainview.contract.errors import FileFormatError
from grainview.formats.lmgc90 import centred_polygon, convert_lmgc90, open_lmgc90, regular_polygon
from grainview.formats.lmgc90_text import fortran_float

DATA = Path(__file__).resolve().parents[1] / "data" / "lmgc90"
SAMPLE, HANDMADE = DATA / "sample", DATA / "handmade"
G = 9.81  # gen_sample.py: gravity (0, -9.81)
DENSITY = 1000.0  # gen_sample.py: every material
H = {"sample": 1e-2, "handmade": 1e-3}  # command.py: time steps


# --- a plain parse of the files, by Fortran's fixed columns -----------------------------------

def number(text):
    return float(text.strip().replace("D", "E"))


def plain_bodies(run):
    """{body number: (contactor type, reference x, y, avrd, [vertices])} of BODIES.DAT."""
    out, lines = {}, (run / "DATBOX" / "BODIES.DAT").read_text().splitlines()
    for k, line in enumerate(lines):
        if line == "$bdyty":
            body = int(lines[k + 1].split()[1])
            avrd = number(lines[k + 3].split("avrd=")[1].split("gyrd=")[0])
            node = lines[k + 5]
            x, y = number(node.split("coo1=")[1][:15]), number(node.split("coo2=")[1][:15])
            kind = lines[k + 7].split()[0]
            vertices = []
            m = k + 8
            while lines[m].strip().startswith("coo1="):
                vertices.append((number(lines[m].split("coo1=")[1][:15]), number(lines[m].split("coo2=")[1][:15])))
                m += 1
            out[body] = (kind, x, y, avrd, vertices)
    return out


def plain_dof(path):
    """{body number: (X(1), X(2), X(3), V(1), V(2), V(3))} of a DOF.OUT file, values read at
    the columns of LMGC90's format (1X,A5,2X,I5,16X,3(2X,A5,D14.7))."""
    out, lines = {}, Path(path).read_text().splitlines()
    for k, line in enumerate(lines):
        if line == "$bdyty":
            body = int(lines[k + 1].split()[1])
            x, v = lines[k + 3], lines[k + 4]
            out[body] = tuple(number(x[c:c + 14]) for c in (34, 55, 76)) + tuple(number(v[c:c + 14])
                                                                               for c in (34, 55, 76))
    return out


def plain_vloc(path):
    """The entries of a Vloc_Rloc.OUT file as dicts, values read at the columns of LMGC90's
    format (1X,5X,2X,5X,2X,5X,2X,5X,3(2X,A5,D14.7))."""
    out, lines = [], Path(path).read_text().splitlines()
    for k, line in enumerate(lines):
        if line.startswith("$icdan"):
            title, data = lines[k + 1].split(), lines[k + 2].split()
            rows = lines[k + 3:k + 8]
            assert [r[29:34] for r in rows] == ["rlt/H", "vlt =", "gapTT", "n(1)=", "coo1="]
            value = lambda r, c: number(rows[r][34 + 21 * c:48 + 21 * c])  # noqa: E731
            out.append(dict(family=line.split()[1], cd=int(data[1]), an=int(data[title.index("anbdy") + 1]),
                            rlt=value(0, 0), rln=value(0, 1), gap=value(2, 0), n=np.array([value(3, 0), value(3, 1)]),
                            point=np.array([value(4, 0), value(4, 1)])))
    return out


def particle_bodies(run):
    """Body numbers of the particles (DISKx, POLYG) and of the walls (JONCx), in file order."""
    bodies = plain_bodies(run)
    return ([b for b, v in bodies.items() if v[0] != "JONCx"], [b for b, v in bodies.items() if v[0] == "JONCx"])


@pytest.fixture(scope="module")
def sample():
    return open_lmgc90(SAMPLE)


@pytest.fixture(scope="module")
def handmade():
    return open_lmgc90(HANDMADE)


# --- the runs as LMGC90 wrote them ------------------------------------------------------------

def test_the_fixtures_are_real_lmgc90_runs(sample, handmade):
    assert sample.attrs["source"] == "LMGC90"
    assert sample.sizes["particle"] == 48 and list(sample["step"].values) == [100, 200, 499, 500]
    np.testing.assert_allclose(sample["time"].values, [1.0, 2.0, 4.99, 5.0], rtol=1e-12)
    assert np.bincount(sample["n_vertices"].values).tolist()[::5] == [12, 36]  # 12 disks, 36 pentagons
    assert list(sample["wall"].values) == ["bottom", "right", "top", "left"]
    assert list(handmade["wall"].values) == ["jonc1", "jonc4", "jonc7", "jonc9"]  # not a box
    bodies = plain_bodies(SAMPLE)
    particles, _ = particle_bodies(SAMPLE)
    avrd = np.array([bodies[b][3] for b in particles])
    np.testing.assert_allclose(sample["mass"], DENSITY * np.pi * avrd**2, rtol=1e-15)
    disks = sample["n_vertices"].values == 0
    np.testing.assert_allclose(sample["radius"].values[disks], avrd[disks], rtol=1e-15)  # a disk's avrd is its radius
    # the box: the inner faces of the four walls of gen_sample.py (8 x 1.25 m by 6 x 1.25 + 2 m)
    np.testing.assert_allclose(sample["box_min"].values, 0.0, atol=1e-12)
    np.testing.assert_allclose(sample["box_max"].values, [[10.0, 9.5]] * 4, rtol=1e-12)


def test_positions_are_reference_plus_displacement(sample):
    bodies = plain_bodies(SAMPLE)
    particles, _ = particle_bodies(SAMPLE)
    for k in range(sample.sizes["time"]):
        dof = plain_dof(SAMPLE / "OUTBOX" / f"DOF.OUT.{k + 1}")
        expected = np.array([[bodies[b][1] + dof[b][0], bodies[b][2] + dof[b][1]] for b in particles])
        np.testing.assert_allclose(sample["position"].values[k], expected, rtol=0, atol=1e-14)
        np.testing.assert_allclose(sample["velocity"].values[k], [dof[b][3:5] for b in particles], rtol=0, atol=0)
        np.testing.assert_allclose(sample["angular_velocity"].values[k], [dof[b][5] for b in particles], rtol=0,
                                   atol=0)


def test_polygon_vertices_are_where_lmgc90_puts_them(sample):
    """The contract's regular n-gon (vertex k at angle + 2 pi k / n) has the vertices of
    BODIES.DAT, rotated by X(3) and moved by X(1:2), as sets."""
    bodies = plain_bodies(SAMPLE)
    particles, _ = particle_bodies(SAMPLE)
    k = sample.sizes["time"] - 1
    dof = plain_dof(SAMPLE / "OUTBOX" / f"DOF.OUT.{k + 1}")
    checked = 0
    for p, b in enumerate(particles):
        vertices = np.array(bodies[b][4])
        if not vertices.size:
            continue
        c, s = math.cos(dof[b][2]), math.sin(dof[b][2])
        lmgc = vertices @ np.array([[c, s], [-s, c]]) + [bodies[b][1] + dof[b][0], bodies[b][2] + dof[b][1]]
        n = int(sample["n_vertices"][p])
        angles = float(sample["angle"][k, p]) + 2 * np.pi * np.arange(n) / n
        ours = sample["position"].values[k, p] + float(sample["radius"][p]) * np.stack([np.cos(angles),
                                                                                        np.sin(angles)], 1)
        distance = np.hypot(*(lmgc[:, None, :] - ours[None, :, :]).transpose(2, 0, 1))
        assert distance.min(axis=1).max() < 1e-6 * float(sample["radius"][p])
        checked += 1
    assert checked == 36


def test_fortran_numbers():
    assert fortran_float(" 0.2773712D+04") == 2773.712
    assert fortran_float("-0.6328271D-14") == -0.6328271e-14
    assert fortran_float(" 5.6568542E-01") == 0.56568542
    assert fortran_float("-0.1234567+100") == -0.1234567e100  # D14.7 drops the D of a 3-digit exponent
    with pytest.raises(ValueError):
        fortran_float("*************")  # what Fortran writes for a number too wide for its field


def test_regular_polygon_finds_radius_count_and_offset():
    phi = 0.3
    square = [(2 * math.cos(phi + k * math.pi / 2), 2 * math.sin(phi + k * math.pi / 2)) for k in (0, 3, 1, 2)]
    radius, n, offset = regular_polygon(square)
    assert (n, radius, offset) == (4, pytest.approx(2.0, rel=1e-15), pytest.approx(phi, rel=1e-15))
    assert regular_polygon([(1, 0), (0, 1), (-1, 0), (0, -1.01)]) is None  # one vertex off the circle
    assert regular_polygon([(1, 0), (0, 1), (-1, 0), (0.6, -0.8)]) is None  # on the circle, unevenly spaced
    assert regular_polygon([(2, 0), (1, 1), (0, 0), (1, -1)]) is None  # a square off the body's node


def test_centred_polygon_by_hand():
    """A right triangle given clockwise around a point off its centroid: reversed to
    counter-clockwise and shifted by its centroid (1, 1) (legs 3 and 3 from (0, 0): centroid at
    a third of each leg)."""
    v, g = centred_polygon([(0, 0), (0, 3), (3, 0)])
    np.testing.assert_allclose(g, [1.0, 1.0], rtol=0, atol=1e-15)
    np.testing.assert_allclose(v, [[2, -1], [-1, 2], [-1, -1]], rtol=0, atol=1e-15)  # (3,0), (0,3), (0,0) - g
    assert centred_polygon([(0, 0), (2, 0), (0.5, 0.5), (0, 2)]) is None  # a dart: not convex
    assert centred_polygon([(0, 0), (1, 0)]) is None


def test_an_irregular_polygon_keeps_lmgc90_vertices(tmp_path):
    """The first POLYG stretched to a kite (its first vertex moved from x = 0.525 to 1.525 m,
    so the body's node is far from the polygon's centroid): stored by its vertices, and
    position + Rot(angle) v_k is LMGC90's vertex k, reference + X(1:2) + Rot(X(3)) u_k, in every
    snapshot; the other polygons are the regular ones of the file without it."""
    from grainview.contract.shapes import body_vertices, polygon_properties, world_vertices
    from grainview.contract.validation import validate

    folder = _copy(tmp_path, "kite", ("DATBOX/BODIES.DAT", _irregular))
    ds, regular = open_lmgc90(folder), open_lmgc90(SAMPLE)
    validate(ds)
    bodies = plain_bodies(folder)
    particles, _ = particle_bodies(folder)
    u = np.array(bodies[particles[0]][4])
    assert u[0, 0] == pytest.approx(1.52501909, rel=1e-9)
    vertices = ds["vertices"].values
    assert vertices.shape == (48, 5, 2) and int(ds["n_vertices"][0]) == 5
    kite = polygon_properties(u[None])
    np.testing.assert_allclose(vertices[0], u - kite["centroid"][0], rtol=0, atol=1e-14)
    assert float(ds["radius"][0]) == pytest.approx(np.hypot(*(u - kite["centroid"][0]).T).max(), rel=1e-15)
    others = np.arange(1, 48)
    np.testing.assert_array_equal(vertices[others], body_vertices(regular["radius"].values[others],
                                                                  regular["n_vertices"].values[others])[:, :5])
    np.testing.assert_array_equal(ds["angle"].values[:, others], regular["angle"].values[:, others])
    np.testing.assert_array_equal(ds["position"].values[:, others], regular["position"].values[:, others])
    for k in range(ds.sizes["time"]):
        dof = plain_dof(folder / "OUTBOX" / f"DOF.OUT.{k + 1}")[particles[0]]
        c, s = math.cos(dof[2]), math.sin(dof[2])
        lmgc = u @ np.array([[c, s], [-s, c]]) + [bodies[particles[0]][1] + dof[0], bodies[particles[0]][2] + dof[1]]
        ours = world_vertices(ds["position"].values[k], ds["angle"].values[k], vertices)[0]
        np.testing.assert_allclose(ours, lmgc, rtol=0, atol=1e-13)
        assert float(ds["angle"][k, 0]) == dof[2]
    # the solid fraction counts the kite's shoelace area instead of the pentagon's
    before = regular.grain.solid_fraction().values * (regular["box_max"] - regular["box_min"]).prod("xy").values
    after = ds.grain.solid_fraction().values * (ds["box_max"] - ds["box_min"]).prod("xy").values
    pentagon = 2.5 * float(regular["radius"][0]) ** 2 * math.sin(2 * math.pi / 5)
    np.testing.assert_allclose(after - before, kite["area"][0] - pentagon, rtol=1e-12)
    out = tmp_path / "kite.nc"
    convert_lmgc90(out, folder)
    with grainview.open_dataset(out) as on_file:
        np.testing.assert_array_equal(on_file["vertices"].values, vertices)
        np.testing.assert_array_equal(on_file["position"].values, ds["position"].values)


# --- contacts and forces ----------------------------------------------------------------------

def expected_contacts(run, k):
    """Contract contacts from the plain parse of Vloc_Rloc.OUT.k: {(i, j): (kind, fn, ft,
    normal, point)}, i < j body indices of the contract, by the rules of docs/formats.md."""
    particles, walls = particle_bodies(run)
    names = list(open_lmgc90(run)["wall"].values) if walls else []
    order = {"bottom": 0, "right": 1, "top": 2, "left": 3}
    index = {b: p for p, b in enumerate(particles)}
    if names and names[0] == "bottom":  # a box: walls by side
        dof = plain_dof(run / "OUTBOX" / f"DOF.OUT.{k}")
        bodies = plain_bodies(run)
        side = {}
        for b in walls:
            x, y, a = bodies[b][1] + dof[b][0], bodies[b][2] + dof[b][1], dof[b][2]
            side[b] = ("bottom" if y < 0 else "top") if abs(math.sin(a)) < 1e-9 else ("left" if x < 0 else "right")
        index.update({b: len(particles) + order[side[b]] for b in walls})
    else:
        index.update({b: len(particles) + w for w, b in enumerate(walls)})
    pairs = {}
    for e in plain_vloc(run / "OUTBOX" / f"Vloc_Rloc.OUT.{k}"):
        pairs.setdefault(tuple(sorted((index[e["cd"]], index[e["an"]]))), []).append(e)
    out = {}
    for (i, j), entries in pairs.items():
        rln = sum(e["rln"] for e in entries)
        if rln <= 0:
            continue
        # LMGC90: n from the antagonist to the candidate, the force on the candidate rln n + rlt t,
        # t = (n_y, -n_x); the contract: normal from i to j, the force of i on j
        i_is_cd = index[entries[0]["cd"]] == i
        normal = -entries[0]["n"] if i_is_cd else entries[0]["n"]
        force = sum((e["rln"] * e["n"] + e["rlt"] * np.array([e["n"][1], -e["n"][0]])) * (-1 if i_is_cd else 1)
                    for e in entries)
        point = sum(e["rln"] * e["point"] for e in entries) / rln
        out[(i, j)] = (len(entries), force @ normal, force @ np.array([-normal[1], normal[0]]), normal, point)
    return out


@pytest.mark.parametrize("run", ["sample", "handmade"])
def test_contacts_are_the_files_entries_pair_by_pair(run, sample, handmade):
    ds = {"sample": sample, "handmade": handmade}[run]
    for k in range(ds.sizes["time"]):
        count = int(ds["contact_count"][k])
        got = {(int(i), int(j)): m for m, (i, j) in enumerate(zip(ds["i"].values[k, :count],
                                                                   ds["j"].values[k, :count]))}
        expected = expected_contacts(DATA / run, k + 1)
        assert set(got) == set(expected)
        for key, (kind, fn, ft, normal, point) in expected.items():
            m = got[key]
            assert int(ds["kind"][k, m]) == kind
            assert float(ds["fn"][k, m]) == pytest.approx(fn, rel=1e-12)
            assert float(ds["ft"][k, m]) == pytest.approx(ft, rel=1e-9, abs=1e-9 * fn)
            np.testing.assert_allclose(ds["normal"].values[k, m], normal, rtol=0, atol=1e-15)
            np.testing.assert_allclose(ds["point"].values[k, m], point, rtol=1e-12, atol=1e-12)
    assert (ds["kind"].values == 2).any() and (ds["kind"].values == 1).any()


def net_contact_force_and_torque(ds, k):
    """Sum over each particle's contacts of the force on it (N, 2), of its torque about the
    centre (N,) and of the forces' magnitudes (N,), from the contract's variables."""
    n = ds.sizes["particle"]
    count = int(ds["contact_count"][k])
    i, j = ds["i"].values[k, :count], ds["j"].values[k, :count]
    normal = ds["normal"].values[k, :count]
    f = ds["fn"].values[k, :count, None] * normal + ds["ft"].values[k, :count, None] * np.stack(
        [-normal[:, 1], normal[:, 0]], 1)  # by i on j
    point, x = ds["point"].values[k, :count], ds["position"].values[k]
    force, torque, size = np.zeros((n, 2)), np.zeros(n), np.zeros(n)
    cross = lambda a, b: a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]  # noqa: E731
    np.add.at(force, i, -f)
    np.add.at(torque, i, cross(point - x[i], -f))
    np.add.at(size, i, np.hypot(f[:, 0], f[:, 1]))
    pairs = j < n
    np.add.at(force, j[pairs], f[pairs])
    np.add.at(torque, j[pairs], cross(point[pairs] - x[j[pairs]], f[pairs]))
    np.add.at(size, j[pairs], np.hypot(f[pairs, 0], f[pairs, 1]))
    return force, torque, size


@pytest.mark.parametrize("run", ["sample", "handmade"])
def test_every_particle_balances_over_the_last_step(run, sample, handmade):
    """Moreau-Jean: m (v_end - v_begin) / H = m g + sum of the contact forces (the impulses over
    H) on each particle, and I (w_end - w_begin) / H = sum of their torques, over the step
    between the last two snapshots (consecutive steps). This fixes every sign: the normal's,
    the tangent's, the force's side, and the contact point (a double contact's resultant at the
    fn-weighted mean of its points has the torque of its two point forces).

    To the precision of the numbers LMGC90 writes (7 significant digits, ``D14.7``): a
    particle's forces are known to about 5e-7 of the sum of their magnitudes S, its torques to
    about 5e-7 S (|x| + r) (the contact points' coordinates, up to 20 m here, are rounded too);
    the tolerances are twice that."""
    ds = {"sample": sample, "handmade": handmade}[run]
    force, torque, size = net_contact_force_and_torque(ds, -1)
    m, inertia = ds["mass"].values, ds["inertia"].values
    dv = (ds["velocity"].values[-1] - ds["velocity"].values[-2]) / H[run]
    dw = (ds["angular_velocity"].values[-1] - ds["angular_velocity"].values[-2]) / H[run]
    reach = np.hypot(*ds["position"].values[-1].T) + ds["radius"].values
    assert np.all(size > 0)  # every particle is loaded
    assert np.all(np.abs(force + m[:, None] * [0.0, -G] - m[:, None] * dv) <= 1e-6 * size[:, None])
    assert np.all(np.abs(torque - inertia * dw) <= 1e-6 * size * reach)
    # the check has teeth: a tangential force of the wrong sign breaks the balance by far
    force, torque, size = net_contact_force_and_torque(ds.assign(ft=-ds["ft"]), -1)
    assert np.abs(force - m[:, None] * [0.0, G]).max() > 1e3 * (1e-6 * size).max()


def test_at_rest_the_contact_stress_equals_the_walls_stress(sample):
    """Love-Weber: for a packing at rest, sum_c f (x) l = sum over the walls' contacts of
    f (x) r_c - sum_p m_p g (x) x_p (each particle's contact forces balance its weight), so the
    stress of the accessor times the box's area equals the moment of the forces the walls
    receive, taken from the files' entries directly."""
    k = sample.sizes["time"] - 1
    assert float(np.abs(sample["velocity"][k]).max()) < 1e-12  # at rest
    area = float(np.prod(sample["box_max"][k] - sample["box_min"][k]))
    moment = np.zeros((2, 2))
    walls_received = np.zeros((4, 2))
    _, walls = particle_bodies(SAMPLE)
    side = {b: w for w, b in enumerate(walls)}  # gen_sample.py's order: bottom, top, left, right
    contract_order = [0, 2, 3, 1]  # -> bottom, right, top, left
    on_walls = {}  # (particle body, wall body) -> [(force on the wall, rln, point)]
    for e in plain_vloc(SAMPLE / "OUTBOX" / f"Vloc_Rloc.OUT.{k + 1}"):
        if e["an"] in side:
            on_wall = -(e["rln"] * e["n"] + e["rlt"] * np.array([e["n"][1], -e["n"][0]]))
            on_walls.setdefault((e["cd"], e["an"]), []).append((on_wall, e["rln"], e["point"]))
            walls_received[contract_order[side[e["an"]]]] += on_wall
    pointwise = np.zeros((2, 2))
    for (_, wall), points in on_walls.items():
        total = sum(f for f, _, _ in points)
        at = sum(rln * point for _, rln, point in points) / sum(rln for _, rln, _ in points)
        moment += np.outer(total, at)  # a face on a wall: the resultant at the fn-weighted point
        pointwise += sum(np.outer(f, point) for f, _, point in points)
    x = sample["position"].values[k]
    moment -= np.einsum("p,i,pj->ij", sample["mass"].values, [0.0, -G], x)
    np.testing.assert_allclose(sample.grain.stress_tensor()[k].values * area, moment, rtol=0,
                               atol=1e-6 * np.abs(moment).max())
    np.testing.assert_allclose(sample["wall_force"].values[k], walls_received, rtol=1e-12, atol=1e-9)
    # the walls carry the whole weight
    assert walls_received[:, 1].sum() == pytest.approx(-G * float(sample["mass"].sum()), rel=1e-6)
    # The resultant of a face-to-wall contact at the fn-weighted point has the two points' force
    # and torque, not their whole moment: the tangential forces' spread along the face (the
    # part sum_k ft_k (s_k - s) t (x) t) is lost. Here that is 2.5 % of sigma_xx: the bottom
    # wall's friction forces pull in opposite directions at the two ends of the faces on it.
    lost = pointwise - (moment + np.einsum("p,i,pj->ij", sample["mass"].values, [0.0, -G], x))
    assert abs(lost[0, 0]) > 0.02 * moment[0, 0] and np.abs(lost[1]).max() < 1e-6 * np.abs(moment).max()


def test_signs_on_hand_made_bodies(handmade):
    """Forces known by hand: each body at rest carries the weight above it."""
    ds, k = handmade, -1
    count = int(ds["contact_count"][k])
    pair = {(int(i), int(j)): m for m, (i, j) in enumerate(zip(ds["i"].values[k, :count], ds["j"].values[k, :count]))}
    n = ds.sizes["particle"]  # 0, 1 disks; 2, 3 stacked squares; 4 tilted square; 5 square, 6 disk on it
    big, small, square, little = (DENSITY * np.pi * 0.5**2, DENSITY * np.pi * 0.3**2, DENSITY * 0.8**2,
                                  DENSITY * np.pi * 0.25**2)

    def check(i, j, kind, fn, ft, normal, point=None):
        m = pair[(i, j)]
        assert int(ds["kind"][k, m]) == kind
        assert float(ds["fn"][k, m]) == pytest.approx(fn, rel=1e-6)
        assert float(ds["ft"][k, m]) == pytest.approx(ft, abs=1e-6 * fn)
        np.testing.assert_allclose(ds["normal"].values[k, m], normal, atol=1e-6)  # LMGC90's n: 7 digits
        if point is not None:
            np.testing.assert_allclose(ds["point"].values[k, m], point, atol=1e-9)

    check(0, 1, 1, small * G, 0.0, [0, 1], [0.0, 1.0])  # disk on disk: i below, normal up
    check(0, n + 0, 1, (big + small) * G, 0.0, [0, -1], [0.0, 0.0])  # disk on the floor: normal to the wall
    check(2, 3, 2, square * G, 0.0, [0, 1], [6.0, 0.8])  # two PLPLx points, one double contact
    check(2, n + 1, 2, 2 * square * G, 0.0, [0, -1], [6.0, 0.0])  # a face on a floor: two PLJCx points
    alpha = 0.2
    # tilted floor: the square pushes it down the slope; t = (-n_y, n_x) points up the slope
    check(4, n + 2, 2, square * G * math.cos(alpha), -square * G * math.sin(alpha),
          [math.sin(alpha), -math.cos(alpha)])
    check(5, 6, 1, little * G, 0.0, [0, 1], [18.0, 0.8])  # disk (DKPLx candidate) on a square
    check(5, n + 3, 2, (square + little) * G, 0.0, [0, -1])
    assert count == 7


def test_lmgc90s_own_conventions_on_the_hand_made_bodies():
    """What the reader relies on, in LMGC90's raw numbers: n points from the antagonist to the
    candidate, rln > 0 in compression, and the friction on the candidate is rlt t with
    t = (n_y, -n_x)."""
    entries = plain_vloc(HANDMADE / "OUTBOX" / "Vloc_Rloc.OUT.2")
    dkdk = next(e for e in entries if e["family"] == "DKDKx")
    assert (dkdk["cd"], dkdk["an"]) == (2, 3)  # the lower disk is the candidate
    np.testing.assert_allclose(dkdk["n"], [0, -1], atol=1e-15)  # from the upper disk (antagonist) down
    assert dkdk["rln"] == pytest.approx(DENSITY * np.pi * 0.3**2 * G, rel=1e-6)
    tilted = [e for e in entries if e["family"] == "PLJCx" and e["an"] == 7]
    assert len(tilted) == 2
    friction = sum(e["rlt"] * np.array([e["n"][1], -e["n"][0]]) for e in tilted)  # on the square
    up_the_slope = np.array([math.cos(0.2), math.sin(0.2)])
    np.testing.assert_allclose(friction, DENSITY * 0.8**2 * G * math.sin(0.2) * up_the_slope, rtol=1e-6)


def test_a_double_contact_is_its_two_entries_summed():
    entries = [e for e in plain_vloc(HANDMADE / "OUTBOX" / "Vloc_Rloc.OUT.2") if e["family"] == "PLPLx"]
    assert len(entries) == 2 and {(e["cd"], e["an"]) for e in entries} == {(5, 6)}
    ds = open_lmgc90(HANDMADE)
    count = int(ds["contact_count"][-1])
    m = [(int(i), int(j)) for i, j in zip(ds["i"].values[-1, :count], ds["j"].values[-1, :count])].index((2, 3))
    assert int(ds["kind"][-1, m]) == 2
    assert float(ds["fn"][-1, m]) == pytest.approx(entries[0]["rln"] + entries[1]["rln"], rel=1e-15)
    assert float(ds["ft"][-1, m]) == pytest.approx(-(entries[0]["rlt"] + entries[1]["rlt"]), abs=1e-9)
    weights = np.array([e["rln"] for e in entries])
    np.testing.assert_allclose(ds["point"].values[-1, m], weights @ np.array([e["point"] for e in entries])
                               / weights.sum(), rtol=1e-15)


# --- the three ways in, and bad input ---------------------------------------------------------

def test_the_file_the_backend_and_the_reader_agree(sample, tmp_path):
    out = tmp_path / "run.nc"
    assert convert_lmgc90(out, SAMPLE) == 4
    assert sorted(os.listdir(tmp_path)) == ["run.nc"]  # no temporary left
    on_file = grainview.open_dataset(out, chunks=None, validate=True)
    backend = xr.open_dataset(SAMPLE, engine="lmgc90")
    through = grainview.open_dataset(SAMPLE, format="lmgc90", chunks=None)
    for other in (on_file, backend, through):
        for name, var in sample.data_vars.items():
            np.testing.assert_array_equal(other[name].values, var.values, err_msg=name)
    with pytest.raises(FileExistsError, match="exists"):
        convert_lmgc90(out, SAMPLE)


def _copy(tmp_path, name, edit=None):
    folder = tmp_path / name
    shutil.copytree(SAMPLE, folder)
    if edit is not None:
        target, change = edit
        path = folder / target
        if change is None:
            path.unlink()
        else:
            path.write_text(change(path.read_text()))
    return folder


def _irregular(text):
    """The first POLYG with one vertex moved off its circle, outwards (x 0.525 -> 1.525 m):
    still convex."""
    head, tail = text.split("POLYG", 1)
    line = tail.split("\n")[1]
    moved = line.replace("coo1= ", "coo1= 1", 1) if "coo1= " in line else line.replace("coo1=-", "coo1=-1", 1)
    return head + "POLYG" + tail.replace(line, moved, 1)


def _concave(text):
    """The first POLYG with its first vertex (on the x axis) pulled to a tenth of its
    distance: inside the chord of its neighbours, so the outline turns clockwise there."""
    head, tail = text.split("POLYG", 1)
    line = tail.split("\n")[1]
    assert "coo1= 5.2501909E-01" in line
    return head + "POLYG" + tail.replace(line, line.replace("E-01", "E-02", 1), 1)


@pytest.mark.parametrize("name,edit,match", [
    ("truncated-vloc", ("OUTBOX/Vloc_Rloc.OUT.3", lambda t: t[:len(t) * 2 // 3]), "truncated Vloc_Rloc"),
    ("truncated-dof", ("OUTBOX/DOF.OUT.2", lambda t: t[:len(t) // 2]), "truncated DOF.OUT"),
    ("unknown-contactor", ("DATBOX/BODIES.DAT", lambda t: t.replace("DISKx", "xKSID", 1)),
     "unknown contactor type 'xKSID'"),
    ("unknown-family", ("OUTBOX/Vloc_Rloc.OUT.4", lambda t: t.replace("PLPLx", "PLALp", 1)),
     "unknown contactor type: contact family 'PLALp'"),
    ("no-bodies", ("DATBOX/BODIES.DAT", None), "no DATBOX/BODIES.DAT"),
    ("no-vloc", ("OUTBOX/Vloc_Rloc.OUT.2", None), "DOF.OUT.2 has no Vloc_Rloc.OUT.2"),
    ("concave", ("DATBOX/BODIES.DAT", _concave),
     "body 1: a POLYG whose vertices are not a convex polygon (the contract holds convex polygons only)"),
    ("steps", ("OUTBOX/Vloc_Rloc.OUT.2", lambda t: t.replace("$steps      200", "$steps      201")),
     "must be of the same step"),
    ("not-lmgc90", ("OUTBOX/DOF.OUT.1", lambda t: "hello\n" + t), "not an LMGC90 OUTBOX file"),
    ("appended", ("OUTBOX/Vloc_Rloc.OUT.4", lambda t: t + t), "a second '$steps' record"),
    # a number garbled inside its field: its leading digits alone ("0.") are no value to keep
    ("garbled-dof", ("OUTBOX/DOF.OUT.2", lambda t: t.replace("X(1)= 0.", "X(1)= 0.#", 1)),
     "cannot read the body block"),
    ("garbled-vloc", ("OUTBOX/Vloc_Rloc.OUT.3", lambda t: re.sub(r"rln/H 0\.(\d)", r"rln/H 0.\1#", t, count=1)),
     "entry without rln/H"),
])
def test_bad_input_gets_one_line_and_writes_nothing(tmp_path, name, edit, match):
    folder = _copy(tmp_path, name, edit)
    out = tmp_path / f"{name}.nc"
    with pytest.raises(FileFormatError, match=re.escape(match)) as info:
        convert_lmgc90(out, folder)
    assert "\n" not in str(info.value)
    assert not out.exists()
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_the_command_line_converts_and_refuses_in_one_line(tmp_path):
    out = tmp_path / "run.nc"
    done = subprocess.run([sys.executable, "-m", "grainview", "convert", "lmgc90", str(HANDMADE), "--out",
                           str(out), "--progress", "off"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "2 snapshots from LMGC90" in done.stdout
    folder = _copy(tmp_path, "bad", ("DATBOX/BODIES.DAT", None))
    bad = subprocess.run([sys.executable, "-m", "grainview", "convert", "lmgc90", str(folder), "--out",
                          str(tmp_path / "bad.nc")], capture_output=True, text=True)
    assert bad.returncode != 0 and len(bad.stderr.strip().splitlines()) == 1, bad.stderr
    assert "no DATBOX/BODIES.DAT" in bad.stderr and not (tmp_path / "bad.nc").exists()


def _lmgc90():
    """tests/data/lmgc90/make_fixtures.py, loaded under its own name (the LAMMPS fixtures'
    script has the same file name)."""
    spec = importlib.util.spec_from_file_location("lmgc90_make_fixtures", DATA / "make_fixtures.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.skipif(_lmgc90().find_build() is None,
                    reason="LMGC90 is not built (tests/data/lmgc90/build_lmgc90.sh, or set LMGC90_BUILD)")
def test_a_fresh_lmgc90_run_converts_and_checks(tmp_path):
    """LMGC90 runs the sample anew with another seed (a run no other test has seen); the
    converted file passes `grainview info --check` and balances every particle over its last
    step. The hand-made run, made again, reads as the committed one."""
    folder = _lmgc90().run(tmp_path / "run", "sample", seed=97)
    out = tmp_path / "fresh.nc"
    done = subprocess.run([sys.executable, "-m", "grainview", "convert", "lmgc90", str(folder), "--out", str(out),
                           "--progress", "off"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    check = subprocess.run([sys.executable, "-m", "grainview", "info", str(out), "--check"], capture_output=True,
                           text=True)
    assert check.returncode == 0 and "valid" in check.stdout, check.stdout + check.stderr
    fresh = grainview.open_dataset(out, chunks=None)
    assert (fresh["kind"].values == 2).any()
    test_every_particle_balances_over_the_last_step("sample", fresh, None)
    # the hand-made bodies (at rest: no chaos to amplify round-off) come out as committed
    again = open_lmgc90(_lmgc90().run(tmp_path / "handmade", "handmade"))
    committed = open_lmgc90(HANDMADE)
    for name, var in committed.data_vars.items():
        if var.dtype.kind == "f":
            np.testing.assert_allclose(again[name].values, var.values, rtol=1e-9, atol=1e-9, err_msg=name)
        else:
            np.testing.assert_array_equal(again[name].values, var.values, err_msg=name)
