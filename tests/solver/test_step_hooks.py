"""Simulation.watch: the hooks called around every step, the one way code outside the stepper
observes, times or stops a run (no replacing of ``sim.step`` by assignment anywhere)."""

import pathlib
import pickle
import re
import time

import numpy as np
import pytest

from grainview.contract.errors import ParameterError
from solver import compaction_sample

ROOT = pathlib.Path(__file__).resolve().parents[2]


class Stop(Exception):
    pass


def _state(sim):
    return np.concatenate([sim.position.ravel(), sim.angle, sim.velocity.ravel(), sim.angular_velocity,
                           sim.walls.point.ravel()])


def test_hooks_are_called_around_each_step_in_order_and_change_nothing():
    plain, watched = compaction_sample(12, "pentagon", seed=4), compaction_sample(12, "pentagon", seed=4)
    calls = []
    with watched.watch(before=lambda: calls.append(("before", watched.step_index)),
                       after=lambda info: calls.append(("after", watched.step_index, info is watched.last))), \
            watched.watch(after=lambda info: calls.append(("second", watched.step_index))):
        for _ in range(5):
            plain.step()
            watched.step()
    expected = []
    for k in range(5):
        expected += [("before", k), ("after", k + 1, True), ("second", k + 1)]
    assert calls == expected
    np.testing.assert_array_equal(_state(watched), _state(plain))  # bit for bit
    watched.step()
    assert len(calls) == 15  # closed with the block: not called any more
    assert watched._step_hooks == ()


def test_a_closed_watch_stops_only_its_own_hooks_and_closing_twice_is_harmless():
    sim = compaction_sample(6, "disk", seed=1)
    first, second = [], []
    a = sim.watch(after=lambda info: first.append(info.iterations))
    b = sim.watch(after=lambda info: second.append(info.iterations))
    sim.step()
    a.close()
    a.close()
    sim.step()
    b.close()
    sim.step()
    assert len(first) == 1 and len(second) == 2


def test_an_after_hook_that_raises_stops_the_run_once_the_step_is_complete():
    sim = compaction_sample(8, "disk", seed=2)

    def stop(info):
        raise Stop

    with sim.watch(after=stop), pytest.raises(Stop):
        sim.step()
    assert sim.step_index == 1 and sim.last is not None


def test_a_before_hook_that_raises_stops_the_run_before_the_step_changes_anything():
    sim = compaction_sample(8, "disk", seed=2)
    sim.step()
    before = _state(sim)

    def stop():
        raise Stop

    with sim.watch(before=stop), pytest.raises(Stop):
        sim.step()
    assert sim.step_index == 1
    np.testing.assert_array_equal(_state(sim), before)


def test_the_hooks_time_is_not_in_the_stage_timings():
    sim = compaction_sample(8, "disk", seed=2)
    sim.step()  # compiled
    staged = sum(sim.timings.values())
    with sim.watch(before=lambda: time.sleep(0.05), after=lambda info: time.sleep(0.05)):
        start = time.perf_counter()
        sim.step()
        elapsed = time.perf_counter() - start
    assert elapsed >= 0.1
    assert sum(sim.timings.values()) - staged < elapsed - 0.09


def test_a_simulation_pickles_once_its_watches_are_closed():
    sim = compaction_sample(6, "disk", seed=1)
    with sim.watch(after=lambda info: None):
        sim.step()
    again = pickle.loads(pickle.dumps(sim))
    again.step()
    sim.step()
    np.testing.assert_array_equal(_state(again), _state(sim))


@pytest.mark.parametrize("kwargs, words", [({}, "expected a before() or an after(info) callable"),
                                           ({"after": 3}, "watch(after=3): expected a callable")])
def test_watch_refuses_what_it_cannot_call(kwargs, words):
    sim = compaction_sample(6, "disk", seed=1)
    with pytest.raises(ParameterError, match=re.escape(words)):
        sim.watch(**kwargs)


REPLACES_STEP = re.compile(r"""\.step\s*=[^=]|del\s+\w+\.step\b"""
                           r"""|(?<![\w.])(?:set|del)attr\(\s*[\w.\[\]]+\s*,\s*["']step["']"""
                           r"""|(?:__dict__|vars\([\w.]*\))\s*\[\s*["']step["']\s*\]\s*=[^=]""")
"""A line that replaces or removes a simulation's ``step``: assigned, deleted, set or deleted by
name (``setattr``, ``delattr``), or written into its ``__dict__`` (pytest's
``monkeypatch.setattr`` on the class, undone after its test, is not)."""


def test_the_check_sees_every_way_of_replacing_the_step():
    replacing = ["sim.step = fake", "del sim.step", 'setattr(sim, "step", fake)', "setattr(self.sim, 'step', f)",
                 'delattr(sim, "step")', 'sim.__dict__["step"] = fake', "vars(sim)['step'] = fake"]
    keeping = ["sim.step()", "if sim.step == 3: pass", 'getattr(sim, "step")', 'setattr(sim, "steps", 3)',
               "sim.step_index = 2", 'hooks["step"] = fake', 'monkeypatch.setattr(Simulation, "step", fake)']
    assert [line for line in replacing if not REPLACES_STEP.search(line)] == []
    assert [line for line in keeping if REPLACES_STEP.search(line)] == []


def test_no_code_replaces_a_simulations_step_by_assignment():
    """Observing a run goes through watch(): an assigned ``sim.step`` would survive in a pickled
    sample and hide from a reader which step ran. (Tests that inject a kill into runs the study
    makes by itself patch the class with pytest's monkeypatch, undone after the test.)"""
    offenders = []
    for path in ROOT.rglob("*.py"):
        if any(part.startswith(".") for part in path.relative_to(ROOT).parts) or path.name == pathlib.Path(__file__).name:
            continue
        text = path.read_text(encoding="utf-8")
        if REPLACES_STEP.search(text):
            offenders.append(str(path.relative_to(ROOT)))
    assert offenders == []
