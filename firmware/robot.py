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

import gc
import sys
import time

import config
import protocol as P
import schedule

ticks_us = time.ticks_us
ticks_diff = time.ticks_diff

# Busy-wait the last few milliseconds before a phase starts: a sleeping wait (poll) can
# wake late on a busy system, the spin cannot. Input is serviced outside this window.
SPIN_US = 4000
MAX_POLL_MS = 50


CTRL_C = 0x03


class Console:
    """The USB serial console (stdin/stdout) as a byte port.

    ``ctrl_c(on)`` says whether Ctrl-C stops the command loop (KeyboardInterrupt). On the
    ESP32 the console driver raises it itself (``micropython.kbd_intr(3)``) and the byte never
    reaches stdin; where the console hands 0x03 over as a byte (the unix port behind the
    virtual robot's raw pseudo-terminal), read() raises it, leaving the bytes after it unread
    for the REPL. Switched off, 0x03 is an ordinary byte on both.
    """

    def __init__(self):
        import micropython
        import select
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


class Controller:
    def __init__(self, port, make_servos, cfg, cfg_problems=(), cfg_path=config.FILE):
        self.port = port
        self.make_servos = make_servos
        self.cfg = cfg
        self.cfg_problems = list(cfg_problems)
        self.cfg_path = cfg_path
        self.servos = make_servos(cfg)
        self.reader = P.LineReader()
        self.last_rx = ticks_us()
        self.hop = None            # {"id", "stop"} while a hop runs
        self.pending_hop = None    # (id, args) accepted, to start from the main loop
        self.phases = []           # [(cycle, phase, commanded_us, measured_us)] of the last hop
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
                       config_problems=self.cfg_problems, hopping=self.hop is not None)

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
        page = [list(p) for p in self.phases[start:start + P.REPORT_PAGE]]
        return P.reply(req_id, status=self.status, total=len(self.phases), start=start, phases=page)

    def do_config(self, req_id, args):
        key = args["key"]
        if args["write"]:
            try:
                new = config.with_value(self.cfg, key, args["value"])
                config.save(new, self.cfg_path)
            except ValueError as e:
                raise P.ProtocolError(P.E_RANGE, str(e)[:120], req_id)
            self.servos.rest()
            self.servos.deinit()
            self.cfg = new
            self.cfg_problems = []
            self.servos = self.make_servos(new)
        if not key:
            return P.reply(req_id, config=self.cfg)
        parts = key.split(".")
        if len(parts) != 2 or parts[0] not in self.cfg or parts[1] not in self.cfg[parts[0]]:
            raise P.ProtocolError(P.E_RANGE, "unknown config key " + key, req_id)
        return P.reply(req_id, key=key, value=self.cfg[parts[0]][parts[1]])

    def do_repl(self, req_id, args):
        self.servos.rest()
        self.quit = True
        return P.reply(req_id)

    # -- the hop -------------------------------------------------------------------
    def _wait_until(self, t0, target_us, heartbeat_us):
        """None once target_us (from t0) is reached, or the reason to abort."""
        while True:
            if self.hop["stop"]:
                return P.HOP_STOPPED
            now = ticks_us()
            silent = ticks_diff(now, self.last_rx)
            if silent > heartbeat_us:
                return P.HOP_HEARTBEAT
            left = target_us - ticks_diff(now, t0)
            if left <= 0:
                return None
            if left > SPIN_US:
                wait = min(left - SPIN_US, heartbeat_us - silent) // 1000
                self.poll(max(0, min(wait, MAX_POLL_MS)))

    def run_hop(self, req_id, args):
        plan = schedule.phases(args["cycles"], args["push_deg"], args["push_ms"], args["wait_ms"])
        end_us = schedule.total_us(args["cycles"], args["push_ms"], args["wait_ms"])
        heartbeat_us = args["heartbeat_ms"] * 1000
        self.phases = []
        self.status = None
        self.hop = {"id": req_id, "stop": False}
        status = P.HOP_COMPLETE
        self.ctrl_c(False)  # a stray 0x03 on the line must not stop the legs mid-hop
        gc.collect()  # collect now, not in the middle of a phase's timing
        t0 = ticks_us()
        self.last_rx = t0
        try:
            for i in range(len(plan) + 1):
                target = plan[i][2] if i < len(plan) else end_us
                abort = self._wait_until(t0, target, heartbeat_us)
                if abort:
                    status = abort
                    break
                if i == len(plan):
                    break
                cycle, name, start_us, angle = plan[i]
                self.servos.set(angle, angle)
                measured = ticks_diff(ticks_us(), t0)
                self.phases.append((cycle, name, start_us, measured))
                self.send(P.event(P.EV_PHASE, hop=req_id, i=i, cycle=cycle, phase=name,
                                  commanded_us=start_us, measured_us=measured))
                gc.collect()  # every phase lasts >= 20 ms: room for it before the next one
        finally:
            self.servos.rest()
            self.hop = None
            self.ctrl_c(True)
        self.status = status
        late = [abs(p[3] - p[2]) for p in self.phases]
        self.send(P.event(P.EV_DONE, hop=req_id, status=status, phases=len(self.phases),
                          total=len(plan), max_err_us=max(late) if late else 0,
                          rest_us=ticks_diff(ticks_us(), t0)))

    # -- main loop -----------------------------------------------------------------
    def step(self, timeout_ms=100):
        self.poll(timeout_ms)
        if self.pending_hop is not None:
            req_id, args = self.pending_hop
            self.pending_hop = None
            self.run_hop(req_id, args)

    def run(self):
        self.send(P.event(P.EV_BOOT, name=P.NAME, version=P.VERSION, protocol=P.PROTOCOL))
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


def main():
    from machine import PWM, Pin
    from servo import Servos

    cfg, bad = config.load()
    console = Console()
    ctl = Controller(console, lambda c: Servos(c, PWM, Pin), cfg, bad)
    interrupted = False
    try:
        ctl.run()
    except KeyboardInterrupt:  # Ctrl-C while idle: main.py ends, the REPL takes the console
        interrupted = True
    finally:
        console.ctrl_c(False)  # a second Ctrl-C (some tools send two) must not cut the rest short
        ctl.servos.rest()
        console.ctrl_c(True)  # the REPL's own Ctrl-C
    if interrupted:
        console.write(STOPPED)
