"""A batched ``mujoco.rollout`` run in chunks of steps, and the memory a batch may take.

``mujoco.rollout`` holds the interpreter for the whole call: a signal (Ctrl-C, the TERM of
``timeout`` or a CI runner) waits until it returns. Run in chunks of at most
:data:`CHUNK_MODEL_STEPS` model-steps, each chunk starting from the state the last one ended
in, a signal ends the command between two chunks, within a second or two. One model's chunks
carry the solver's warm start from one to the next, so its record is the one-call record bit
for bit; a batch of several models is split only when it is long (over
:data:`SPLIT_BATCH_MODEL_STEPS`), as its warm starts cannot be carried per model (its records
then differ by the solver's tolerance, ~1e-7).

A batch keeps every step's sensors (and state, for a video) of every model: its size is
checked against :data:`MAX_BATCH_BYTES` before anything is built or allocated.
"""

from __future__ import annotations

import mujoco
import numpy as np
from mujoco import rollout as mj_rollout

from ..errors import SimError

# Model-steps per rollout call: about 0.1 s of the seed robot on a quiet core, 0.5 s on a busy one.
CHUNK_MODEL_STEPS = 2_000
# A batch of several models shorter than this runs in one call, bit for bit as before (a fit's
# candidates, --samples over a few cycles); a longer one is split for the signal's sake.
SPLIT_BATCH_MODEL_STEPS = 400_000
# What a batch's record may take: every step's sensors and state of every model, 8 bytes a
# number. 4 GiB: beside the rest on a laptop of 8 GB; one seed robot over the 2,000,000-step
# budget is 0.9 GB, 64 draws over 1000 cycles would be 38 GB.
MAX_BATCH_BYTES = 4 * 2**30


def batch_bytes(model: mujoco.MjModel, n_models: int, nstep: int, keep_states: bool = True) -> int:
    """Bytes of the record of ``n_models`` copies of ``model`` over ``nstep`` steps.

    Parameters
    ----------
    model : mujoco.MjModel
        The model: its sensor and full-physics state sizes.
    n_models : int
        Models in the batch.
    nstep : int
        Physics steps of each.
    keep_states : bool
        Whether every step's state is kept beside the sensors.

    Returns
    -------
    int
        The record's size [bytes], 8 a number.
    """
    nstate = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    return 8 * n_models * nstep * (model.nsensordata + (nstate if keep_states else 0))


def check_batch(model: mujoco.MjModel, n_models: int, nstep: int, keep_states: bool = True) -> None:
    """Refuse a batch whose record would be over :data:`MAX_BATCH_BYTES`.

    Parameters
    ----------
    model : mujoco.MjModel
        The model: its sensor and full-physics state sizes.
    n_models : int
        Models in the batch.
    nstep : int
        Physics steps of each.
    keep_states : bool
        Whether every step's state is kept beside the sensors.

    Raises
    ------
    SimError
        The record would be over the limit; the hint names ``--cycles`` and ``--samples``.
    """
    need = batch_bytes(model, n_models, nstep, keep_states)
    if need > MAX_BATCH_BYTES:
        raise SimError(f"{n_models} simulation(s) of {nstep:,} steps would keep {need / 2**30:.1f} GiB of states and "
                       f"sensors, over the limit of {MAX_BATCH_BYTES / 2**30:g} GiB",
                       "simulate fewer cycles (--cycles) or fewer draws (--samples): the spread of 16 draws over "
                       "a few cycles is the prediction's")


def add_warnings(data: mujoco.MjData, into: dict[str, int]) -> None:
    """Add the warnings MuJoCo counted on ``data`` in its last call to ``into`` (name -> count).

    Parameters
    ----------
    data : mujoco.MjData
        A data a rollout call ran on (each call counts afresh).
    into : dict of str to int
        The counts so far, added to.
    """
    for i in range(len(data.warning)):
        if data.warning[i].number:
            name = mujoco.mjtWarning(i).name
            into[name] = into.get(name, 0) + int(data.warning[i].number)


def chunk_bounds(nstep: int, n_models: int) -> list[tuple[int, int]]:
    """The ``[start, stop)`` steps of each rollout call for ``n_models`` over ``nstep`` steps.

    Parameters
    ----------
    nstep : int
        Physics steps of the run.
    n_models : int
        Models in the batch.

    Returns
    -------
    list of tuple of int
        One ``(start, stop)`` per call, covering ``0 .. nstep``: one call for a short batch of
        several models, else at most :data:`CHUNK_MODEL_STEPS` model-steps each.
    """
    if n_models > 1 and n_models * nstep <= SPLIT_BATCH_MODEL_STEPS:
        return [(0, nstep)]
    size = max(1, CHUNK_MODEL_STEPS // n_models)
    return [(a, min(nstep, a + size)) for a in range(0, nstep, size)]


def rollout_chunked(models: list[mujoco.MjModel], datas: list[mujoco.MjData], initial_state: np.ndarray,
                    control: np.ndarray, keep_states: bool
                    ) -> tuple[np.ndarray | None, np.ndarray, np.ndarray, dict[str, int]]:
    """``mujoco.rollout`` of ``models`` (one or many) from ``initial_state`` under ``control``
    in chunks (see the module doc). Each call counts its warnings afresh, so they are added
    up chunk by chunk.

    Parameters
    ----------
    models : list of mujoco.MjModel
        The models, all of one structure.
    datas : list of mujoco.MjData
        One ``MjData`` per thread.
    initial_state : ndarray
        ``(n_models, nstate)`` full-physics start states.
    control : ndarray
        ``(n_models, nstep, nu)`` actuator commands for every step [rad].
    keep_states : bool
        Whether every step's state is returned.

    Returns
    -------
    states : ndarray or None
        ``(n_models, nstep, nstate)`` the state after each step, or None without ``keep_states``.
    sensordata : ndarray
        ``(n_models, nstep, nsensordata)`` the sensors of each step.
    final : ndarray
        ``(n_models, nstate)`` the state after the last step.
    warnings : dict of str to int
        MuJoCo's warning name -> count, summed over the chunks and datas.
    """
    n, nstep = control.shape[0], control.shape[1]
    model_arg = models if len(models) > 1 else models[0]
    data_arg = datas if len(datas) > 1 else datas[0]
    sensordata = np.empty((n, nstep, models[0].nsensordata))
    states = None
    state, warmstart = initial_state, None
    warnings: dict[str, int] = {}
    for a, b in chunk_bounds(nstep, n):
        chunk_state, chunk_sensors = mj_rollout.rollout(model_arg, data_arg, state, control[:, a:b],
                                                        initial_warmstart=warmstart)
        sensordata[:, a:b] = chunk_sensors
        if keep_states:
            if states is None:
                states = np.empty((n, nstep, chunk_state.shape[2]))
            states[:, a:b] = chunk_state
        state = chunk_state[:, -1].copy()
        for data in datas:
            add_warnings(data, warnings)
        if n == 1:   # one model on one data: its warm start goes on to the next chunk
            warmstart = datas[0].qacc_warmstart.copy()[None]
    return states, sensordata, state, warnings
