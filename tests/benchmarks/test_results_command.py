"""``python -m benchmarks``: RESULTS.md is assembled from the section files and nothing else,
every section names a benchmark module that exists, and a bad argument is refused in one line
before anything is measured."""

import os
import subprocess
import sys

import pytest

from .conftest import load_benchmark

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")


@pytest.fixture(scope="module")
def command():
    return load_benchmark("__main__")


def test_results_md_is_the_assembly_of_the_section_files(command):
    # the committed RESULTS.md is what the command's last step writes from benchmarks/results/
    with open(command.RESULTS) as fh:
        committed = fh.read()
    assert committed == command.assembled()  # nothing hand-edited, no section left out


def test_every_section_file_belongs_to_a_section_and_every_section_has_one(command):
    files = {f[:-3] for f in os.listdir(command.RESULTS_DIR) if f.endswith(".md")}
    names = {s.name for s in command.SECTIONS}
    assert files == names


def test_every_section_runs_a_module_that_exists(command):
    for section in command.SECTIONS:
        assert os.path.exists(os.path.join(command.HERE, f"{section.module}.py")), section.name
        for quick in (False, True):
            if quick and section.quick is None:
                continue
            line = section.command(quick, command.RESULTS_DIR)
            assert line[1:3] == ["-m", f"benchmarks.{section.module}"]
            if section.out:
                assert line[-2:] == [section.out, os.path.join("benchmarks", "results", f"{section.name}.md")]


def test_assembly_demotes_headings_relinks_and_lists_what_is_missing(command, tmp_path):
    folder = tmp_path / "results"
    folder.mkdir()
    (folder / "a.md").write_text("# Speed: a test\n\nRun on 2026-11-26 21:00 UTC, commit abc.\n\n## Table\n\n"
                                 "![plot](a.png) [other](b.md) [web](https://x.org) [here](#table)\n\n```\n# code\n```\n")
    sections = (command.Section("a", "m", "what a measures", ()), command.Section("b", "m", "what b measures", ()))
    out = tmp_path / "RESULTS.md"
    text = command.assemble(str(folder), str(out), sections, note="a note")
    assert out.read_text() == text == command.assembled(str(folder), sections, "a note", str(tmp_path))
    assert "| [a](#speed-a-test) | what a measures | 2026-11-26 21:00 UTC |" in text
    assert "| b | what b measures | not measured |" in text
    assert "\n## Speed: a test\n" in text and "\n### Table\n" in text and "\n# code\n" in text
    assert "![plot](results/a.png) [other](results/b.md) [web](https://x.org) [here](#table)" in text
    assert "a note" in text


def test_an_unknown_section_is_refused_in_one_line():
    done = subprocess.run([sys.executable, "-m", "benchmarks", "--only", "scaling,nope"], capture_output=True,
                          text=True, cwd=ROOT, timeout=60)
    assert done.returncode == 2 and done.stdout == ""
    last = done.stderr.strip().splitlines()[-1]
    assert "unknown section(s) nope" in last and "scaling" in last


def test_a_rewritten_results_file_keeps_the_notes_below_its_marker(tmp_path, capsys):
    """What a person wrote below the notes marker survives the benchmark's rewrite; a file
    without the marker is replaced whole; a new file is just the generated text."""
    from benchmarks.common import NOTES_MARKER, write_text_keeping_notes

    path = tmp_path / "results.md"
    assert write_text_keeping_notes(str(path), "# new\n\n| a |\n") == "# new\n\n| a |\n"
    path.write_text(f"# old\n\n| b |\n\n{NOTES_MARKER}\n\n## What the numbers say\n\nhand-written\n")
    whole = write_text_keeping_notes(str(path), "# new\n\n| c |\n")
    assert whole == path.read_text() == f"# new\n\n| c |\n\n{NOTES_MARKER}\n\n## What the numbers say\n\nhand-written\n"
    assert "notes below its marker were kept" in capsys.readouterr().out
    path.write_text("# old, no marker\n\nnot kept\n")
    assert write_text_keeping_notes(str(path), "# new\n") == path.read_text() == "# new\n"
