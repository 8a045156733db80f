# Servo configuration: the board's config.json, and the horn angle <-> pulse width maps.
#
# MicroPython-safe and pure (no machine): the host imports it as ``locust.firmware.config``
# to turn the virtual robot's PWM pulses back into horn angles with the same numbers.
#
# Horn angles are in "firmware units": degrees from rest, the same sign for both legs
# (push = -30). Each servo maps them to its own shaft angle with a direction (the right leg
# is mirrored: -1) and a trim, then to a pulse width over its calibrated pulse range.

import json

try:
    import os
except ImportError:  # pragma: no cover
    os = None

FILE = "config.json"
SERVOS = ("left", "right")

# key -> (lowest, highest, integer?)
LIMITS = {
    "pin": (0, 48, True),
    "pulse_min_us": (300, 2700, False),
    "pulse_max_us": (300, 2700, False),
    "range_deg": (30, 360, False),
    "trim_deg": (-30, 30, False),
    "direction": (-1, 1, True),
    "travel_deg": (1, 90, False),
}


def default():
    """The config used while config.json is missing or invalid.

    Its pulse range and travel are the robot parameters' (``locust.params.Servo``): this
    file cannot import the host, so it keeps a copy, and a host test checks the two agree.
    The host writes config.json from ``params.Servo`` itself (``locust flash``).
    """
    return {
        "left": {"pin": 18, "pulse_min_us": 500, "pulse_max_us": 2500, "range_deg": 180,
                 "trim_deg": 0.0, "direction": 1, "travel_deg": 45},
        "right": {"pin": 19, "pulse_min_us": 500, "pulse_max_us": 2500, "range_deg": 180,
                  "trim_deg": 0.0, "direction": -1, "travel_deg": 45},
    }


def problems(cfg):
    """Everything wrong with a config dict, as a list of strings (empty: valid)."""
    out = []
    if type(cfg) is not dict:
        return ["config is not an object"]
    for name in SERVOS:
        servo = cfg.get(name)
        if type(servo) is not dict:
            out.append(name + " missing")
            continue
        for key in LIMITS:
            lo, hi, whole = LIMITS[key]
            value = servo.get(key)
            if type(value) is not int and (whole or type(value) is not float):
                out.append("%s.%s must be %s" % (name, key, "an integer" if whole else "a number"))
            elif not (value == value and lo <= value <= hi):
                out.append("%s.%s=%s outside %s..%s" % (name, key, value, lo, hi))
        if not out:
            if servo["direction"] == 0:
                out.append(name + ".direction must be 1 or -1")
            if servo["pulse_max_us"] <= servo["pulse_min_us"]:
                out.append(name + ".pulse_max_us must exceed pulse_min_us")
            elif abs(servo["trim_deg"]) + servo["travel_deg"] > servo["range_deg"] / 2:
                out.append(name + ": travel plus trim exceed half the pulse range's angle")
    if not out and cfg["left"]["pin"] == cfg["right"]["pin"]:
        out.append("left and right use the same pin")
    return out


def load(path=FILE):
    """(config, problems): the file's config, or the default with the reason it was not used."""
    try:
        with open(path) as fh:
            cfg = json.loads(fh.read())
    except OSError:
        return default(), []
    except ValueError:
        return default(), [path + " is not valid JSON; using defaults"]
    bad = problems(cfg)
    if bad:
        return default(), [path + ": " + b for b in bad]
    return cfg, []


def save(cfg, path=FILE):
    """Validate and write atomically (write a temporary file, then rename)."""
    bad = problems(cfg)
    if bad:
        raise ValueError("; ".join(bad))
    tmp = path + ".tmp"
    with open(tmp, "w") as fh:
        fh.write(json.dumps(cfg))
    os.rename(tmp, path)


def with_value(cfg, key, value):
    """A copy of cfg with "left.trim_deg"-style key set; raises ValueError if invalid."""
    parts = key.split(".")
    if len(parts) != 2 or parts[0] not in SERVOS or parts[1] not in LIMITS:
        raise ValueError("unknown config key " + key)
    new = {name: dict(cfg[name]) for name in SERVOS}
    if LIMITS[parts[1]][2]:
        if value != int(value):
            raise ValueError(key + " must be an integer")
        value = int(value)
    new[parts[0]][parts[1]] = value
    bad = problems(new)
    if bad:
        raise ValueError("; ".join(bad))
    return new


def clamp(value, lo, hi):
    return lo if value < lo else hi if value > hi else value


def horn_to_pulse_us(servo, horn_deg):
    """(pulse_us, horn_deg actually commanded): the horn angle is clamped to the travel."""
    travel = servo["travel_deg"]
    horn = clamp(horn_deg, -travel, travel)
    shaft = servo["direction"] * horn + servo["trim_deg"]
    lo = servo["pulse_min_us"]
    hi = servo["pulse_max_us"]
    centre = (lo + hi) / 2
    pulse = centre + shaft * (hi - lo) / servo["range_deg"]
    return clamp(pulse, lo, hi), horn


def pulse_to_horn_deg(servo, pulse_us):
    """The inverse of horn_to_pulse_us (without the clamp)."""
    lo = servo["pulse_min_us"]
    hi = servo["pulse_max_us"]
    shaft = (pulse_us - (lo + hi) / 2) * servo["range_deg"] / (hi - lo)
    return (shaft - servo["trim_deg"]) / servo["direction"]
