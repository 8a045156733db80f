"""Audit a simulated run: a run that breaks its own physics is invalid, never a result.

Checks, each with a threshold stated here and reported with its measured value:

- non-finite state (NaN/inf anywhere in the record);
- loop closure: the two anchors of each leg's ``connect`` must stay together. A soft
  ``connect`` (the notebook's solref 0.02 s) lets them part by ~1 cm under servo torque: that
  is reported as a note; apart by more than the shortest link, the linkage has come apart
  (the seed's broken sweep left them 8-17 cm apart) and the run is invalid;
- energy: the mechanical energy (kinetic + gravity + springs) may not rise above its start
  plus the work the servos did, beyond a small slack for soft contacts; a blow-up makes
  energy out of nothing;
- MuJoCo's own warnings (bad acceleration, full constraint buffers, ...);
- at rest when the schedule starts: after ``solver.settle_s`` the robot's kinetic energy, as
  the speed of its whole mass, must be under ``SETTLED_SPEED_LIMIT_M_PER_S``. A robot still
  falling from its drop (a 0.1 s settle after the 8 cm drop: 0.15-1 m/s) would start its
  first push in the air; a 0.3 s settle leaves under 1.2 mm/s, the default 0.5 s under
  0.02 mm/s. (A zero settle, the notebook's, starts at rest at the drop height.)
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .rollout import Trajectory

LOOP_RESIDUAL_NOTE_M = 0.002         # above this: a note that the loop is soft
ASSEMBLY_RESIDUAL_LIMIT_M = 1e-6     # the model must be built closed
# Soft constraints and contacts store and return a little energy; a blow-up creates joules.
ENERGY_SLACK_J = 0.005
ENERGY_SLACK_OF_WORK = 0.10
SETTLED_SPEED_LIMIT_M_PER_S = 0.05   # sqrt(2 KE / mass) when the first push is sent


@dataclass
class Audit:
    """The audit of one run: whether it is valid, why not, and the figures it was judged on.

    Attributes
    ----------
    valid : bool
        No check failed.
    reasons : list of str
        Each failed check, with its measured value and limit.
    loop_residual_max_m : float
        Largest distance between a leg's two loop anchors during the run [m].
    energy_surplus_max_j : float
        Largest mechanical energy above its start plus the servos' work, E(t) - E(0) - W_servo(t) [J].
    servo_work_j : float
        Positive work the servos did [J].
    warnings : dict of str to int
        MuJoCo's warnings by name, with their counts.
    notes : list of str
        What is worth knowing but does not invalidate the run (a soft loop).
    """

    valid: bool
    reasons: list[str] = field(default_factory=list)
    loop_residual_max_m: float = float("nan")
    energy_surplus_max_j: float = float("nan")    # max of E(t) - E(0) - W_servo(t)
    servo_work_j: float = float("nan")            # positive work the servos did
    warnings: dict[str, int] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


def audit(traj: Trajectory) -> Audit:
    """Check a rollout against its own physics (the checks are listed in the module docstring).

    Parameters
    ----------
    traj : Trajectory
        The rollout, with its sensor data.

    Returns
    -------
    Audit
        Invalid, with its reasons, when any check fails.
    """
    s = traj.built.sensors
    sd = traj.sensordata
    reasons: list[str] = []
    notes: list[str] = []

    finite_rows = np.isfinite(sd).all(axis=1) & np.isfinite(traj.final_qpos).all()
    if not finite_rows.all():
        first = int(np.argmin(finite_rows))
        reasons.append(f"non-finite state from t = {first * traj.timestep_s:.4f} s (step {first})")
    sd_ok = sd[finite_rows] if finite_rows.any() else sd[:0]

    residual0 = max(float(np.linalg.norm(traj.initial_sensordata[s.loop_a[side]]
                                         - traj.initial_sensordata[s.loop_b[side]]))
                    for side in s.loop_a)
    if residual0 > ASSEMBLY_RESIDUAL_LIMIT_M:
        reasons.append(f"model built open: loop anchors {residual0 * 1e6:.3g} um apart before the first step "
                       f"(limit {ASSEMBLY_RESIDUAL_LIMIT_M * 1e6:g} um)")
    residual = 0.0
    for side in s.loop_a:
        gap = np.linalg.norm(sd_ok[:, s.loop_a[side]] - sd_ok[:, s.loop_b[side]], axis=1)
        if gap.size:
            residual = max(residual, float(gap.max()))
    shortest_link = min(traj.built.link_lengths_m)
    if residual > shortest_link:
        reasons.append(f"loop closure broken: anchors {residual * 1000:.1f} mm apart, more than the "
                       f"shortest link ({shortest_link * 1000:.1f} mm): the linkage came apart")
    elif residual > LOOP_RESIDUAL_NOTE_M:
        notes.append(f"soft loop: anchors up to {residual * 1000:.1f} mm apart under load "
                     f"(stiffen solver.loop_timeconst_s / solver.loop_dmax)")

    e0 = float(traj.initial_sensordata[s.energy_potential][0] + traj.initial_sensordata[s.energy_kinetic][0])
    energy = sd_ok[:, s.energy_potential][:, 0] + sd_ok[:, s.energy_kinetic][:, 0]
    power = (sd_ok[:, s.actuator_force] * sd_ok[:, s.actuator_velocity]).sum(axis=1)
    work = np.cumsum(power) * traj.timestep_s
    surplus = float((energy - e0 - work).max()) if energy.size else float("nan")
    positive_work = float(np.clip(power, 0, None).sum() * traj.timestep_s)
    slack = ENERGY_SLACK_J + ENERGY_SLACK_OF_WORK * positive_work
    if not surplus <= slack:
        reasons.append(f"energy audit failed: mechanical energy rose {surplus:.4g} J above the start "
                       f"plus servo work (slack {slack:.3g} J): the simulation created energy")

    if traj.plan.settle_steps > 0 and len(sd) >= traj.plan.settle_steps:
        kinetic_j = float(sd[traj.plan.settle_steps - 1, s.energy_kinetic][0])
        speed = (2.0 * max(kinetic_j, 0.0) / float(traj.built.model.body_mass.sum())) ** 0.5
        if not speed <= SETTLED_SPEED_LIMIT_M_PER_S:
            reasons.append(f"not at rest when the schedule started: the robot moved at {speed * 1000:.0f} mm/s "
                           f"(limit {SETTLED_SPEED_LIMIT_M_PER_S * 1000:.0f} mm/s) after "
                           f"{traj.plan.settle_steps * traj.timestep_s:g} s of settling: it was still falling "
                           "from its drop; raise solver.settle_s or lower geometry.drop_height_m")

    if traj.warnings:
        listed = ", ".join(f"{name.removeprefix('mjWARN_')} x{n}" for name, n in traj.warnings.items())
        reasons.append(f"MuJoCo warnings: {listed}")

    return Audit(valid=not reasons, reasons=reasons, notes=notes, loop_residual_max_m=residual,
                 energy_surplus_max_j=surplus, servo_work_j=positive_work, warnings=dict(traj.warnings))
