"""locust.bundled_recording in a checkout: every file of calibration/recordings (their home, the
docs' paths) is found through the package, and a name that is not one is refused with the
names there are. The same in an installed wheel: tests/test_wheel.py and the notebook's wheel run."""

from __future__ import annotations

from pathlib import Path

import pytest

import locust
from locust.bundled import bundled_recording, bundled_recordings
from locust.errors import CalibrationError

ROOT = Path(__file__).resolve().parents[1]
HOME = ROOT / "calibration" / "recordings"


def test_every_file_in_the_recordings_folder_is_found_through_the_package():
    home = sorted(p.name for p in HOME.iterdir() if p.is_file() and not p.name.startswith("."))
    assert bundled_recordings() == home and "synthetic_beam.csv" in home
    for name in home:
        path = bundled_recording(name)
        assert path.is_absolute() and path.name == name
        assert path.resolve() == (HOME / name).resolve()
    assert locust.bundled_recording("synthetic_ramp.csv") == bundled_recording("synthetic_ramp.csv")


@pytest.mark.parametrize("name", ["synthetic_nothing.csv", "../robot.toml", "recordings/synthetic_beam.csv",
                                  str(HOME / "synthetic_beam.csv"), ""])
def test_a_name_that_is_not_a_bundled_recording_is_refused_with_the_names(name):
    with pytest.raises(CalibrationError) as err:
        bundled_recording(name)
    assert err.value.message == f"no bundled recording is named {name!r}"
    assert err.value.hint.startswith("the bundled recordings are: ") and "synthetic_servo.csv" in err.value.hint
