"""Robot parameters: presets, overrides, TOML round trip, errors."""

import pytest

from locust import params
from locust.errors import ParamsError
from locust.io import robot_toml


def test_presets_add_one_and_two_cm_to_every_link():
    seed = params.preset("seed").link_lengths_m()
    for name, added in (("small", 0.0), ("medium", 0.01), ("large", 0.02)):
        got = params.preset(name).link_lengths_m()
        assert got == pytest.approx(tuple(v + added for v in seed), abs=1e-12)
    assert seed == (0.04, 0.04, 0.02, 0.06)


def test_seed_notebook_runs_the_notebook_way():
    nb = params.preset("seed-notebook")
    assert (nb.solver.timestep_s, nb.solver.control_hz, nb.solver.settle_s) == (1e-4, 60.0, 0.0)
    assert nb.source_of("servo.kp_nm_per_rad").source == "seed"


def test_set_overrides_and_records_provenance():
    r = robot_toml.resolve_robot("seed", None, ["servo.kp_nm_per_rad=25", "contact.self_collision=true"])
    assert r.servo.kp_nm_per_rad == 25.0 and r.contact.self_collision is True
    assert r.source_of("servo.kp_nm_per_rad").source == "override"


@pytest.mark.parametrize("item, fragment", [
    ("servo.kp=3", "unknown robot parameter"),
    ("servo.kp_nm_per_rad", "is not KEY=VALUE"),
    ("servo.kp_nm_per_rad=abc", "bad value"),
    ("schedule.cycles=2.5", "not a whole number"),
])
def test_bad_set_options(item, fragment):
    with pytest.raises(ParamsError) as err:
        robot_toml.resolve_robot("seed", None, [item])
    assert fragment in err.value.message


def test_toml_round_trip_keeps_values_and_uncertainty(tmp_path):
    fitted = params.preset("medium").with_values(
        {"compliance.hinge_stiffness_nm_per_rad": 0.061},
        params.Provenance(source="fit:beam.csv", uncertainty=0.002, date="2026-11-21"))
    path = robot_toml.save_robot(fitted, tmp_path / "robot.toml")
    back = robot_toml.load_robot(path)
    assert back.flat() == fitted.flat()
    prov = back.source_of("compliance.hinge_stiffness_nm_per_rad")
    assert (prov.source, prov.uncertainty, prov.date) == ("fit:beam.csv", 0.002, "2026-11-21")


def test_broken_toml_names_the_file(tmp_path):
    bad = tmp_path / "robot.toml"
    bad.write_text("[servo]\nkp_nm_per_rad = = 3\n")
    with pytest.raises(ParamsError) as err:
        robot_toml.load_robot(bad)
    assert str(bad) in err.value.message


def test_a_misspelt_base_preset_is_refused(tmp_path):
    """Before: `base = "meduim"` silently loaded the seed."""
    path = tmp_path / "robot.toml"
    path.write_text('name = "mine"\nbase = "meduim"\n')
    with pytest.raises(ParamsError, match="base = 'meduim' is not a preset"):
        robot_toml.load_robot(path)
    path.write_text('name = "mine"\nbase = "medium"\n')
    assert robot_toml.load_robot(path).geometry.leg_m == pytest.approx(0.07)   # Medium: +1 cm on the seed's 6 cm


@pytest.mark.parametrize("raw", ['"big"', "-0.1", "nan", "true"])
def test_an_uncertainty_that_is_not_a_number_is_an_error_not_a_traceback(tmp_path, raw):
    path = tmp_path / "robot.toml"
    path.write_text(f'[servo]\nkp_nm_per_rad = {{ value = 0.26, source = "fit:x", uncertainty = {raw} }}\n')
    with pytest.raises(ParamsError, match=r"servo.kp_nm_per_rad has uncertainty = .* not a number >= 0"):
        robot_toml.load_robot(path)
    path.write_text('[servo]\nkp_nm_per_rad = { value = 0.26, source = "fit:x", uncertainty = 0.019 }\n')
    assert robot_toml.load_robot(path).source_of("servo.kp_nm_per_rad").uncertainty == 0.019
