"""The beam, hinge and servo fits of the REAL recordings in ../shared/data print the values
they printed before their solver vectors became calibrate.fitparams: each
estimate's line, value, relative sd and 95 % interval, to the printed digit. A change in a
fitter's packing, bounds or chain rule moves one of these digits; a deliberate change of a
fit updates them here with its reason. Lengths are printed in mm (`radius`, `rms_residual`:
they were printed in m beside the hinge's "(0.79 mm RMS)"), the JSON keeps metres."""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from locust.commands import cli


def printed(*args) -> list[str]:
    res = CliRunner().invoke(cli, ["calibrate", *map(str, args), "--no-plot"])
    assert res.exit_code == 0, res.output
    return [" ".join(line.split()) for line in res.stdout.splitlines()]


def assert_printed(lines: list[str], expected: str) -> None:
    """Each line of ``expected`` is a printed line, or the start of one (up to a space)."""
    for want in expected.strip().splitlines():
        want = " ".join(want.split())
        assert any(line == want or line.startswith(want + " ") for line in lines), \
            f"{want!r} not printed; got:\n" + "\n".join(lines)


def test_beam_fit_of_the_rubber_pendulum_prints_its_values(shared_data):
    """pendulum_rubber_60fps_m.csv fitted as a beam (29.5 g on the marker side)."""
    lines = printed("beam", shared_data / "hinge" / "pendulum_rubber_60fps_m.csv", "--mass-kg", 0.0295)
    assert_printed(lines, """
        natural_frequency 3.137 Hz ± 0.5 % (95 %: 3.102 … 3.172)
        damping_ratio 0.05921 ± 9.4 % (95 %: 0.04762 … 0.07080)
        stiffness 11.46 N/m ± 1.1 % (95 %: 11.21 … 11.72)
        damping 0.06886 N·s/m ± 9.4 % (95 %: 0.05535 … 0.08238)
        damped_frequency 3.132 Hz
        rms_residual 4.236 mm
        fit_window 0.1335, 4.705 s
    """)


def test_hinge_fit_of_damping_test_prints_its_values(shared_data):
    """Damping_test.trk without Coulomb friction (the fit with it: the slow test below); the
    residual is one figure in one unit where both say it: the row and the TOO NARROW flag."""
    lines = printed("hinge", shared_data / "hinge" / "Damping_test.trk", "--inertia-kgm2", 8.5e-7,
                    "--gravity", "out-of-plane", "--coulomb", "off")
    assert_printed(lines, EXPECTED["hinge_damping_nocoulomb"])
    row = next(ln for ln in lines if ln.startswith("rms_residual") and ln.endswith(" mm"))
    flag = next(ln for ln in lines if "TOO NARROW" in ln)
    assert f"({float(row.split()[1]):.2f} mm RMS)" in flag
    assert not [ln for ln in lines if ln.endswith(" m") or " m " in ln]


@pytest.mark.slow
def test_hinge_fit_of_damping_test_with_coulomb_prints_its_values(shared_data):
    lines = printed("hinge", shared_data / "hinge" / "Damping_test.trk", "--inertia-kgm2", 8.5e-7,
                    "--gravity", "out-of-plane")
    assert_printed(lines, EXPECTED["hinge_damping"])


@pytest.mark.slow
@pytest.mark.parametrize("name, files, inertias", [
    ("servo_aa", ["sg90_aa_battery_step.csv"], [3.3e-6]),
    ("servo_gyro", ["sg90_unloaded_gyro_steps.txt"], [1e-6]),
    ("servo_both", ["sg90_aa_battery_step.csv", "sg90_unloaded_gyro_steps.txt"], [3.3e-6, 1e-6]),
])
def test_servo_fits_of_the_real_sg90s_print_their_values(shared_data, name, files, inertias):
    args = [shared_data / "servo" / f for f in files]
    for inertia in inertias:
        args += ["--inertia-kgm2", inertia]
    lines = printed("servo", *args, "--stall-torque-nm", 0.15)
    assert_printed(lines, EXPECTED[name])


EXPECTED = {
    "hinge_damping_nocoulomb": """
        compliance.hinge_stiffness 1.461e-4 N·m/rad ± 0.2 % (95 %: 1.456e-4 … 1.466e-4) TOO NARROW: the residual (0.79
        compliance.hinge_damping 1.588e-6 N·m·s/rad ± 1.1 % (95 %: 1.553e-6 … 1.623e-6) TOO NARROW: the residual (0.79
        neutral_angle 95.00 deg ± 0.3 % (95 %: 94.35 … 95.65)
        coulomb_friction not fitted (--coulomb off)
        natural_frequency 2.087 Hz
        damping_ratio 0.07126
        rest_angle 95.00 deg
        radius 50.67 mm
        start_angle 72.19 deg
        rms_residual 0.7854 mm
        rms_residual 0.7982 deg
    """,
    # with Coulomb friction the swing is integrated and its Jacobian comes from the variational
    # equations: 10 times nearer central differences at a 100 times tighter tolerance than the
    # forward differences it replaced (3e-5 of a column against 3e-4), which had these at
    # 1.587e-6 and 7.192e-8 [1.468e-8, 1.292e-7] (a thousandth of a standard deviation away)
    "hinge_damping": """
        compliance.hinge_stiffness 1.458e-4 N·m/rad ± 0.2 % (95 %: 1.453e-4 … 1.463e-4) TOO NARROW: the residual (0.78
        compliance.hinge_damping 1.534e-6 N·m·s/rad ± 1.8 % (95 %: 1.480e-6 … 1.588e-6) TOO NARROW: the residual (0.78
        neutral_angle 94.99 deg ± 0.3 % (95 %: 94.35 … 95.64)
        coulomb_friction 7.190e-8 N·m ± 41 % (95 %: 1.466e-8 … 1.291e-7)
        coulomb_friction fitted: significant (score test p = 1.7e-05)
        natural_frequency 2.085 Hz
        damping_ratio 0.06888
        rest_angle 94.99 deg
        radius 50.57 mm
        start_angle 72.19 deg
        rms_residual 0.7793 mm
        rms_residual 0.7922 deg
    """,
    "servo_aa": """
        servo.noload_speed 10.23 rad/s ± 0.6 % (95 %: 10.12 … 10.35)
        servo.armature 3.130e-4 kg·m² ± 11 % (95 %: 2.466e-4 … 3.794e-4)
        servo.kp 0.2592 N·m/rad ± 7.4 % (95 %: 0.2212 … 0.2973)
        command_delay -0.03854 s
        command_delay_std 0.001920 s
        command_clock_ratio 0.9954
        command_clock_ratio_std 1.660e-4
        rms_residual 1.473 deg
        rms_per_recording 1.473
        rms_half_step 1.473
    """,
    "servo_gyro": """
        servo.noload_speed 10.53 rad/s ± 1.7 % (95 %: 10.17 … 10.89)
        servo.armature 4.879e-4 kg·m² ± 5.1 % (95 %: 4.375e-4 … 5.384e-4)
        servo.kp 0.3767 N·m/rad ± 4.0 % (95 %: 0.3457 … 0.4077)
        command_delay 0.02864 s
        command_delay_std 0.001500 s
        command_clock_ratio 1.000
        command_clock_ratio_std 0
        rms_residual 0.5827 rad/s
        rms_per_recording 0.5827
        rms_half_step 0.5829
        gyro_gain_units_per_rad_per_s[0] 7.796 ± 1.1 % (95 %: 7.624 … 7.968)
    """,
    "servo_both": """
        servo.noload_speed 10.31 rad/s ± 1.1 % (95 %: 10.08 … 10.53)
        servo.armature 4.646e-4 kg·m² ± 5.4 % (95 %: 4.141e-4 … 5.150e-4)
        servo.kp 0.3771 N·m/rad ± 3.6 % (95 %: 0.3493 … 0.4050)
        command_delay -0.04664, 0.02954 s
        command_delay_std 0.001950, 0.001430 s
        command_clock_ratio 0.9954, 1.000
        command_clock_ratio_std 3.570e-4, 0
        rms_residual 2.135 deg
        rms_residual 0.5798 rad/s
        rms_per_recording 2.135, 0.5798
        rms_half_step 2.122, 0.5804
        gyro_gain_units_per_rad_per_s[1] 7.878 ± 0.9 % (95 %: 7.727 … 8.029)
    """,
}
