"""`sweep --vary` of a whole-number parameter refuses a range whose steps are not whole before
any design runs (an earlier version ran `solver.iterations=1:10.5:3` and marked 5.75 and 10.5
invalid)."""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from locust.commands import cli
from locust.errors import SweepError
from locust.params import preset
from locust.sweep.design import parse_axis


def test_fractional_steps_of_a_whole_number_are_refused(tmp_path):
    res = CliRunner().invoke(cli, ["sweep", "--vary", "solver.iterations=1:10.5:3", "--out", str(tmp_path / "s")])
    assert res.exit_code == 2 and "is a whole number, and this range gives 5.75, 10.5" in res.output, res.output
    assert "hint:" in res.output and not (tmp_path / "s").exists()


def test_whole_steps_and_real_parameters_are_kept():
    assert parse_axis("solver.iterations=10:30:3", preset("seed")).values() == [10.0, 20.0, 30.0]
    assert parse_axis("geometry.leg_m=0.05:0.06:3", preset("seed")).values()[1] == pytest.approx(0.055)
    with pytest.raises(SweepError, match="gives 2.5"):
        parse_axis("solver.iterations=1:4:3", preset("seed"))
