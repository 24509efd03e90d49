"""What ``grainview study`` says of its time and its steps: a resumed test's unconverged steps
in one line."""

from __future__ import annotations

import warnings

from grainview.app.cli import _study_sample, _warnings_as_notes, main
from grainview.contract.errors import ConvergenceWarning
from solver.parameters import BiaxialTest
from solver.preparation import preparation

def test_a_resumed_test_sums_up_its_unconverged_steps_in_one_line(tmp_path, monkeypatch, capsys):
    from solver.engine import ContactDynamics

    path = tmp_path / "pentagons.nc"
    assert main(["run", "--shape", "pentagon", "--particles", "24", "--strain", "0.002", "--out", str(path),
                 "--progress", "off", "--no-compress"]) == 0
    capsys.readouterr()

    def resume(self, path, progress=None, compress=True):  # three unconverged steps and another warning
        for k in range(3):
            warnings.warn(f"step {k}: the NLGS stopped at its sweep cap", ConvergenceWarning)
        warnings.warn("something else", UserWarning)
        return 3

    monkeypatch.setattr(ContactDynamics, "resume", resume)
    prep = preparation("paper", particles=24, shape="pentagon")
    with _warnings_as_notes():
        _study_sample("pentagons", prep, path, "partial", tmp_path / "c.nc", test=BiaxialTest(strain=0.002),
                      near_contacts=True, overwrite=False, progress=False)
    captured = capsys.readouterr()
    assert "NLGS stopped" not in captured.out  # no line per step
    assert [line for line in captured.out.splitlines() if line.startswith("note:")] == ["note: something else"]
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("pentagons: warning: the contact solver (")
    assert "did not converge in 3 of the resumed test's steps; in the whole test " in err[0]
    assert "pentagons: resumed for 3 steps" in captured.out
