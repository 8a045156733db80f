"""The demo's commands run side by side (its hops stage): each logged under its own number in
order, the bar counting those done, a failure stopping the demo once the others have ended."""

from __future__ import annotations

import io

import pytest

from locust.demo.runner import Demo
from locust.errors import ReportError
from locust.progress import progress


def test_commands_side_by_side_are_logged_in_order_and_counted(tmp_path):
    d = Demo(tmp_path, io.StringIO())
    d.call(["--version"])                                   # step 1, before the batch
    with progress(length=3, file=io.StringIO()) as bar:
        d.call_side_by_side([(["--version"], ()), (["--help"], ()), (["--version"], ())], 2, bar)
    assert bar.pos == 3 and d.steps == 4
    logs = sorted(p.name for p in (tmp_path / "logs").iterdir())
    assert logs == ["01---version.log", "02---version.log", "03---help.log", "04---version.log"]
    assert "Usage:" in (tmp_path / "logs" / "03---help.log").read_text()


def test_a_failure_side_by_side_stops_the_demo_after_the_others(tmp_path):
    d = Demo(tmp_path, io.StringIO())
    calls = [(["no-such-verb"], ()), (["--version"], ()), (["--version"], (tmp_path / "never-written",))]
    with progress(length=3, file=io.StringIO()) as bar, pytest.raises(ReportError, match="no-such-verb") as err:
        d.call_side_by_side(calls, 2, bar)
    assert "exit 2" in err.value.message
    assert bar.pos == 1      # only the second succeeded; the third wrote no file it should have
    assert len(list((tmp_path / "logs").iterdir())) == 3    # every command ran to its end
