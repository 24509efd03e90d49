"""The readers are one registry (grainview.formats.READERS): the ``convert`` subcommands,
pyproject.toml's xarray entry points and docs/formats.md's table of readers agree with it, and
a reader another package adds through one ``xarray.backends`` entry point is found by
``grainview convert --help``, ``grainview.open_dataset(format=)`` and ``xr.open_dataset(engine=)``."""

import os
import re
import subprocess
import sys
import textwrap
import tomllib
from pathlib import Path

import pytest

from grainview.formats import READERS
from grainview.formats.readers import load

ROOT = Path(__file__).resolve().parents[2]


def test_each_record_names_what_exists():
    for name, reader in READERS.items():
        assert reader.name == name
        assert callable(load(reader.opener)) and callable(load(reader.convert.function))
        from xarray.backends import BackendEntrypoint

        assert issubclass(load(reader.backend.target), BackendEntrypoint)
        import inspect

        opener = list(inspect.signature(load(reader.opener)).parameters)
        assert reader.backend.options == tuple(p for p in opener[1:] if p != "progress")
        for argument in reader.convert.arguments:
            assert argument.parse is None or callable(load(argument.parse))


def test_the_convert_subcommands_are_the_registry():
    from grainview.app.cli import build_parser

    convert = build_parser("convert")._subparsers._group_actions[0].choices["convert"]
    formats = convert._subparsers._group_actions[0]
    assert list(formats.choices) == list(READERS)
    for name, parser in formats.choices.items():
        assert parser.description == READERS[name].convert.description
        own = [a for a in parser._actions if a.dest not in ("help", "out", "overwrite", "progress", "no_compress")]
        assert [a.dest for a in own] == [argument.dest for argument in READERS[name].convert.arguments]
        assert ("progress" in {a.dest for a in parser._actions}) == READERS[name].convert.progress


def test_pyprojects_xarray_entry_points_are_the_registry():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    assert project["project"]["entry-points"]["xarray.backends"] == {n: r.backend.target for n, r in READERS.items()}


def _docs_rows(text):
    """{format: (reads, opened by, backend)} of docs/formats.md's '### The readers, by name'."""
    section = text.split("### The readers, by name", 1)[1].split("\n#", 1)[0]
    rows = {}
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        name = re.fullmatch(r"`([a-z0-9_]+)`", cells[0]) if len(cells) == 4 else None
        if name:
            rows[name.group(1)] = (cells[1], cells[2].strip("`"), cells[3].strip("`"))
    return rows


def test_the_docs_table_of_readers_is_the_registry():
    rows = _docs_rows((ROOT / "docs" / "formats.md").read_text(encoding="utf-8"))
    expected = {n: (r.convert.help, r.opener, r.backend.target) for n, r in READERS.items()}
    assert rows == expected, "docs/formats.md's rows should read " + "; ".join(
        f"| `{n}` | {h} | `{o}` | `{b}` |" for n, (h, o, b) in expected.items())


def test_an_unknown_format_is_named_with_the_known_ones():
    from grainview import open_dataset
    from grainview.contract.errors import ParameterError

    with pytest.raises(ParameterError, match="format='nope': expected 'grainview' or one of box2d, lammps"):
        open_dataset("x", format="nope")


TOY = '''
import xarray as xr

from grainview.formats.backends import ReaderBackend
from grainview.formats.readers import Argument, Backend, Convert, Reader


def open_toy(path, scale=1.0):
    values = [float(v) * scale for v in open(path).read().split()]
    return xr.Dataset({"x": ("time", values)}, attrs={"source": "toy"})


def convert_toy(out, path, *, scale=1.0, overwrite=False, compress=True, progress=False):
    values = open_toy(path, scale)["x"].values
    open(out, "w").write(" ".join(map(str, values)))
    return len(values)


class ToyBackend(ReaderBackend):
    reader = Reader("toy", "toy_reader:open_toy", Backend("toy_reader:ToyBackend", ("scale",), "toy numbers"), Convert(
        "toy_reader:convert_toy", "a toy code's numbers", "A toy code's numbers, one per snapshot.",
        (Argument(("path",), {"help": "the toy file"}),
         Argument(("--scale",), {"type": float, "default": 1.0, "help": "a factor (default: 1)"}))))
'''

CHECK = '''
import sys
import xarray as xr
import grainview
from grainview.app.cli import main

path, out = sys.argv[1:]
print("grainview", grainview.open_dataset(path, format="toy", chunks=None, scale=2.0)["x"].values.tolist())
print("xarray", xr.open_dataset(path, engine="toy", scale=3.0)["x"].values.tolist())
assert main(["convert", "toy", path, "--scale", "10", "--out", out]) == 0
print("file", open(out).read())
'''


def test_a_reader_added_through_one_entry_point_is_found_everywhere(tmp_path):
    (tmp_path / "toy_reader.py").write_text(TOY)
    info = tmp_path / "toy_reader-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: toy-reader\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text("[xarray.backends]\ntoy = toy_reader:ToyBackend\n")
    (tmp_path / "run.toy").write_text("1 2 3")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), str(ROOT), os.environ.get("PYTHONPATH", "")])}
    help_text = subprocess.run([sys.executable, "-m", "grainview", "convert", "--help"], env=env, cwd=tmp_path,
                               capture_output=True, text=True, check=True).stdout
    assert re.search(r"^\s+toy\s+a toy code's numbers$", help_text, re.M)
    toy_help = subprocess.run([sys.executable, "-m", "grainview", "convert", "toy", "--help"], env=env, cwd=tmp_path,
                              capture_output=True, text=True, check=True).stdout
    assert "A toy code's numbers, one per snapshot." in toy_help and "--scale SCALE" in toy_help
    done = subprocess.run([sys.executable, "-c", textwrap.dedent(CHECK), str(tmp_path / "run.toy"),
                           str(tmp_path / "out.txt")], env=env, cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert "grainview [2.0, 4.0, 6.0]" in lines and "xarray [3.0, 6.0, 9.0]" in lines
    assert "wrote " + str(tmp_path / "out.txt") + ": 3 snapshots (check it: grainview info " in done.stdout
    assert "file 10.0 20.0 30.0" in lines


@pytest.mark.parametrize("engine, said", [
    ("lammps", "engine='lammps' needs contacts=<the pairs' dump local> besides the particles' dump"),
    ("box2d", "engine='box2d' needs sample=<the cross-check sample's .npz>"),
    ("pegs", "engine='pegs' needs positions=<particle_positions.txt or the *_centers.txt files> besides the "
             "adjacency list"),
])
def test_each_backend_is_made_from_its_record_and_names_what_it_needs(engine, said):
    import xarray as xr

    from grainview.contract.errors import ParameterError

    backend = xr.backends.list_engines()[engine]
    assert backend.reader is READERS[engine] and backend.description == READERS[engine].backend.description
    with pytest.raises(ParameterError) as caught:
        xr.open_dataset("nothing", engine=engine)
    assert str(caught.value) == said
