"""Which OpenGL MuJoCo renders with, and MuJoCo imported whatever the answer.

MuJoCo chooses its OpenGL backend from ``MUJOCO_GL`` as it is first imported, and the import
itself fails when it cannot have it: a value it does not know (``MUJOCO_GL=bogus``: a
``RuntimeError``), or ``osmesa`` on a machine without the OSMesa library (PyOpenGL's
``AttributeError``). Only rendering needs OpenGL; simulating, the statics and the fits do not.
So the backend is checked first, here, and where it cannot be had MuJoCo is imported with
rendering off (``MUJOCO_GL=disable`` for the import alone: the variable is the user's again
afterwards, and so in every process this one starts). A render then stops with what is wrong
and what to install (:func:`check_renderer`), and everything else runs.

MuJoCo is imported here, as this module is (``locust.sim`` imports it first): a module outside
``locust.sim`` takes ``mujoco`` (and ``minimize``, its least-squares solver) from here, never
importing MuJoCo before it.
"""

from __future__ import annotations

import ctypes
import importlib
import os
import platform

from ..errors import SimError

# The values MuJoCo 4.0's Python bindings accept (mujoco/rendering/classic/gl_context.py; the
# engine is pinned), by operating system.
_OFF = ("disable", "disabled", "off", "false", "0")
_ANY = ("enable", "enabled", "on", "true", "1", "glfw", "")
_BY_SYSTEM = {"Linux": ("glx", "egl", "osmesa"), "Windows": ("wgl",), "Darwin": ("cgl",)}
OSMESA_PACKAGE = "libosmesa6"
INSTALL_OSMESA = f"sudo apt-get install -y {OSMESA_PACKAGE}"

_problem: tuple[str, str] | None = None   # (what, hint) once MuJoCo is imported without a renderer


def backend_problem(value: str | None, system: str | None = None) -> tuple[str, str] | None:
    """Why MuJoCo cannot render with ``MUJOCO_GL=value`` on ``system`` (None: it can, as far as
    can be told before a context is made).

    Parameters
    ----------
    value : str or None
        ``MUJOCO_GL`` as set (None: not set).
    system : str, optional
        ``platform.system()``; this machine's by default.

    Returns
    -------
    tuple of str, or None
        The problem and its hint.
    """
    system = system or platform.system()
    given = (value or "").lower().strip()
    if given in _OFF:
        return (f"MUJOCO_GL={value}: rendering is switched off",
                f"unset MUJOCO_GL to render with OSMesa ({INSTALL_OSMESA}), or MUJOCO_GL=egl on a GPU")
    known = _ANY + _BY_SYSTEM.get(system, ())
    if given not in known:
        names = ", ".join(v for v in known if v.isalpha() and v not in ("enable", "enabled", "on", "true"))
        return (f"MUJOCO_GL={value}: not an OpenGL backend MuJoCo knows (on {system}: {names})",
                f"unset MUJOCO_GL (locust renders with osmesa: {INSTALL_OSMESA}), or MUJOCO_GL=egl on a GPU")
    if system == "Linux" and given == "osmesa" and not _osmesa_loads():
        return (f"MUJOCO_GL=osmesa, but the OSMesa library (libOSMesa.so, Debian's {OSMESA_PACKAGE}) is not "
                "installed or does not load", f"install it: {INSTALL_OSMESA} (or MUJOCO_GL=egl on a GPU)")
    return None


def _osmesa_loads() -> bool:
    """Whether the OSMesa library loads under one of the names PyOpenGL tries for MuJoCo
    (``libOSMesa.so``, then ``libOSMesa.so.9`` down to ``.0``)."""
    for name in ["libOSMesa.so", *(f"libOSMesa.so.{n}" for n in range(9, -1, -1))]:
        try:
            ctypes.CDLL(name, mode=ctypes.RTLD_GLOBAL)
            return True
        except OSError:
            continue
    return False


def import_mujoco():
    """MuJoCo, imported with the backend ``MUJOCO_GL`` names, or with rendering off when it
    cannot have it (:func:`backend_problem`; :func:`check_renderer` then refuses to render).

    Returns
    -------
    module
        ``mujoco``.

    Raises
    ------
    locust.errors.SimError
        MuJoCo cannot be imported even so.
    """
    global _problem
    value = os.environ.get("MUJOCO_GL")
    problem = backend_problem(value)
    if problem is not None and (value or "").lower().strip() not in _OFF:
        os.environ["MUJOCO_GL"] = "disable"
    try:
        import mujoco
    except Exception as exc:   # the backend's own libraries failed in a way not foreseen above
        raise SimError(f"MuJoCo cannot be imported with MUJOCO_GL={value} ({type(exc).__name__}: {exc})",
                       f"unset MUJOCO_GL (locust renders with osmesa: {INSTALL_OSMESA}), or MUJOCO_GL=egl "
                       "on a GPU") from None
    finally:
        if value is None:
            os.environ.pop("MUJOCO_GL", None)
        else:
            os.environ["MUJOCO_GL"] = value
    _problem = problem
    return mujoco


def check_renderer() -> None:
    """Refuse to render where MuJoCo was imported without a renderer (:func:`import_mujoco`).

    Raises
    ------
    locust.errors.SimError
        What is wrong with ``MUJOCO_GL`` or its library, and what to do.
    """
    if _problem is not None:
        raise SimError(f"cannot render: {_problem[0]}", _problem[1])


mujoco = import_mujoco()
minimize = importlib.import_module("mujoco.minimize")
