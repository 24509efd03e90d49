"""The MercuryDPM reader against what MercuryDPM itself writes.

The fixtures (tests/data/mercurydpm/Settle2D.data, .fstat, .restart) were written by MercuryDPM
(the kernel of the fork kuwt/MercuryDPM_fork at fb0ebf1, built here with
tests/data/mercurydpm/build_mercurydpm.sh) running the driver Settle2D.cpp: 32 frictional disks
settling under gravity in a box of four InfiniteWalls, in MercuryDPM's nondimensional units.
The expected values below are computed from those files' text with plain Python and numpy, and
from the .restart's own interaction and wall forces, never with the reader.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import grainview
from grainview.contract.errors import FileFormatError, ParameterError
from grainview.formats.mercurydpm import convert_mercurydpm, open_mercurydpm

DATA = Path(__file__).resolve().parents[1] / "data" / "mercurydpm"
GRAVITY = np.array([0.0, -1.0])  # Settle2D.cpp: setGravity(Vec3D(0, -1, 0))


def files(folder=DATA):
    return folder / "Settle2D.data", folder / "Settle2D.fstat", folder / "Settle2D.restart"


def plain_data(path):
    """[(time, bounds, rows)] of a 2D .data file, parsed line by line."""
    lines = Path(path).read_text().splitlines()
    out, k = [], 0
    while k < len(lines):
        head = [float(v) for v in lines[k].split()]
        n = int(head[0])
        out.append((head[1], head[2:], np.array([[float(v) for v in line.split()] for line in lines[k + 1:k + 1 + n]])))
        k += 1 + n
    return out


def plain_fstat(path):
    """[(time, rows)] of an .fstat file, parsed line by line."""
    out = []
    for line in Path(path).read_text().splitlines():
        if line.startswith("#"):
            values = line[1:].split()
            if len(values) == 2:
                out.append((float(values[0]), []))
            continue
        out[-1][1].append([float(v) for v in line.split()])
    return out


def expected_contacts(fstat_rows, n):
    """{(i, j): (force exerted by i on j, normal from i to j, point)} of one snapshot, one by one
    from the lines: a particle line whose P is the higher index gives the force on it along n
    from the lower one; a wall line (I = -w-1) gives minus the force on the particle along n
    from the particle to the wall. Overlapping pairs with a compressive normal force only."""
    out = {}
    for row in fstat_rows:
        t, p, other, cx, cy, cz, overlap, _, fn, ft, nx, ny, nz, tx, ty, tz = row
        p, other = int(p), int(other)
        vector = np.array([fn * nx + ft * tx, fn * ny + ft * ty])
        if other < 0:
            key = (p, n - other - 1)
        elif p > other:
            key = (other, p)
        else:
            continue  # the same pair, written from the other side
        if overlap > 0 and fn > 0:
            out[key] = (vector, np.array([nx, ny]), np.array([cx, cy]))
    return out


def restart_records(path, kind):
    """The .restart's lines of ``kind`` ("InfiniteWall", "LinearViscoelasticSlidingFrictionInteraction") as
    dicts of their numbers."""
    out = []
    for line in Path(path).read_text().splitlines():
        tokens = line.split()
        if tokens and tokens[0] == kind:
            record, key = {}, None
            for token in tokens[1:]:
                try:
                    record.setdefault(key, []).append(float(token))
                except ValueError:
                    key = token
            out.append(record)
    return out


@pytest.fixture(scope="module")
def ds():
    with pytest.warns(UserWarning, match="1 touching pair"):
        return open_mercurydpm(files()[0], units="si")


@pytest.fixture(scope="module")
def raw():
    data, fstat, _ = files()
    return plain_data(data), plain_fstat(fstat)


def test_the_fixture_is_a_real_mercurydpm_run(raw):
    data, fstat = raw
    restart = files()[2].read_text()
    assert restart.startswith("MercuryDPM 1.0 name Settle2D")
    assert "systemDimensions 2 particleDimensions 2" in restart
    assert [t for t, *_ in data] == [t for t, _ in fstat] == [0, 5, 10, 15, 20, 25, 30, 35, 40, 40.001]
    for _, rows in fstat:  # every particle pair twice, normal and tangent flipped
        pairs = {(int(r[1]), int(r[2])): r for r in rows if r[2] >= 0}
        assert len(pairs) % 2 == 0
        for (p, q), row in pairs.items():
            mirror = pairs[(q, p)]
            np.testing.assert_array_equal(mirror[10:16], [-v for v in row[10:16]])
            assert mirror[8:10] == row[8:10]


def test_each_contact_is_stored_once_with_the_files_force(ds, raw):
    data, fstat = raw
    n = ds.sizes["particle"]
    for k, (_, rows) in enumerate(fstat):
        expected = expected_contacts(rows, n)
        count = int(ds["contact_count"][k])
        assert count == len(expected)
        i, j = ds["i"][k, :count].values, ds["j"][k, :count].values
        assert len(set(zip(i, j))) == count and np.all(i < j)
        for m in range(count):
            force, normal, point = expected[(int(i[m]), int(j[m]))]
            n_m = ds["normal"][k, m].values
            np.testing.assert_allclose(n_m, normal, rtol=0, atol=1e-9)
            assert float(ds["fn"][k, m]) == pytest.approx(force @ n_m, rel=1e-12, abs=1e-15)
            assert float(ds["ft"][k, m]) == pytest.approx(force @ [-n_m[1], n_m[0]], rel=1e-9, abs=1e-12)
            np.testing.assert_array_equal(ds["point"][k, m].values, point)


def test_forces_are_the_restarts_own_interaction_forces(ds):
    """The last snapshot is the state the .restart saved: each of its interactions' force (the
    force on its first body P) is the contact's, and each wall's force the reader's wall_force."""
    restart = files()[2]
    n = ds.sizes["particle"]
    last = ds.isel(time=-1)
    count = int(last["contact_count"])
    by_pair = {(int(a), int(b)): m for m, (a, b) in enumerate(zip(last["i"][:count].values, last["j"][:count].values))}
    matched = 0
    for record in restart_records(restart, "LinearViscoelasticSlidingFrictionInteraction"):
        on_p = np.array(record["force"][:2])
        if "particleWallIds" in record:
            p, w = (int(v) for v in record["particleWallIds"])
            key, on_j = (p, n + w), -on_p  # the wall is j: the particle pushes it with minus the force on itself
        else:
            p, q = (int(v) for v in record["particleIds"])
            key = (min(p, q), max(p, q))
            on_j = on_p if p == key[1] else -on_p
        if key not in by_pair:  # the tensile pair left out
            assert on_j @ (last["position"][key[1]] - last["position"][key[0]]).values < 0
            continue
        m = by_pair[key]
        normal = last["normal"][m].values
        assert float(last["fn"][m]) == pytest.approx(on_j @ normal, rel=1e-8)
        assert float(last["ft"][m]) == pytest.approx(on_j @ [-normal[1], normal[0]], rel=1e-6, abs=1e-9)
        matched += 1
    assert matched == count
    walls = restart_records(restart, "InfiniteWall")
    np.testing.assert_allclose(last["wall_force"].values, [w["force"][:2] for w in walls], rtol=1e-8, atol=1e-12)
    assert list(ds["wall"].values) == ["bottom", "right", "top", "left"]
    # the walls carry the pile's weight between them (the side walls a part of it, by friction), to
    # the pile's residual motion (0.005% of its weight here)
    np.testing.assert_allclose(last["wall_force"].sum("wall").values, [0, -float(ds["mass"].sum())], atol=2e-3)
    assert abs(float(last["wall_force"][1, 1]) + float(last["wall_force"][3, 1])) > 1.0


def test_contact_forces_and_weight_sum_to_mercurydpms_own_total_force(ds, restart=None):
    """At the last snapshot (the state the .restart saved), the contact forces on each particle
    plus its weight equal the total force MercuryDPM itself holds for it (the .restart's
    ``force``): the directions and signs of every contact force, walls included."""
    restart = restart or files()[2]
    total_force = np.array([record["force"][:2] for record in restart_records(restart, "BaseParticle")])
    last = ds.isel(time=-1)
    count = int(last["contact_count"])
    n = ds.sizes["particle"]
    total = ds["mass"].values[:, None] * GRAVITY
    for m in range(count):
        i, j = int(last["i"][m]), int(last["j"][m])
        normal = last["normal"][m].values
        on_j = float(last["fn"][m]) * normal + float(last["ft"][m]) * np.array([-normal[1], normal[0]])
        total[i] -= on_j
        if j < n:
            total[j] += on_j
    # to the .fstat's 10 digits (the pair left out as tensile pulls with less than that here)
    np.testing.assert_allclose(total, total_force, rtol=0, atol=1e-8)


def test_z_and_stress_from_the_accessors_equal_numpy_from_the_files(ds, raw):
    data, fstat = raw
    n = ds.sizes["particle"]
    z = ds.grain.coordination()["z"].values
    stress = ds.grain.stress_tensor().values
    for k, ((_, bounds, rows), (_, contact_rows)) in enumerate(zip(data, fstat)):
        expected = expected_contacts(contact_rows, n)
        if not expected:
            continue
        centre = rows[:, 0:2]
        pairs = [key for key in expected if key[1] < n]
        touched = {a for a, _ in pairs} | {b for _, b in pairs}
        moment = np.zeros((2, 2))
        for (a, b), (force, _, point) in expected.items():
            branch = centre[b] - centre[a] if b < n else point - centre[a]
            moment += np.outer(force, branch)
        area = (bounds[2] - bounds[0]) * (bounds[3] - bounds[1])
        assert z[k] == pytest.approx(2 * len(pairs) / len(touched), rel=1e-14)
        np.testing.assert_allclose(stress[k], moment / area, rtol=1e-9, atol=1e-9 * np.abs(moment).max() / area)


def test_particles_are_the_data_files_lines(ds, raw):
    data, _ = raw
    for k, (t, bounds, rows) in enumerate(data):
        assert float(ds["time"][k]) == t
        np.testing.assert_array_equal(ds["position"][k].values, rows[:, 0:2])
        np.testing.assert_array_equal(ds["velocity"][k].values, rows[:, 2:4])
        np.testing.assert_array_equal(ds["angle"][k].values, rows[:, 5])
        np.testing.assert_array_equal(ds["angular_velocity"][k].values, -rows[:, 6])  # written negated for XBalls
        np.testing.assert_array_equal(ds["box_max"][k].values, bounds[2:])
    radius = data[0][2][:, 4]
    mass = np.pi * radius**2 * 1.0  # Settle2D.cpp: density 1, disks
    np.testing.assert_allclose(ds["mass"].values, mass, rtol=1e-9)  # radii written to 10 digits in .data
    np.testing.assert_allclose(ds["inertia"].values, mass * radius**2 / 2, rtol=1e-9)


def test_units_scale_every_quantity(ds):
    L, M, T = 2e-3, 1e-5, 1e-2
    with pytest.warns(UserWarning):
        scaled = open_mercurydpm(files()[0], units={"length": L, "mass": M, "time": T})
    for name, factor in (("radius", L), ("position", L), ("point", L), ("branch", L), ("gap", L),
                         ("velocity", L / T), ("angular_velocity", 1 / T), ("time", T), ("mass", M),
                         ("inertia", M * L**2), ("fn", M * L / T**2), ("ft", M * L / T**2),
                         ("wall_force", M * L / T**2), ("box_max", L)):
        np.testing.assert_allclose(scaled[name].values, ds[name].values * factor, rtol=1e-12,
                                   atol=1e-12 * factor * float(np.nanmax(np.abs(ds[name].values))), err_msg=name)
    assert scaled.attrs["thickness_m"] == L
    # a stress is a force per area of a slab one length unit thick: M L T^-2 / L^3
    np.testing.assert_allclose(scaled.grain.stress_tensor().values, ds.grain.stress_tensor().values * M / (L * T**2),
                               rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("units, match", [
    (None, "carry no units"), ("cgs", "carry no units"), ({"length": 1, "mass": 1}, "carry no units"),
    ({"length": 1, "mass": 0, "time": 1}, "mass=0: expected a finite number > 0"),
])
def test_units_must_be_given(units, match):
    with pytest.raises(ParameterError, match=match) as info:
        open_mercurydpm(files()[0], units=units)
    assert "\n" not in str(info.value)


def test_the_file_the_backend_and_the_reader_agree(ds, tmp_path):
    data, fstat, restart = files()
    out = tmp_path / "run.nc"
    with pytest.warns(UserWarning):
        assert convert_mercurydpm(out, data, units="si") == 10
    assert sorted(os.listdir(tmp_path)) == ["run.nc"]
    on_file = grainview.open_dataset(out, chunks=None, validate=True)
    with pytest.warns(UserWarning):
        backend = xr.open_dataset(data, engine="mercurydpm", fstat=fstat, restart=restart, units="si")
    with pytest.warns(UserWarning):
        through = grainview.open_dataset(data, format="mercurydpm", units="si", chunks=None, validate=True)
    for other in (on_file, backend, through):
        for name, var in ds.data_vars.items():
            np.testing.assert_array_equal(other[name].values, var.values, err_msg=name)
    with pytest.raises(FileExistsError, match="exists"):
        convert_mercurydpm(out, data, units="si")


def _cut(text, fraction):
    return text[:int(len(text) * fraction)]


def _drop_snapshot(text, time):
    """An .fstat without the snapshot at ``time``."""
    blocks = text.split("# ")
    keep, skip = [], 0
    for block in blocks:
        if skip:
            skip -= 1
            continue
        if block.split("\n")[0] == f"{time} 1":
            skip = 2
            continue
        keep.append(block)
    return "# ".join(keep)


def _disagree(text):
    """The second line of the first pair in the last snapshot with another normal force."""
    lines = text.split("\n")
    for k in range(len(lines) - 1, 0, -1):
        values = lines[k].split()
        if len(values) == 16 and int(values[2]) >= 0:
            values[8] = repr(2 * float(values[8]))
            lines[k] = " ".join(values)
            return "\n".join(lines)
    raise AssertionError("no particle pair")


BAD = [
    ("truncated-data", "data", lambda t: _cut(t, 0.63), "truncated: the snapshot"),
    ("truncated-fstat", "fstat", lambda t: _cut(t, 0.77), "expected 16 numbers"),
    ("missing-data-column", "data", lambda t: t.replace(" 0\n1.94008130746886", "\n1.94008130746886", 1),
     "expected 8 numbers"),
    ("missing-fstat-column", "fstat", lambda t: t.replace(" 0.3157590378 -0.9488394121 0 0.9488394121",
                                                          " 0.3157590378 -0.9488394121 0.9488394121", 1),
     "expected 16 numbers"),
    ("mismatched-snapshots", "fstat", lambda t: _drop_snapshot(t, "20"), "mismatched snapshots"),
    ("fstat-shorter", "fstat", lambda t: _drop_snapshot(t, "40.001"), "does not have"),
    ("3d-run", "data", lambda t: t.replace("32 0 0 0 10.4 10", "32 0 0 0 -0.5 10.4 10 0.5", 1), "a 3D run"),
    ("other-run", "restart", lambda t: t.replace("radius 0.426194548209948", "radius 0.5", 1), "not the same run"),
    ("pair-disagrees", "fstat", _disagree, "disagree"),
    ("not-fstat", "fstat", lambda t: "hello\n" + t, "before a snapshot's three '#' header lines"),
]


@pytest.mark.parametrize("name, which, edit, match", BAD, ids=[b[0] for b in BAD])
def test_bad_input_gets_one_line_and_writes_nothing(tmp_path, name, which, edit, match):
    folder = tmp_path / "run"
    folder.mkdir()
    for path in files():
        text = path.read_text()
        if path.suffix == "." + which:
            changed = edit(text)
            assert changed != text
            text = changed
        (folder / path.name).write_text(text)
    out = tmp_path / f"{name}.nc"
    with pytest.raises((FileFormatError, ParameterError), match=match) as info:
        convert_mercurydpm(out, folder / "Settle2D.data", units="si")
    assert "\n" not in str(info.value)
    assert not out.exists()
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_the_command_line_converts_and_refuses_in_one_line(tmp_path):
    out = tmp_path / "run.nc"
    command = [sys.executable, "-m", "grainview", "convert", "mercurydpm", str(files()[0]), "--out", str(out),
               "--progress", "off"]
    done = subprocess.run(command + ["--units", "si"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "wrote" in done.stdout and "note: 1 touching pair" in done.stdout and done.stderr == ""
    again = subprocess.run(command + ["--units", "si"], capture_output=True, text=True)
    assert again.returncode != 0 and again.stderr.strip().count("\n") == 0 and "exists" in again.stderr
    bad = subprocess.run(command[:-4] + ["--out", str(tmp_path / "b.nc"), "--units", "length=1,mass=1"],
                         capture_output=True, text=True)
    assert bad.returncode != 0 and bad.stderr.strip().count("\n") == 0 and "carry no units" in bad.stderr
    assert not (tmp_path / "b.nc").exists()


def _make_fixtures():
    spec = importlib.util.spec_from_file_location("mercurydpm_make_fixtures", DATA / "make_fixtures.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.slow
@pytest.mark.skipif(_make_fixtures().find_driver() is None,
                    reason="MercuryDPM's Settle2D is not built (tests/data/mercurydpm/build_mercurydpm.sh)")
def test_a_fresh_mercurydpm_run_converts_and_checks(tmp_path):
    """MercuryDPM runs Settle2D anew: with the fixtures' seed it writes the committed files again
    (numbers to 1e-9), and with another seed a run no other test has seen converts, passes
    `grainview info --check`, and its contacts, balance, z and stress check as above."""
    make = _make_fixtures()
    same = make.run(tmp_path / "same", seed=1)
    for name in make.FILES[:2]:
        fresh = (same / name).read_text().split()
        committed = (DATA / name).read_text().split()
        assert len(fresh) == len(committed)
        numbers = [(float(a), float(b)) for a, b in zip(fresh, committed) if a != "#"]
        np.testing.assert_allclose(*np.array(numbers).T, rtol=1e-9, atol=1e-12)
    folder = make.run(tmp_path / "run", seed=97)
    out = tmp_path / "fresh.nc"
    done = subprocess.run([sys.executable, "-m", "grainview", "convert", "mercurydpm",
                           str(folder / "Settle2D.data"), "--units", "si", "--out", str(out), "--progress", "off"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    check = subprocess.run([sys.executable, "-m", "grainview", "info", str(out), "--check"], capture_output=True,
                           text=True)
    assert check.returncode == 0 and "valid" in check.stdout, check.stdout + check.stderr
    fresh = grainview.open_dataset(out, chunks=None)
    raw = plain_data(folder / "Settle2D.data"), plain_fstat(folder / "Settle2D.fstat")
    test_each_contact_is_stored_once_with_the_files_force(fresh, raw)
    test_contact_forces_and_weight_sum_to_mercurydpms_own_total_force(fresh, folder / "Settle2D.restart")
    test_z_and_stress_from_the_accessors_equal_numpy_from_the_files(fresh, raw)
