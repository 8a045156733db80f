# The robot's command loop: frames in on the USB serial console, replies and events out.
#
# Nothing that arrives may crash it: every line is decoded and checked by protocol.py, and
# any error (even a bug here) becomes an error reply while the loop carries on.
#
# Ctrl-C (0x03) stops the loop while it idles, as it stops main.py on any MicroPython
# board: the servos go to rest and the console is the REPL (mpremote gets in this way; Ctrl-D
# there, a soft reset, runs main.py again). While a hop runs Ctrl-C is switched off, so a
# stray 0x03 is just a byte of a bad frame and cannot stop the legs half-way. The `repl`
# command also hands the console back to the REPL (`locust flash` uses it).
#
# There is no watchdog: MicroPython's ESP32 machine.WDT cannot be stopped once started, so it
# would reset a board left at the REPL. A silent host is covered by the heartbeat, and the
# console's writes do not block for ever on any chip (the UART drains by itself; USB CDC and
# USB-Serial-JTAG give up after a timeout when no host reads).

import gc
import sys
import time
from array import array

import config
import protocol as P
import schedule

ticks_us = time.ticks_us
ticks_diff = time.ticks_diff

# Busy-wait the last 12 ms before a phase starts. On the ESP32 select.poll() with a timeout
# sleeps in FreeRTOS ticks (ulTaskNotifyTake(.., 1) in MicroPython's poll loop, 10 ms ticks
# at CONFIG_FREERTOS_HZ=100): it returns on the first tick after its timeout, up to 10 ms
# late. Sleeping only until 12 ms before the phase keeps that overshoot out of the phase
# start; the spin cannot be late. Input is serviced outside this window (poll(0) only).
SPIN_US = 12000
MAX_POLL_MS = 50


CTRL_C = 0x03


class Console:
    """The USB serial console (stdin/stdout) as a byte port.

    ``ctrl_c(on)`` says whether Ctrl-C stops the command loop (KeyboardInterrupt). On the
    ESP32 the console driver raises it itself (``micropython.kbd_intr(3)``) and the byte never
    reaches stdin (the virtual robot does the same with a SIGINT); where a console hands 0x03
    over as a byte (the unix port on a raw terminal), read() raises it, leaving the bytes after
    it unread for the REPL. Switched off, 0x03 is an ordinary byte on both.

    Input is read a byte per poll(0): a board's stdin has no non-blocking read of "what is
    there", and read(n) would block for n bytes. That costs tens of microseconds a byte on
    the chip, so it happens only outside the spin before a phase.
    """

    def __init__(self):
        import select

        import micropython
        self._in = sys.stdin.buffer
        self._out = sys.stdout.buffer
        self._pollin = select.POLLIN
        self._poller = select.poll()
        self._poller.register(sys.stdin, select.POLLIN)
        self._kbd_intr = micropython.kbd_intr
        self.ctrl_c(True)

    def ctrl_c(self, on):
        self.interruptible = on
        self._kbd_intr(CTRL_C if on else -1)

    def _ready(self, timeout_ms):
        for _, ev in self._poller.poll(timeout_ms):
            if ev & self._pollin:
                return True
        return False

    def read(self, timeout_ms):
        """The bytes that arrive within timeout_ms (b"" if none), at most 64."""
        if not self._ready(timeout_ms):
            return b""
        data = bytearray()
        while len(data) < 64:
            b = self._in.read(1)  # poll said ready: one byte never blocks
            if not b:
                break
            if b[0] == CTRL_C and self.interruptible:
                raise KeyboardInterrupt
            data += b
            if not self._ready(0):
                break
        return bytes(data)

    def write(self, data):
        self._out.write(data)


class Elapsed:
    """Microseconds since start(), valid however long a hop runs.

    ticks_us() wraps at 2**30 us (17.9 min) on a 32-bit board, and ticks_diff() is only right
    for differences under 2**29 us (8.9 min); a hop may last 1000 x 70 s. So the elapsed time
    is summed from the differences between consecutive readings, each far below 2**29 us
    (the hop loop reads the clock at least every MAX_POLL_MS). Past 2**30 us the sum is a
    long integer on the board, as it should be.
    """

    def start(self):
        self.last = ticks_us()
        self.total = 0
        return self.last

    def now(self):
        t = ticks_us()
        self.total += ticks_diff(t, self.last)
        self.last = t
        return self.total


class NoServos:
    """Stands in when no servo could be created at boot (bad pins): the loop still answers,
    so the host can read config_problems and write a config that works."""

    def set(self, left_deg, right_deg):
        raise ValueError("no servos: fix the config (locust flash --servo left.pin=...)")

    def rest(self):
        return 0.0, 0.0

    def deinit(self):
        pass


RESET_CAUSES = {1: "power_on", 2: "hard", 3: "watchdog", 4: "deepsleep", 5: "soft"}


def reset_cause():
    """machine.reset_cause() by name. On the ESP32 MicroPython reports a brown-out (the supply
    sagging under the servos' stall current) as PWRON_RESET: "power_on" while the board's power
    stayed plugged in means a brown-out."""
    try:
        import machine
        return RESET_CAUSES.get(machine.reset_cause(), "unknown")
    except Exception:
        return "unknown"


def machine_name():
    """os.uname().machine ("<board> with ESP32S3"): the only place a board names its chip."""
    try:
        import os
        return os.uname().machine
    except Exception:  # a port without os.uname (the unix port without the virtual robot's shim)
        return ""


class Controller:
    def __init__(self, port, make_servos, cfg, cfg_problems=(), cfg_path=config.FILE, chip=None,
                 servos=None):
        self.port = port
        self.make_servos = make_servos
        self.cfg = cfg
        self.cfg_problems = list(cfg_problems)
        self.cfg_path = cfg_path
        self.chip = chip
        self.servos = servos if servos is not None else make_servos(cfg)
        self.reader = P.LineReader()
        self.last_rx = ticks_us()
        self.hop = None            # {"id", "stop"} while a hop runs
        self.pending_hop = None    # (id, args) accepted, to start from the main loop
        self.hop_args = None       # the last hop's arguments: its phases follow from them
        self.errors = array("i")   # measured - commanded start of each phase of the last hop, us
        self.status = None         # status of the last hop
        self.quit = False

    # -- I/O ---------------------------------------------------------------------
    def ctrl_c(self, on):
        """Let Ctrl-C stop the loop (on) or make 0x03 a plain byte (off), if the port can."""
        allow = getattr(self.port, "ctrl_c", None)
        if allow is not None:
            allow(on)

    def send(self, msg):
        self.port.write(P.encode(msg))

    def poll(self, timeout_ms):
        data = self.port.read(timeout_ms)
        if data:
            for line in self.reader.feed(data):
                self.handle_line(line)

    def handle_line(self, line):
        req_id = None
        try:
            if line is None:
                raise P.ProtocolError(P.E_TOO_LONG, "frame longer than %d bytes" % P.MAX_FRAME)
            obj = P.decode(line)
            self.last_rx = ticks_us()  # any intact frame proves the host is alive
            if type(obj.get("id")) is int:
                req_id = obj["id"]
            req_id, cmd, args = P.check_request(obj)
            if self.hop is not None and cmd not in P.DURING_HOP:
                raise P.ProtocolError(P.E_BUSY, cmd + " is not allowed during a hop", req_id)
            self.send(getattr(self, "do_" + cmd)(req_id, args))
        except P.ProtocolError as e:
            self.send(P.error(e.req_id if e.req_id is not None else req_id, e.code, e.detail))
        except Exception as e:  # a bug: report it, keep the loop alive
            self.send(P.error(req_id, P.E_INTERNAL, repr(e)[:100]))

    # -- commands (each returns the reply) ----------------------------------------
    def do_hello(self, req_id, args):
        return P.reply(req_id, name=P.NAME, version=P.VERSION, protocol=P.PROTOCOL,
                       platform=sys.platform, mpy=getattr(sys.implementation, "_mpy", 0),
                       micropython=list(sys.implementation.version[:3]), machine=machine_name(),
                       chip=self.chip, reset=reset_cause(), config_problems=self.cfg_problems,
                       hopping=self.hop is not None)

    def do_ping(self, req_id, args):
        return P.reply(req_id, t_us=ticks_us())

    def do_stop(self, req_id, args):
        running = self.hop is not None
        if running:
            self.hop["stop"] = True
        self.servos.rest()
        return P.reply(req_id, stopped=running)

    def do_rest(self, req_id, args):
        self.servos.rest()
        return P.reply(req_id, left_deg=0.0, right_deg=0.0)

    def _check_travel(self, req_id, name, angle):
        travel = min(self.cfg["left"]["travel_deg"], self.cfg["right"]["travel_deg"])
        if abs(angle) > travel:
            raise P.ProtocolError(P.E_RANGE, "%s=%s beyond the servo travel +-%s deg" % (name, angle, travel), req_id)

    def do_pose(self, req_id, args):
        self._check_travel(req_id, "left_deg", args["left_deg"])
        self._check_travel(req_id, "right_deg", args["right_deg"])
        left, right = self.servos.set(args["left_deg"], args["right_deg"])
        return P.reply(req_id, left_deg=left, right_deg=right)

    def do_hop(self, req_id, args):
        self._check_travel(req_id, "push_deg", args["push_deg"])
        self.pending_hop = (req_id, args)
        return P.reply(req_id, phases=2 * args["cycles"],
                       duration_us=schedule.total_us(args["cycles"], args["push_ms"], args["wait_ms"]))

    def do_report(self, req_id, args):
        start = args["start"]
        page = []
        a = self.hop_args
        for i in range(start, min(start + P.REPORT_PAGE, len(self.errors))):
            cycle, name, start_us, _ = schedule.phase(i, a["push_deg"], a["push_ms"], a["wait_ms"])
            page.append([cycle, name, start_us, start_us + self.errors[i]])
        return P.reply(req_id, status=self.status, total=len(self.errors), start=start, phases=page)

    def do_config(self, req_id, args):
        key = args["key"]
        if args["write"]:
            try:
                # the chip's pin rules as well as the limits: a pin the chip refuses must never
                # reach config.json, where it would be tried at every boot
                new = config.with_value(self.cfg, key, args["value"], self.chip)
            except ValueError as e:
                raise P.ProtocolError(P.E_RANGE, str(e)[:160], req_id) from None
            self._apply(req_id, new)
        if not key:
            return P.reply(req_id, config=self.cfg)
        parts = key.split(".")
        if len(parts) != 2 or parts[0] not in self.cfg or parts[1] not in self.cfg[parts[0]]:
            raise P.ProtocolError(P.E_RANGE, "unknown config key " + key, req_id)
        return P.reply(req_id, key=key, value=self.cfg[parts[0]][parts[1]])

    def _apply(self, req_id, new):
        """Drive the servos from ``new``, then save it; on any failure the old config and its
        servos come back and nothing is saved. Saving first (as before) could store a config
        whose pins fail, and main.py would then fail on it at every boot."""
        self.servos.rest()
        self.servos.deinit()
        try:
            servos = self.make_servos(new)
        except Exception as e:  # e.g. ValueError("invalid pin") from machine.Pin
            self.servos = self.make_servos(self.cfg)  # the old pins worked: they still do
            raise P.ProtocolError(P.E_RANGE, ("the board refused the new config: " + repr(e))[:160], req_id) from None
        try:
            config.save(new, self.cfg_path, self.chip)
        except Exception as e:  # a full or failing filesystem
            servos.rest()
            servos.deinit()
            self.servos = self.make_servos(self.cfg)
            raise P.ProtocolError(P.E_INTERNAL, ("config.json not saved: " + repr(e))[:160], req_id) from None
        self.servos = servos
        self.cfg = new
        self.cfg_problems = []

    def do_repl(self, req_id, args):
        self.servos.rest()
        self.quit = True
        return P.reply(req_id)

    # -- the hop -------------------------------------------------------------------
    def _wait_until(self, clock, target_us, heartbeat_us):
        """None once target_us (from the hop's start) is reached, or the reason to abort."""
        while True:
            if self.hop["stop"]:
                return P.HOP_STOPPED
            left = target_us - clock.now()
            # the heartbeat's silence is short (<= 10 s): one ticks_diff is exact for it
            silent = ticks_diff(clock.last, self.last_rx)
            if silent > heartbeat_us:
                return P.HOP_HEARTBEAT
            if left <= 0:
                return None
            if left > SPIN_US:
                # the heartbeat's deadline gets the same 12 ms margin as a phase: within it
                # the loop polls without sleeping (poll(0)), still reading the host's pings
                wait = (min(left, heartbeat_us - silent) - SPIN_US) // 1000
                self.poll(max(0, min(wait, MAX_POLL_MS)))

    def run_hop(self, req_id, args):
        n = schedule.count(args["cycles"])
        end_us = schedule.total_us(args["cycles"], args["push_ms"], args["wait_ms"])
        heartbeat_us = args["heartbeat_ms"] * 1000
        self.hop_args = args
        self.errors = array("i")  # let the last hop's go before the new one is allocated
        self.errors = array("i", bytearray(4 * n))  # one allocation: 8 kB for 1000 cycles
        done = 0
        worst = 0
        self.status = None
        self.hop = {"id": req_id, "stop": False}
        status = P.HOP_COMPLETE
        self.ctrl_c(False)  # a stray 0x03 on the line must not stop the legs mid-hop
        gc.collect()  # collect now, not in the middle of a phase's timing
        clock = Elapsed()
        self.last_rx = t0_ticks = clock.start()
        try:
            for i in range(n + 1):
                if i < n:
                    cycle, name, start_us, angle = schedule.phase(i, args["push_deg"], args["push_ms"], args["wait_ms"])
                else:
                    start_us = end_us
                abort = self._wait_until(clock, start_us, heartbeat_us)
                if abort:
                    status = abort
                    break
                if i == n:
                    break
                self.servos.set(angle, angle)
                measured = clock.now()
                self.errors[i] = measured - start_us
                done = i + 1
                worst = max(worst, abs(measured - start_us))
                self.send(P.event(P.EV_PHASE, hop=req_id, i=i, cycle=cycle, phase=name,
                                  commanded_us=start_us, measured_us=measured))
                gc.collect()  # every phase lasts >= 20 ms: room for it before the next one
        finally:
            # whatever failed above (even rest() itself), the loop must come back idle with
            # Ctrl-C on: a hop left "running" answers busy to everything but stop
            self.hop = None
            try:
                self.servos.rest()
            finally:
                self.ctrl_c(True)
        self.errors = self.errors[:done]
        self.status = status
        rest_us = clock.now()
        # the raw ticks_us at the start and the end: a wrap crossed if the end is the smaller
        self.send(P.event(P.EV_DONE, hop=req_id, status=status, phases=done, total=n, max_err_us=worst,
                          rest_us=rest_us, ticks_us=[t0_ticks, clock.last]))

    # -- main loop -----------------------------------------------------------------
    def step(self, timeout_ms=100):
        self.poll(timeout_ms)
        if self.pending_hop is not None:
            req_id, args = self.pending_hop
            self.pending_hop = None
            self.run_hop(req_id, args)

    def run(self):
        self.send(P.event(P.EV_BOOT, name=P.NAME, version=P.VERSION, protocol=P.PROTOCOL,
                          reset=reset_cause()))
        while not self.quit:
            try:
                self.step()
            except Exception as e:  # never leave the loop on a bug
                try:
                    self.servos.rest()
                    self.send(P.error(None, P.E_INTERNAL, repr(e)[:100]))
                except Exception:
                    pass


STOPPED = b"\r\nlocust: Ctrl-C stopped the command loop, servos at rest; Ctrl-D restarts it\r\n"


ESCAPE_FILE = "noboot"


def escape(chip):
    """True to skip the firmware at boot and leave the board at the REPL: a file named
    ``noboot`` on the board, or the BOOT button held down while it boots. However the
    firmware or its config fails, a board can always be reached this way."""
    try:
        import os
        os.stat(ESCAPE_FILE)
        return True
    except OSError:
        pass
    button = config.BOOT_BUTTON.get(chip)
    if button is None:
        return False
    try:
        from machine import Pin
        return Pin(button, Pin.IN, Pin.PULL_UP).value() == 0
    except Exception:
        return False


def boot_servos(cfg, bad, chip, make):
    """(config, problems, servos) for boot: the saved config if its servos start, else the
    chip's default config, else none at all; never an exception (a crash here would
    repeat at every boot)."""
    try:
        return cfg, bad, make(cfg)
    except Exception as e:
        bad = bad + ["servos on the saved config failed: " + repr(e)[:80]]
    fallback = config.default(chip)
    try:
        return fallback, bad + ["using the default config"], make(fallback)
    except Exception as e:
        return fallback, bad + ["servos on the default config failed: " + repr(e)[:80]], NoServos()


def main():
    from machine import PWM, Pin
    from servo import Servos

    chip = config.chip_of(machine_name())
    if escape(chip):
        print("locust: boot escape (noboot file or BOOT button): firmware not started")
        return
    make = lambda c: Servos(c, PWM, Pin)  # noqa: E731
    cfg, bad, servos = boot_servos(*config.load(config.FILE, chip), chip, make)
    console = Console()
    ctl = Controller(console, make, cfg, bad, config.FILE, chip, servos)
    interrupted = False
    try:
        ctl.run()
    except KeyboardInterrupt:  # Ctrl-C while idle: main.py ends, the REPL takes the console
        interrupted = True
    finally:
        console.ctrl_c(False)  # a second Ctrl-C (some tools send two) must not cut the rest short
        try:
            ctl.servos.rest()
        except Exception:  # Ctrl-C can land anywhere on a board, e.g. between a config's deinit and its new servos
            pass
        console.ctrl_c(True)  # the REPL's own Ctrl-C
    if interrupted:
        console.write(STOPPED)
