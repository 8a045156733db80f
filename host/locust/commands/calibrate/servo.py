"""``locust calibrate servo``: the hobby servo identified from step responses."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import click

from ...calibrate import inputs
from ...calibrate import servo as servo_fit
from ...calibrate.plots import plot_fit
from ...errors import CalibrationError
from ...io.importing import ImportOptions
from ...progress import progress
from ..options import FINITE, POSITIVE, import_options, time_options
from .options import output_options
from .output import default_plot_path, finish, interruptible


@click.command()
@click.argument("data", nargs=-1, required=True, type=click.Path(dir_okay=False, path_type=Path))
@click.option("--inertia-kgm2", type=POSITIVE, multiple=True, required=True,
              help="Load inertia about the servo axis [kg*m^2]; once, or once per DATA in the same order.")
@click.option("--stall-torque-nm", type=POSITIVE, default=None,
              help="Stall torque [N*m] from a stall test or the datasheet (SG90: about 0.15). It splits the "
                   "ratios one load gives; leave it out when DATA holds loads of very different inertia (beside the "
                   "armature: a few 1e-4 kg*m^2 for an SG90) or a load held against gravity.")
@click.option("--kv-nms-per-rad", type=FINITE, default=0.0, show_default=True,
              help="Velocity feedback inside the drive's clamp [N*m*s/rad], held at this value: the SG90's real "
                   "recordings do not ask for it (docs/servo.md).")
@click.option("--fit-kv", is_flag=True,
              help="Fit kv too (steps of several sizes, as a gyro log holds, are needed to tell it from kp).")
@click.option("--gravity-moment-nm", type=FINITE, multiple=True,
              help="Moment of the load's weight with the horn horizontal (angle 0) [N*m]; once, or once per DATA "
                   "[default: 0, a horizontal rig].")
@click.option("--pivot", default=None, metavar="X,Y",
              help="Servo axis in the track's coordinates [m]: DATA is then a track of the horn tip.")
@click.option("--step", "step", default=None, metavar="FROM,TO,AT_S",
              help="With --pivot: the commanded step, degrees from the horizontal, and when it was sent [s].")
@click.option("--marker", default=None, help="With --pivot: marker of the horn tip [default: the only one].")
@click.option("--validate", "validate", multiple=True, type=click.Path(dir_okay=False, path_type=Path),
              help="A recording not fitted (repeatable): predict it with the fitted servo, report its RMS and "
                   "each step's peak speed, measured and predicted, and draw it.")
@click.option("--validate-inertia-kgm2", type=POSITIVE, multiple=True,
              help="Load inertia of the --validate recordings; once, or once per --validate [default: that of "
                   "the first fitted recording of the same kind].")
@import_options
@time_options
@output_options
def servo(data, inertia_kgm2, stall_torque_nm, kv_nms_per_rad, fit_kv, gravity_moment_nm, pivot, step, marker, validate,
          validate_inertia_kgm2, imports, timing, write_path, as_json, plot_path, no_plot, force):
    """Identify the hobby servo (no-load speed, armature, kp; kv with --fit-kv) from step responses.

    Each DATA is one of two kinds, told apart by its layout:

    \b
    angle  a CSV with a header t_s,angle_deg,command_deg (degrees from the horizontal;
           a square-wave command's steps are fitted together), or with --pivot and
           --step a track of the horn tip;
    rate   a gyro log on the horn: rows millis,command_deg,gyro with no header (the
           controller's clock in ms, the command, the gyro in its own unit). The gyro's
           gain [units per rad/s] is fitted; between steps the horn must rest.

    Recordings of both kinds, each with its own --inertia-kgm2, are fitted together to one
    servo. The rig is simulated in MuJoCo with the robot model's servo (docs/servo.md); the
    timing of each recording (a delay and, for an angle recording of three or more command
    edges, the ratio of camera and firmware clocks) is fitted beside it and reported.
    Parameters the recordings cannot determine are reported as not identifiable and never
    written. --validate predicts other recordings with the fitted servo (their own delay,
    and the fitted gyro gain, are the only things fitted to them).

    \b
    Examples (real SG90s: an AA battery swung 0 <-> 180 deg; a gyro on an unloaded horn):
      locust calibrate servo sg90_aa_battery_step.csv --inertia-kgm2 3.3e-6 --stall-torque-nm 0.15
      locust calibrate servo sg90_aa_battery_step.csv sg90_unloaded_gyro_steps.txt \\
          --inertia-kgm2 3.3e-6 --inertia-kgm2 1e-6 --stall-torque-nm 0.15 --validate other_steps.txt
    """
    inertias = inputs.per_recording(inertia_kgm2, len(data), "--inertia-kgm2")
    moments = inputs.per_recording(gravity_moment_nm or (0.0,), len(data), "--gravity-moment-nm")
    if pivot is not None and len(data) > 1:
        raise CalibrationError("--pivot takes one horn track", "fit tracks one at a time, or give angle CSVs")
    recordings = [inputs.servo_recording(path, servo_fit.ServoRig(inertia, moment), pivot, step, marker, imports,
                                         timing)
                  for path, inertia, moment in zip(data, inertias, moments)]
    if pivot is None and not imports.identity:
        raise CalibrationError("--units, --rename and --mirror apply to a horn track (--pivot), not to angles",
                               "leave them out for t_s,angle_deg,command_deg recordings and gyro logs")
    from ...api.calibration import fit_servo_recordings

    with (progress(length=servo_fit.progress_steps(len(recordings)), label="fitting servo") as bar,
          interruptible("the servo fit")):
        facade_fit = fit_servo_recordings(recordings, stall_torque_nm, kv_nms_per_rad=kv_nms_per_rad, fit_kv=fit_kv,
                                          progress=bar.update)
    fit = facade_fit.result
    validations = []
    if validate:
        v_inertias = inputs.per_recording(validate_inertia_kgm2, len(validate), "--validate-inertia-kgm2") \
            if validate_inertia_kgm2 else [None] * len(validate)
        for path, inertia in zip(validate, v_inertias):
            rec = inputs.servo_recording(path, servo_fit.ServoRig(inertias[0]), None, None, None, ImportOptions(),
                                         timing)
            if inertia is None:
                inertia = next((r.rig.inertia_kgm2 for r in recordings if r.kind == rec.kind), inertias[0])
            rec = replace(rec, rig=servo_fit.ServoRig(inertia))
            validations.append(servo_fit.validate(fit.servo, rec, gain=fit.rate_gain))
    extra = {}
    if validations:
        extra["validation"] = [v.summary() for v in validations]
        if not no_plot:
            target = plot_path.with_name(plot_path.stem + "-validate.png") if plot_path else \
                default_plot_path(validate[0], "servo").with_name(f"{validate[0].stem}-validate.png")
            extra["validation_plot"] = str(plot_fit([v.curves for v in validations], target,
                                                    "predicted by the fitted servo (not fitted to it)", force))
    finish(facade_fit, data[0], write_path, as_json, plot_path, no_plot, force, extra=extra)
