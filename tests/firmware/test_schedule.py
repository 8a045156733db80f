# The hop schedule (runs under CPython and MicroPython).
import schedule


def test_phases_of_the_seed_schedule():
    plan = schedule.phases(6, -30.0, 300, 1000)
    assert len(plan) == 12
    assert plan[0] == (1, "push", 0, -30.0)
    assert plan[1] == (1, "wait", 300000, 0.0)
    assert plan[11] == (6, "wait", 5 * 1300000 + 300000, 0.0)
    assert schedule.total_us(6, 300, 1000) == 7800000
