# Two hobby servos on machine.PWM at 50 Hz, driven by horn angle (firmware units).
#
# The angle is clamped to the servo's mechanical travel before it becomes a pulse, so no
# command (from the protocol or a bug) can drive a leg past its stops. On the ESP32 a new
# duty takes effect at the start of the next 20 ms PWM period.

import config

PERIOD_HZ = 50


class Servos:
    def __init__(self, cfg, pwm_cls, pin_cls):
        self.cfg = cfg
        self.pwm = {}
        self.horn_deg = {}
        try:
            for name in config.SERVOS:
                pulse, _ = config.horn_to_pulse_us(cfg[name], 0.0)
                # freq and duty_ns in the constructor: from MicroPython 1.26 the channel starts
                # with this duty. Older ESP32 ports start it at 50 % (a 10 ms pulse, the servo
                # lunges to its end stop) until duty_ns applies; locust flash refuses them.
                self.pwm[name] = pwm_cls(pin_cls(cfg[name]["pin"]), freq=PERIOD_HZ, duty_ns=int(pulse * 1000))
                self.horn_deg[name] = 0.0
        except Exception:
            self.deinit()  # the left servo's channel must not stay on when the right one fails
            raise

    def set(self, left_deg, right_deg):
        """Command both horns; returns the (clamped) angles actually commanded."""
        for name, angle in (("left", left_deg), ("right", right_deg)):
            pulse, horn = config.horn_to_pulse_us(self.cfg[name], angle)
            self.pwm[name].duty_ns(int(pulse * 1000))
            self.horn_deg[name] = horn
        return self.horn_deg["left"], self.horn_deg["right"]

    def rest(self):
        return self.set(0.0, 0.0)

    def deinit(self):
        for name in list(self.pwm):
            self.pwm.pop(name).deinit()
