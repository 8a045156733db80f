# The bang-bang hop schedule, one phase at a time (pure: no clock, no hardware).
#
# The firmware asks for phase i when it is due instead of building the whole list: a
# 1000-cycle schedule is 2000 phases, and a list of 2000 tuples (with their boxed start
# times) costs tens of kB, a good part of the heap of an ESP32 without PSRAM.


def count(cycles):
    """The number of phases of `cycles` cycles (push, then wait)."""
    return 2 * cycles


def phase(i, push_deg, push_ms, wait_ms):
    """(cycle, name, start_us, horn_deg) of phase i (0-based) of push then wait cycles.

    cycle counts from 1; start_us is the commanded start from the beginning of the hop.
    """
    c = i // 2
    t0 = c * (push_ms + wait_ms) * 1000
    if i % 2 == 0:
        return (c + 1, "push", t0, push_deg)
    return (c + 1, "wait", t0 + push_ms * 1000, 0.0)


def phases(cycles, push_deg, push_ms, wait_ms):
    """[(cycle, name, start_us, horn_deg)] for `cycles` cycles (the whole list, for the host)."""
    return [phase(i, push_deg, push_ms, wait_ms) for i in range(count(cycles))]


def total_us(cycles, push_ms, wait_ms):
    return cycles * (push_ms + wait_ms) * 1000
