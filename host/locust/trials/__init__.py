"""Filmed trials: the measured tracks and run records of each trial, grouped by leg set
(:mod:`.measured`), their configurations on a robot (:mod:`.configs`), and each trace put on
the schedule's clock from its first push (:mod:`.measure`). ``calibrate hop`` and ``report``
both build on it."""
