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


# Which GPIOs may drive a servo, per chip. Every chip's MicroPython reports the same
# sys.platform ("esp32"); os.uname().machine names the chip ("... with ESP32S3"), and each
# chip wires different pins to its flash, its console and its boot straps. A pin outside
# these lists either does not exist as a machine.Pin there ("invalid pin"), cannot drive an
# output, or takes the console, the flash or the boot mode with it, which can leave the board
# unreachable or crash-looping. The reasons are what the user is told.
# (pins, kind, reason): kind "input" cannot drive a pulse, "flash" takes the module's flash
# or PSRAM with it (the board crashes), "console" the USB serial link, "strap" the boot mode.
_ESP32_RESERVED = (
    ((0, 2, 5, 12, 15), "strap",
     "a boot strapping pin (a servo's pull can change how the chip boots; 12 sets the flash voltage)"),
    ((1, 3), "console", "the console UART (TX 1, RX 3): the USB serial link to the host"),
    ((6, 7, 8, 9, 10, 11), "flash", "wired to the module's SPI flash (driving it crashes the board)"),
    ((16, 17), "flash", "wired to the PSRAM on WROVER modules (not a Pin in the SPIRAM build)"),
    ((34, 35, 36, 37, 38, 39), "input", "input only (no output driver: it cannot make a PWM pulse)"),
)
_S2S3_RESERVED = (
    ((0, 45, 46), "strap", "a boot strapping pin (a servo's pull can change how the chip boots)"),
    ((26,), "flash", "wired to the PSRAM's chip select (not a Pin in the SPIRAM build)"),
    ((43, 44), "console", "the UART0 pins (TX 43, RX 44): the boot log and a REPL"),
)
_S2S3_PINS = tuple(range(0, 19)) + (21, 26) + tuple(range(33, 47))  # 19/20: the native USB
CHIPS = {
    # chip: (GPIOs MicroPython's machine.Pin accepts, reserved, (default left, right pin))
    "esp32": (tuple(range(0, 20)) + (21, 22, 23, 25, 26, 27) + tuple(range(32, 40)), _ESP32_RESERVED, (18, 19)),
    "s2": (_S2S3_PINS, _S2S3_RESERVED, (4, 5)),
    "s3": (_S2S3_PINS + (47, 48), _S2S3_RESERVED + (
        ((3,), "strap", "a boot strapping pin (JTAG source)"),
        ((33, 34, 35, 36, 37), "flash", "wired to the octal PSRAM or flash on N8R8/N16R8 modules"),
        ((47, 48), "other", "present only on the extended-IO builds, and 1.8 V on octal modules"),
    ), (4, 5)),
    "c3": (tuple(range(0, 14)) + (20, 21), (
        ((2, 8, 9), "strap", "a boot strapping pin (9 is the BOOT button)"),
        ((11,), "flash", "the flash's power pin (VDD_SPI) on most modules"),
        ((12, 13), "flash", "wired to the module's SPI flash"),
        ((20, 21), "console", "the UART0 pins (RX 20, TX 21): the boot log"),
    ), (4, 5)),
}
# why a GPIO a chip lacks is missing (18/19 on the C3, 19/20 on the S2/S3 are its USB)
_MISSING = {"c3": {18: "the USB-Serial-JTAG line D-", 19: "the USB-Serial-JTAG line D+"},
            "s2": {19: "the native USB line D-", 20: "the native USB line D+"},
            "s3": {19: "the native USB line D-", 20: "the native USB line D+"}}
BOOT_BUTTON = {"esp32": 0, "s2": 0, "s3": 0, "c3": 9}  # held low at boot: skip the firmware


def chip_of(machine):
    """The chip ("esp32", "s2", "s3", "c3") named by os.uname().machine, or None if another.

    MicroPython's ESP32 port reports "<board> with <MCU>", the MCU being ESP32, ESP32S2,
    ESP32S3, ESP32C3 (and others locust has no pin rules for)."""
    mcu = str(machine).split(" with ")[-1].strip().upper().replace("-", "")
    if not mcu.startswith("ESP32"):
        return None
    name = mcu[5:].lower() or "esp32"
    return name if name in CHIPS else None


def pin_problem(pin, chip):
    """Why ``pin`` cannot drive a servo on ``chip`` (None: it can, or the chip is unknown)."""
    if chip not in CHIPS:
        return None
    exists, reserved, _ = CHIPS[chip]
    if pin not in exists:
        why = _MISSING.get(chip, {}).get(pin)
        return "GPIO%s is not a machine.Pin on the %s%s" % (pin, chip_name(chip), " (" + why + ")" if why else "")
    for pins, _, why in reserved:
        if pin in pins:
            return "GPIO%s on the %s is %s" % (pin, chip_name(chip), why)
    return None


def pins_of_kind(chip, kind):
    """The pins of ``chip`` reserved as ``kind`` ("input", "flash", "console", "strap")."""
    out = []
    for pins, k, _ in CHIPS[chip][1]:
        if k == kind:
            out.extend(pins)
    return out


def usable_pins(chip):
    """The GPIOs that may drive a servo on ``chip``."""
    return [p for p in CHIPS[chip][0] if pin_problem(p, chip) is None]


def chip_name(chip):
    return "ESP32" if chip == "esp32" else "ESP32-" + str(chip).upper()


def default(chip="esp32"):
    """The config used while config.json is missing or invalid, with ``chip``'s default pins.

    Its pulse range and travel are the robot parameters' (``locust.params.Servo``): this
    file cannot import the host, so it keeps a copy, and a host test checks the two agree.
    The host writes config.json from ``params.Servo`` itself (``locust flash``).
    """
    left, right = CHIPS[chip][2] if chip in CHIPS else CHIPS["esp32"][2]
    return {
        "left": {"pin": left, "pulse_min_us": 500, "pulse_max_us": 2500, "range_deg": 180,
                 "trim_deg": 0.0, "direction": 1, "travel_deg": 45},
        "right": {"pin": right, "pulse_min_us": 500, "pulse_max_us": 2500, "range_deg": 180,
                  "trim_deg": 0.0, "direction": -1, "travel_deg": 45},
    }


def problems(cfg, chip=None):
    """Everything wrong with a config dict, as a list of strings (empty: valid).

    With ``chip`` the pins are checked against that chip's rules (CHIPS)."""
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
    if not out:
        for name in SERVOS:
            why = pin_problem(cfg[name]["pin"], chip)
            if why:
                out.append("%s.pin: %s" % (name, why))
    return out


def load(path=FILE, chip=None):
    """(config, problems): the file's config, or the default with the reason it was not used."""
    try:
        with open(path) as fh:
            cfg = json.loads(fh.read())
    except OSError:
        return default(chip), []
    except ValueError:
        return default(chip), [path + " is not valid JSON; using defaults"]
    bad = problems(cfg, chip)
    if bad:
        return default(chip), [path + ": " + b for b in bad]
    return cfg, []


def save(cfg, path=FILE, chip=None):
    """Validate and write atomically (write a temporary file, then rename)."""
    bad = problems(cfg, chip)
    if bad:
        raise ValueError("; ".join(bad))
    tmp = path + ".tmp"
    with open(tmp, "w") as fh:
        fh.write(json.dumps(cfg))
    os.rename(tmp, path)


def with_value(cfg, key, value, chip=None):
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
    bad = problems(new, chip)
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
