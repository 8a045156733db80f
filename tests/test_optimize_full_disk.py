"""`locust optimize` on a disk that fills up mid-trial: the command ends with
error:/hint:, and the journal it tore is mended by `--repair` (saved beside it first), every
whole trial kept. The full disk is a real one: a 64 kB tmpfs (mounting needs root; the test is
skipped, saying so, where mounting is not allowed)."""

from __future__ import annotations

import errno
import hashlib
import re
import shutil

from click.testing import CliRunner

from locust.commands import cli
from locust.sweep.journal import full_disk, repair

VARY = ["--vary", "geometry.leg_m=0.05:0.07", "--cycles", "1"]


def optimize(*args):
    return CliRunner().invoke(cli, ["optimize", *VARY, *map(str, args)])


def test_a_journal_torn_by_a_full_disk_is_refused_then_repaired(tmp_path, small_disk):
    small_disk, _ = small_disk
    first = optimize("--trials", 5, "--out", tmp_path / "opt")
    assert first.exit_code == 0, first.output
    journal = small_disk / "study.journal"
    shutil.copy(tmp_path / "opt" / "study.journal", journal)    # 11 kB: three pages of the tmpfs
    pages = -(-journal.stat().st_size // 4096)
    (small_disk / "fill").write_bytes(b"x" * (64 * 1024 - (pages + 1) * 4096))   # leaves one page: a trial or two

    full = optimize("--trials", 20, "--out", tmp_path / "opt2", "--storage", journal)
    assert full.exit_code == 2, full.output
    assert "error:" in full.output and "the disk is full" in full.output and "--repair" in full.output
    assert "Traceback" not in full.output and "Should not reach" not in full.output
    torn = journal.read_bytes()
    assert not torn.endswith(b"\n")   # the write that failed left its line cut short

    refused = optimize("--trials", 1, "--out", tmp_path / "opt2", "--storage", journal)
    assert refused.exit_code == 2 and "damaged" in refused.output and "--repair" in refused.output
    assert journal.read_bytes() == torn   # refused, left as it was

    (small_disk / "fill").unlink()
    mended = optimize("--trials", 1, "--out", tmp_path / "opt2", "--storage", journal, "--repair")
    assert mended.exit_code == 0, mended.output
    backup = small_disk / "study.journal.torn-1"
    assert hashlib.md5(backup.read_bytes()).digest() == hashlib.md5(torn).digest()
    assert f"saved as {backup}" in mended.output
    whole = torn[:torn.rfind(b"\n") + 1]
    assert journal.read_bytes().startswith(whole)   # every whole line kept, the study goes on from them
    held = re.search(r"study 'locust': (\d+) trials \(", mended.output)
    assert held and "valid" in mended.output and int(held.group(1)) >= 7, mended.output


def test_repair_keeps_whole_lines_and_the_file_as_it_was(tmp_path):
    path = tmp_path / "study.journal"
    path.write_bytes(b'{"op_code": 0}\n{"op_code": 4}\n{"op_co')
    done = repair(path)
    assert (done.records, done.cut_bytes) == (2, 7)
    assert path.read_bytes() == b'{"op_code": 0}\n{"op_code": 4}\n'
    assert done.backup.read_bytes() == b'{"op_code": 0}\n{"op_code": 4}\n{"op_co'
    again = repair(path)   # a whole journal is left alone
    assert (again.cut_bytes, again.backup) == (0, None) and "nothing to repair" in again.line()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["study.journal", "study.journal.torn-1"]


def test_full_disk_found_behind_optunas_second_failure():
    try:
        try:
            raise OSError(errno.ENOSPC, "No space left on device")
        except OSError:
            raise AssertionError("Should not reach.")   # noqa: B904 - Optuna's, as it raises it
    except AssertionError as exc:
        assert full_disk(exc).errno == errno.ENOSPC
    assert full_disk(AssertionError("other")) is None
    assert full_disk(OSError(errno.EACCES, "denied")) is None
