"""benchmarks/archive/detection_records.py: a turn times the stages on a sample and counts its
contact points (a hand-made one: three disks in a row, two of them touching, on a floor), and the
table gives each label's median and range over the turns and the ratio of the medians."""

import json

import numpy as np
import pytest

from .conftest import load_benchmark


@pytest.fixture(scope="module")
def records():
    return load_benchmark("archive.detection_records")


def test_a_turn_times_every_stage_and_counts_the_points(records, tmp_path, monkeypatch):
    # disks of radius 1 at x = 0, 2, 5 on the floor y = 0: the pair (0, 1) touches, (1, 2) is
    # 1 m apart (beyond the alert 0.1 m), and the three rest on the floor: 1 + 3 points
    np.savez(tmp_path / "disk_3.npz", pos=np.array([[0.0, 1.0], [2.0, 1.0], [5.0, 1.0]]), angle=np.zeros(3),
             radius=np.ones(3), nvert=np.zeros(3, np.int32), wall_point=np.zeros((1, 2)),
             wall_normal=np.array([[0.0, 1.0]]), alert=0.1, skin=0.5)
    monkeypatch.setattr(records, "DATA", str(tmp_path))
    monkeypatch.setattr(records, "SAMPLES", (("disk", 3),))
    out = records.turn("here", calls=2)
    assert out["label"] == "here" and out["solver"].endswith("solver")
    assert out["disk 3: points"] == 4
    assert {k for k in out if k.startswith("disk 3: ")} == {"disk 3: broad", "disk 3: narrow", "disk 3: narrow x2",
                                                           "disk 3: points"}
    assert all(out[f"disk 3: {stage}"] > 0 for stage in ("broad", "narrow", "narrow x2"))


def test_the_table_gives_medians_ranges_and_their_ratio(records, tmp_path):
    turns = [{"label": "base", "solver": "a", "x: narrow": v} for v in (2.0, 4.0, 3.0)]
    turns += [{"label": "new", "solver": "b", "x: narrow": v} for v in (6.0, 9.0, 7.5)]
    path = tmp_path / "turns.jsonl"
    path.write_text("".join(json.dumps(t) + "\n" for t in (turns[0], turns[3], turns[1], turns[4], turns[2],
                                                           turns[5])))
    lines = records.table(str(path)).splitlines()
    assert lines[0] == "| stage | base: ms (range), 3 turns | new: ms (range), 3 turns | new / base |"
    assert lines[2] == "| x: narrow | 3 (2-4) | 7.5 (6-9) | 2.500 |"
