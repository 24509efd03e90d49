"""The PeGS2 reader against PeGS2's own output.

PeGS2 is MATLAB and cannot run here: the fixtures (tests/data/pegs/, origins in its README.md)
are real PeGS2 output from public repositories (the adjacency list and tracked positions of frame
1 of the Step09 test images, and the same frame's untracked centres). The expected values are
computed from those files' text with numpy, never with the reader.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import grainview
from grainview.contract.errors import FileFormatError, ParameterError
from grainview.formats.pegs import convert_pegs, open_pegs

DATA = Path(__file__).resolve().parents[1] / "data" / "pegs"
ADJACENCY, POSITIONS, CENTRES = DATA / "Adjacency_list.txt", DATA / "particle_positions.txt", \
    DATA / "Step09-0001_centers.txt"
SCALE = 4.375e-5  # contactDetect_params.txt: metersperpixel
FORCE = 1.0  # a calibrated solve: newtons
EDGE_NORMAL = {2: (0.0, -1.0), 1: (1.0, 0.0), -2: (0.0, 1.0), -1: (-1.0, 0.0)}  # image bottom is the contract's bottom
WALLS = {2: 0, 1: 1, -2: 2, -1: 3}


def read(**options):
    options = {"metres_per_pixel": SCALE, "force_unit_n": FORCE, **options}
    return open_pegs(ADJACENCY, POSITIONS, **options)


@pytest.fixture(scope="module")
def ds():
    return read()


@pytest.fixture(scope="module")
def raw():
    adjacency = np.array([[float(v) for v in line.split(",")] for line in ADJACENCY.read_text().splitlines()])
    positions = np.array([[float(v) for v in line.split(",")] for line in POSITIONS.read_text().splitlines()])
    return adjacency, positions


def cartesian(positions):
    """Particle index -> (centre in m, radius in m, edge flag): ids 1..29 are indices 0..28; image
    rows grow downward, so y is flipped about the lowest disk edge."""
    y0 = (positions[:, 3] + positions[:, 4]).max()
    centre = np.column_stack([positions[:, 2], y0 - positions[:, 3]]) * SCALE
    return centre, positions[:, 4] * SCALE, positions[:, 5].astype(int)


def expected_contacts(adjacency, positions):
    """{(i, j): (force exerted by i on j, normal from i to j)}: a pair's force is the mean of the
    rows fitted on its two disks (fn = N, ft = T along t = (-n_y, n_x)); a wall row is the
    contact with the wall the disk's edge flag names."""
    centre, radius, edge = cartesian(positions)
    n = centre.shape[0]
    fits = {}
    for _, a, b, T, N in adjacency:
        a = int(a) - 1
        key = (a, n + WALLS[edge[a]]) if b < 0 else (min(a, int(b) - 1), max(a, int(b) - 1))
        fits.setdefault(key, []).append((N, T))
    out = {}
    for (i, j), values in fits.items():
        N, T = np.mean(values, axis=0)
        branch = centre[min(j, n - 1)] - centre[i]
        normal = np.array(EDGE_NORMAL[edge[i]]) if j >= n else branch / np.hypot(*branch)
        tangent = np.array([-normal[1], normal[0]])
        if N > 0:
            out[(i, j)] = (FORCE * (N * normal + T * tangent), normal)
    return out


def test_the_fixture_is_pegs2_output(raw):
    adjacency, positions = raw
    assert adjacency.shape == (58, 5) and set(adjacency[:, 0]) == {1}
    assert positions.shape == (29, 6)
    pairs = {(int(a), int(b)) for _, a, b, _, _ in adjacency if b > 0}
    assert all((b, a) in pairs for a, b in pairs)  # every pair fitted on both disks: 25 pairs, 50 rows
    assert len(pairs) == 50 and int((adjacency[:, 2] == -1).sum()) == 8


def test_contacts_are_the_mean_of_the_two_fits(ds, raw):
    expected = expected_contacts(*raw)
    count = int(ds["contact_count"][0])
    assert count == len(expected) == 33
    assert ds.attrs["pegs_pairs"] == "25 particle pairs fitted on both disks, 0 on one"
    for m in range(count):
        i, j = int(ds["i"][0, m]), int(ds["j"][0, m])
        force, normal = expected[(i, j)]
        np.testing.assert_allclose(ds["normal"][0, m].values, normal, rtol=0, atol=1e-15)
        assert float(ds["fn"][0, m]) == pytest.approx(force @ normal, rel=1e-12)
        assert float(ds["ft"][0, m]) == pytest.approx(force @ [-normal[1], normal[0]], rel=1e-9, abs=1e-18)


def test_a_disks_own_fit_balances_in_the_contracts_axes(raw, tmp_path):
    """PeGS2's forceBalance makes the two forces on a disk with two contacts equal and opposite.
    Read on their own (only that disk's rows), they must balance in the contract too: the sign
    convention of the tangential force and the flip of the image's y axis are right. Of the
    file's nine two-contact disks, one (id 13) was fitted with tensile forces, which the reader
    leaves out; six balance to round-off; the other two (ids 2, 26) balance only with the
    tangential sign mirrored, because PeGS2's two-contact branch sets alpha = acos(...) >= 0
    whatever the contacts' order: their sign is PeGS2's error, not the reader's (the mirrored
    convention would balance those two and none of the six)."""
    adjacency, positions = raw
    n = positions.shape[0]
    balanced, mirrored = set(), set()
    for particle in sorted({int(a) for a in adjacency[:, 1]}):
        rows = adjacency[adjacency[:, 1] == particle]
        if len(rows) != 2 or np.any(rows[:, 4] <= 0):
            continue
        path = tmp_path / f"only_{particle}.txt"
        path.write_text("\n".join(",".join(repr(float(v)) for v in row) for row in rows) + "\n")
        one = open_pegs(path, POSITIONS, metres_per_pixel=SCALE, force_unit_n=FORCE)
        assert int(one["contact_count"][0]) == 2
        total, total_mirrored = np.zeros(2), np.zeros(2)
        for m in range(2):
            i, j = int(one["i"][0, m]), int(one["j"][0, m])
            assert j >= n or particle - 1 in (i, j)
            normal = one["normal"][0, m].values
            tangent = np.array([-normal[1], normal[0]])
            sign = -1.0 if i == particle - 1 else 1.0  # the force on the disk
            total += sign * (float(one["fn"][0, m]) * normal + float(one["ft"][0, m]) * tangent)
            total_mirrored += sign * (float(one["fn"][0, m]) * normal - float(one["ft"][0, m]) * tangent)
        scale = float(np.abs(rows[:, 3:]).max())
        if np.abs(total).max() < 1e-12 * scale:
            balanced.add(particle)
        if np.abs(total_mirrored).max() < 1e-12 * scale:
            mirrored.add(particle)
    assert balanced == {3, 6, 7, 9, 12, 15}
    assert mirrored == {2, 26}


def test_a_pair_fitted_on_one_disk_keeps_its_one_estimate(ds, tmp_path):
    """Without disk 2's row of its contact with disk 13, the pair has only disk 13's fit, whose
    normal force is tensile (-0.0044): it is left out, with a warning; without disk 13's row of
    its contact with disk 15, the pair keeps disk 15's estimate (N = 0.01457, T = -0.00743)."""
    lines = ADJACENCY.read_text().splitlines(keepends=True)
    for drop, kept, count in (("1,2,13,", None, 32), ("1,13,15,", ("1,15,13,", (12, 14)), 33)):
        path = tmp_path / "one_sided.txt"
        path.write_text("".join(line for line in lines if not line.startswith(drop)))
        if kept is None:
            with pytest.warns(UserWarning, match="1 contact"):
                one = open_pegs(path, POSITIONS, metres_per_pixel=SCALE, force_unit_n=FORCE)
            assert (1, 12) not in set(zip(one["i"][0].values, one["j"][0].values))
        else:
            one = open_pegs(path, POSITIONS, metres_per_pixel=SCALE, force_unit_n=FORCE)
            _, _, _, T, N = (float(v) for v in next(line for line in lines if line.startswith(kept[0])).split(","))
            m = list(zip(one["i"][0].values, one["j"][0].values)).index(kept[1])
            assert (float(one["fn"][0, m]), float(one["ft"][0, m])) == (N, T)
        assert int(one["contact_count"][0]) == count
        assert one.attrs["pegs_pairs"] == "24 particle pairs fitted on both disks, 1 on one"


def test_positions_walls_and_box(ds, raw):
    adjacency, positions = raw
    centre, radius, edge = cartesian(positions)
    np.testing.assert_allclose(ds["position"][0].values, centre, rtol=1e-15)
    np.testing.assert_allclose(ds["radius"].values, radius, rtol=1e-15)
    np.testing.assert_allclose(ds["box_min"][0].values, (centre - radius[:, None]).min(axis=0), rtol=1e-12)
    np.testing.assert_allclose(ds["box_max"][0].values, (centre + radius[:, None]).max(axis=0), rtol=1e-12)
    assert float(ds["box_min"][0, 1]) == pytest.approx(0, abs=1e-15)
    assert list(ds["wall"].values) == ["bottom", "right", "top", "left"]
    wall_force = np.zeros((4, 2))
    for (i, j), (force, _) in expected_contacts(adjacency, positions).items():
        if j >= centre.shape[0]:
            wall_force[j - centre.shape[0]] += force
    np.testing.assert_allclose(ds["wall_force"][0].values, wall_force, rtol=1e-12, atol=1e-18)
    assert wall_force[0, 1] < 0 and wall_force[2, 1] > 0  # pushed down on the bottom, up on the top


def test_z_and_stress_from_the_accessors_equal_numpy_from_the_files(raw):
    thickness = 6.35e-3
    ds = read(thickness_m=thickness)
    adjacency, positions = raw
    centre, radius, _ = cartesian(positions)
    n = centre.shape[0]
    expected = expected_contacts(adjacency, positions)
    pairs = [key for key in expected if key[1] < n]
    touched = {a for a, _ in pairs} | {b for _, b in pairs}
    moment = np.zeros((2, 2))
    for (i, j), (force, normal) in expected.items():
        branch = centre[j] - centre[i] if j < n else radius[i] * normal
        moment += np.outer(force, branch)
    size = (centre + radius[:, None]).max(axis=0) - (centre - radius[:, None]).min(axis=0)
    assert float(ds.grain.coordination()["z"][0]) == pytest.approx(2 * len(pairs) / len(touched), rel=1e-14)
    np.testing.assert_allclose(ds.grain.stress_tensor()[0].values, moment / (size[0] * size[1] * thickness),
                               rtol=1e-10)


def test_untracked_centres_give_the_same_contacts(ds):
    centres = open_pegs(ADJACENCY, CENTRES, metres_per_pixel=SCALE, force_unit_n=FORCE)
    for name in ("i", "j", "fn", "ft"):
        np.testing.assert_array_equal(centres[name].values, ds[name].values)
    np.testing.assert_allclose(centres["position"].values, ds["position"].values, rtol=0, atol=2e-8)  # re-detected


def test_scales_and_frames(ds, raw, tmp_path):
    adjacency, positions = raw
    scaled = read(metres_per_pixel=2 * SCALE, force_unit_n=1e-3, frame_interval_s=0.5)
    np.testing.assert_allclose(scaled["position"].values, 2 * ds["position"].values, rtol=1e-15)
    np.testing.assert_allclose(scaled["fn"].values, 1e-3 * ds["fn"].values, rtol=1e-15)
    assert float(scaled["time"][0]) == 0.5  # frame 1
    # two frames: the same frame again as frame 3, its forces doubled
    two_adjacency, two_positions = tmp_path / "adjacency.txt", tmp_path / "positions.txt"
    again = adjacency.copy()
    again[:, 0], again[:, 3:] = 3, 2 * adjacency[:, 3:]
    moved = positions.copy()
    moved[:, 0] = 3
    for path, table in ((two_adjacency, np.vstack([adjacency, again])), (two_positions, np.vstack([positions, moved]))):
        path.write_text("".join(",".join(repr(float(v)) for v in row) + "\n" for row in table))
    two = open_pegs(two_adjacency, two_positions, metres_per_pixel=SCALE, force_unit_n=FORCE, frame_interval_s=0.1)
    np.testing.assert_allclose(two["time"].values, [0.1, 0.3])
    np.testing.assert_allclose(two["fn"][1].values, 2 * ds["fn"][0].values, rtol=1e-15)


@pytest.mark.parametrize("options, match", [
    ({"metres_per_pixel": None}, "metres_per_pixel is required: PeGS2 gives positions in pixels"),
    ({"force_unit_n": None}, "force_unit_n is required"),
    ({"metres_per_pixel": -1.0}, "expected a number > 0"),
    ({"force_unit_n": "newton"}, "expected a number > 0"),
])
def test_units_must_be_given(options, match):
    with pytest.raises(ParameterError, match=match) as info:
        read(**options)
    assert "\n" not in str(info.value)


def test_the_file_the_backend_and_the_reader_agree(ds, tmp_path):
    out = tmp_path / "run.nc"
    assert convert_pegs(out, ADJACENCY, POSITIONS, metres_per_pixel=SCALE, force_unit_n=FORCE) == 1
    assert sorted(os.listdir(tmp_path)) == ["run.nc"]
    on_file = grainview.open_dataset(out, chunks=None, validate=True)
    backend = xr.open_dataset(ADJACENCY, engine="pegs", positions=POSITIONS, metres_per_pixel=SCALE,
                              force_unit_n=FORCE)
    through = grainview.open_dataset(ADJACENCY, format="pegs", positions=POSITIONS, metres_per_pixel=SCALE,
                                     force_unit_n=FORCE, chunks=None, validate=True)
    for other in (on_file, backend, through):
        for name, var in ds.data_vars.items():
            np.testing.assert_array_equal(other[name].values, var.values, err_msg=name)
    with pytest.raises(FileExistsError, match="exists"):
        convert_pegs(out, ADJACENCY, POSITIONS, metres_per_pixel=SCALE, force_unit_n=FORCE)


def _lines(text, edit):
    lines = text.splitlines()
    edit(lines)
    return "\n".join(lines) + "\n"


def _set(k, column, value):
    def edit(lines):
        values = lines[k].split(",")
        values[column] = value
        lines[k] = ",".join(values)
    return edit


BAD = [
    ("truncated-mid-row", "adjacency", lambda t: t[:t.index("\n", 1000) - 30], "columns, expected 5"),
    ("truncated-mid-number", "adjacency", lambda t: t[:t.index("\n", 1000) - 3], "truncated: its last line"),
    ("missing-column", "positions", lambda t: _lines(t, _set(4, 5, "")).replace(",\n", "\n"), "columns, expected 6"),
    ("mismatched-frames", "adjacency", lambda t: _lines(t, _set(57, 0, "2")), "mismatched frames: .* has frame 2"),
    ("unknown-id", "adjacency", lambda t: _lines(t, _set(0, 2, "30")), "particle id 30 is not among"),
    ("wall-of-an-inner-disk", "positions", lambda t: _lines(t, _set(6, 5, "0")), "not at an edge"),
    ("frames-with-other-particles", "positions",
     lambda t: t + "\n".join("2," + line.split(",", 1)[1] for line in t.splitlines()[:-1]) + "\n",
     "frame 2 holds other particles"),
    ("not-numbers", "adjacency", lambda t: "frame,id1,id2,T,N\n" + t, "expected 5 numbers"),
    ("twice-from-one-disk", "adjacency", lambda t: t + t.splitlines()[0] + "\n", "appears twice from the same disk"),
]


@pytest.mark.parametrize("name, which, edit, match", BAD, ids=[b[0] for b in BAD])
def test_bad_input_gets_one_line_and_writes_nothing(tmp_path, name, which, edit, match):
    source = ADJACENCY if which == "adjacency" else POSITIONS
    changed = edit(source.read_text())
    assert changed != source.read_text()
    path = tmp_path / source.name
    path.write_text(changed)
    adjacency, positions = (path, POSITIONS) if which == "adjacency" else (ADJACENCY, path)
    out = tmp_path / f"{name}.nc"
    with pytest.raises((FileFormatError, ParameterError), match=match) as info:
        convert_pegs(out, adjacency, positions, metres_per_pixel=SCALE, force_unit_n=FORCE)
    assert "\n" not in str(info.value)
    assert not out.exists()
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_the_command_line_converts_and_refuses_in_one_line(tmp_path):
    out = tmp_path / "run.nc"
    command = [sys.executable, "-m", "grainview", "convert", "pegs", str(ADJACENCY), "--positions",
               str(POSITIONS), "--out", str(out), "--progress", "off", "--force-unit-n", "1"]
    done = subprocess.run(command + ["--metres-per-pixel", str(SCALE)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "wrote" in done.stdout and "1 frames" in done.stdout
    again = subprocess.run(command + ["--metres-per-pixel", str(SCALE)], capture_output=True, text=True)
    assert again.returncode != 0 and again.stderr.strip().count("\n") == 0 and "exists" in again.stderr
    missing = subprocess.run(command, capture_output=True, text=True)
    assert missing.returncode != 0 and "--metres-per-pixel" in missing.stderr
