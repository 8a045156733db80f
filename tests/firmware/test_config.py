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


def test_chip_named_by_uname_machine():
    # os.uname().machine as MicroPython's ESP32 port builds it: "<board> with <MCU>"
    assert config.chip_of("Generic ESP32 module with ESP32") == "esp32"
    assert config.chip_of("Generic ESP32S2 module with ESP32S2") == "s2"
    assert config.chip_of("ESP32S3 module with ESP32S3") == "s3"
    assert config.chip_of("ESP32C3 module with ESP32C3") == "c3"
    assert config.chip_of("ESP32C6 module with ESP32C6") is None  # no pin rules: refused by flash
    assert config.chip_of("linux [GCC 14.2.1] version") is None


def test_pin_rules_per_chip():
    refused = {"esp32": (0, 1, 3, 6, 11, 12, 20, 34, 39, 40), "s2": (0, 19, 20, 22, 43, 46),
               "s3": (0, 3, 19, 20, 35, 43), "c3": (8, 9, 12, 18, 19, 20, 22)}
    accepted = {"esp32": (4, 13, 18, 19, 33), "s2": (4, 5, 21, 42), "s3": (4, 5, 21, 42), "c3": (0, 4, 5, 10)}
    for chip in config.CHIPS:
        for pin in refused[chip]:
            assert config.pin_problem(pin, chip) is not None, (chip, pin)
        for pin in accepted[chip]:
            assert config.pin_problem(pin, chip) is None, (chip, pin)
        assert config.problems(config.default(chip), chip) == []  # each chip's default pins are its own
    # the classic ESP32's defaults (18, 19) are the USB lines of a C3: refused there
    assert len(config.problems(config.default("esp32"), "c3")) == 2
    assert config.pin_problem(6, None) is None  # unknown chip: only the 0..48 range applies


def test_with_value_checks_the_chip():
    cfg = config.default("esp32")
    for pin in (6, 34, 1):
        try:
            config.with_value(cfg, "left.pin", pin, "esp32")
        except ValueError as e:
            assert "GPIO%d" % pin in str(e)
            continue
        raise AssertionError("accepted left.pin=%d" % pin)
    assert config.with_value(cfg, "left.pin", 4, "esp32")["left"]["pin"] == 4
