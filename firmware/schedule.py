# The bang-bang hop schedule as a list of phases (pure: no clock, no hardware).


def phases(cycles, push_deg, push_ms, wait_ms):
    """[(cycle, name, start_us, horn_deg)] for `cycles` cycles of push then wait.

    cycle counts from 1; start_us is the commanded start from the beginning of the hop.
    """
    out = []
    period_us = (push_ms + wait_ms) * 1000
    for c in range(cycles):
        t0 = c * period_us
        out.append((c + 1, "push", t0, push_deg))
        out.append((c + 1, "wait", t0 + push_ms * 1000, 0.0))
    return out


def total_us(cycles, push_ms, wait_ms):
    return cycles * (push_ms + wait_ms) * 1000
