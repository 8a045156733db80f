# Servo configuration and the angle <-> pulse maps (runs under CPython and MicroPython).
import config


def _close(a, b, tol=1e-6):
    return abs(a - b) <= tol


def test_default_is_valid():
    assert config.problems(config.default()) == []


def test_pulse_map_known_values():
    cfg = config.default()
    # 500..2500 us over 180 deg: 2000/180 us per degree about 1500 us
    assert config.horn_to_pulse_us(cfg["left"], 0.0) == (1500.0, 0.0)
    pulse, horn = config.horn_to_pulse_us(cfg["left"], -30.0)
    assert _close(pulse, 1500 - 30 * 2000 / 180) and horn == -30.0
    pulse, _ = config.horn_to_pulse_us(cfg["right"], -30.0)  # mirrored leg
    assert _close(pulse, 1500 + 30 * 2000 / 180)


def test_clamped_to_travel():
    cfg = config.default()
    pulse, horn = config.horn_to_pulse_us(cfg["left"], -80.0)
    assert horn == -45 and _close(pulse, 1000.0)
    pulse, horn = config.horn_to_pulse_us(cfg["right"], 1e9)
    assert horn == 45 and _close(pulse, 1000.0)


def test_inverse_with_trim():
    cfg = config.with_value(config.default(), "right.trim_deg", 3.5)
    for angle in (-45.0, -30.0, -1.25, 0.0, 12.0, 45.0):
        pulse, _ = config.horn_to_pulse_us(cfg["right"], angle)
        assert _close(config.pulse_to_horn_deg(cfg["right"], pulse), angle, 1e-9)


def test_with_value_rejects():
    cfg = config.default()
    for key, value in (("left.trim_deg", 99), ("left.direction", 0), ("left.pin", 19),
                       ("left.pulse_max_us", 400), ("middle.pin", 3), ("left.colour", 1),
                       ("left.pin", 2.5)):
        try:
            config.with_value(cfg, key, value)
        except ValueError:
            continue
        raise AssertionError("accepted %s=%s" % (key, value))
    assert cfg == config.default()  # untouched


def test_save_load_roundtrip():
    path = "/tmp/locust_fw_test_config.json"
    cfg = config.with_value(config.default(), "left.trim_deg", -2.0)
    config.save(cfg, path)
    loaded, bad = config.load(path)
    assert bad == [] and loaded["left"]["trim_deg"] == -2.0
    with open(path, "w") as fh:
        fh.write("{broken")
    loaded, bad = config.load(path)
    assert loaded == config.default() and len(bad) == 1
