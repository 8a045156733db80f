"""Every shell example in README.md and docs/*.md runs as a reader types it, and prints the
figures the page shows beside it.

What is an example, and what the test does with it:

- A fenced block marked ``sh``, ``bash``, ``shell`` or ``console`` is an example: the test runs
  each of its commands in order, in one fresh working folder of its own (outside the
  checkout), and each example is one test case named after its page and line.
- In a ``console`` block a command starts with ``$ `` (a line ending in ``\\`` goes on on the
  next); the lines under it, up to the next ``$ ``, are what it prints, trimmed: every line
  shown must be among the lines it prints (stdout and stderr together, as on a terminal), in
  that order, its words the same and each number equal to the digits shown (``114.7`` for a
  printed ``114.73``). ``...`` stands for text left out: a line of its own for lines, or part
  of a line. A command whose shown output has an ``error:`` line must exit with 2 (a refusal);
  every other command must exit with 0.
- A table right under a console block (nothing but blank lines between) holds figures of that
  block: each number in its body, but for the first column (which names the row), must be one
  the block's commands printed, to the digits shown.
- A ``sh`` block shows no output; each command must exit with 0.
- A ``text`` block is not run: a synopsis with placeholders (``locust calibrate beam TRACKS
  --mass-kg M [...]``), a printout, a diagram, or steps that need what a test cannot give (a
  camera, the robot on the desk). So that an example cannot hide there, a ``text`` block that
  holds a locust command has a placeholder (a word in capitals, ``[``, ``<`` or ``...``) or a
  comment line saying what it needs, and every fence on the pages says what it holds.

The working folder is a copy of the checkout's ``calibration/`` (its robot.toml and the
bundled recordings, at the paths the docs use) and ``data/``, with the public reference data
at ``../shared/data`` where this checkout has it beside it (examples that name it are skipped
where it is not). ``cd DIR`` moves the example's later commands into DIR. The virtual robot's
flash lives in the test's own folder (``LOCUST_VIRTUAL_DIR``), flashed beforehand unless the
example flashes it itself; a board command with no ``--port`` (docs/hardware.md: steps on a
real board) runs on the virtual robot, ``--port sim`` added. The reader's own recordings a
page names (``step.csv``, ``trials.csv``, ``hop.mp4``) are stood in for by one of the same
kind (``STAND_INS``); an option that needs a program the machine lacks (``--cad-check``:
LibreCAD) skips its example, saying so. Install steps (``make``, ``pip``,
``python3 -m venv``) are not run here: ``make test`` is this run, and tests/test_wheel.py
installs the wheel. Examples that take over about 20 s on a 2-core machine are slow
(``SLOW`` says which), run by ``make test-all``.
"""

from __future__ import annotations

import math
import os
import re
import shlex
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
RUN = {"sh", "bash", "shell", "console"}
KNOWN = RUN | {"text", "python", "toml", "json", "csv", "xml"}
FENCE = re.compile(r"^(?P<indent>\s*)```(?P<lang>\S*)\s*$")
NUMBER = r"\d+(?:\.\d+)?(?:[eE][-+]?\d+)?"
LOCUST_COMMANDS = ("calibrate", "config", "demo", "fab", "flash", "hop", "measure", "optimize", "params", "ports",
                   "pose", "repl", "report", "sim", "sweep", "track", "virtual")
BOARD_COMMANDS = {"flash", "hop", "pose", "config", "repl"}
OUTPUT_OPTIONS = {"--video", "--still", "--still-push", "--out", "--trk", "--write", "--plot", "--pwm-log",
                  "--push-clip", "--push-clip-held", "--csv"}
# the reader's own recordings a page names, each stood in for by one of the same kind:
# name -> (what stands in, where it is, made by rendering (slow))
STAND_INS = {
    "step.csv": ("the AA-battery swing the servo protocol films (../shared/data)",
                 SHARED / "data" / "servo" / "sg90_aa_battery_step.csv", False),
    "trials.csv": ("ramp trials: the bundled synthetic ones",
                   ROOT / "calibration" / "recordings" / "synthetic_ramp.csv", False),
    "hop.mp4": ("a filmed hop: one cycle of the virtual seed robot, fixed camera, with its sidecars", None, True),
}
# what an option needs of the machine, skipped without it
NEEDS = {"--cad-check": "librecad"}
SET_UP = ("make", "pip", "python3 -m venv")     # install steps: `make test` is this run; tests/test_wheel.py installs
COMMAND_TIMEOUT_S = 1500


def _option(argv: list[str], name: str) -> list[str]:
    return [argv[k + 1] for k, a in enumerate(argv[:-1]) if a == name]


def _slow_samples(argv: list[str]) -> bool:
    return any(int(n) >= 32 for n in _option(argv, "--samples"))


def _big_sweep(argv: list[str]) -> bool:
    designs = math.prod(int(v.rsplit(":", 1)[1]) for v in _option(argv, "--vary") if v.count(":") == 2)
    return argv[:1] == ["sweep"] and designs * max([1, *map(int, _option(argv, "--samples"))]) >= 30


def _big_study(argv: list[str]) -> bool:
    trials = math.prod(int(n) for n in _option(argv, "--trials") or ["50"])     # (optimize's default trials)
    return argv[:1] == ["optimize"] and trials * max([1, *map(int, _option(argv, "--robust"))]) >= 30


# (why it is slow, is it): each over about 20 s on a busy 2-core machine
def _slow_explain(argv: list[str]) -> bool:
    """``--explain`` runs some 300 simulations: more than one cycle each is slow."""
    if "--explain" not in argv:
        return False
    cycles = argv[argv.index("--cycles") + 1] if "--cycles" in argv[:-1] else None
    return cycles is None or int(cycles) > 1


SLOW = (
    ("the whole toolkit, minutes", lambda argv: argv[:1] == ["demo"]),
    ("an optimisation of 30 trials or more", _big_study),
    ("a hop fit", lambda argv: argv[:2] == ["calibrate", "hop"]),
    ("a servo fit", lambda argv: argv[:2] == ["calibrate", "servo"]),
    ("32 or more draws", _slow_samples),
    ("a sweep of 30 designs or more", _big_sweep),
    ("video rendered", lambda argv: "--video" in argv or "--side-by-side" in argv or "--push-clip" in argv),
    ("an explanation of more than one cycle", lambda argv: _slow_explain(argv)),
)


@dataclass
class Command:
    """One command of an example: the line it starts on, its words, and the output shown."""

    line: int
    text: str
    shown: list[str] = field(default_factory=list)


@dataclass
class Example:
    """A fenced block that runs: its page, the line of its fence, its commands, and the table
    of figures under it (rows of cells), if any."""

    page: Path
    line: int
    lang: str
    commands: list[Command]
    table: list[tuple[int, str]] = field(default_factory=list)

    @property
    def name(self) -> str:
        return f"{self.page.relative_to(ROOT)}:{self.line}"


def fences(page: Path):
    """(fence line, language, [(line, text)], line after the closing fence) for each fenced block."""
    lines = page.read_text(encoding="utf-8").split("\n")
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        indent, j = len(m.group("indent")), i + 1
        while not lines[j].strip().startswith("```"):
            j += 1
        body = [(k + 1, lines[k][indent:] if lines[k][:indent].strip() == "" else lines[k].lstrip())
                for k in range(i + 1, j)]
        yield i + 1, m.group("lang"), body, j + 1
        i = j + 1


def strip_comment(text: str) -> str:
    """The command without its shell comment (a ``#`` starting a word, outside quotes)."""
    quote, prev = None, " "
    for k, ch in enumerate(text):
        if quote:
            quote = None if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch == "#" and prev.isspace():
            return text[:k].rstrip()
        prev = ch
    return text.rstrip()


def parse_commands(lang: str, body: list[tuple[int, str]]) -> list[Command]:
    commands: list[Command] = []
    going_on = False
    for line, text in body:
        if going_on:
            commands[-1].text += " " + strip_comment(text).removesuffix("\\").strip()
            going_on = strip_comment(text).endswith("\\")
            continue
        if lang == "console":
            if text.startswith("$ "):
                commands.append(Command(line, strip_comment(text[2:]).removesuffix("\\").strip()))
                going_on = strip_comment(text).endswith("\\")
            elif commands:
                commands[-1].shown.append(text.rstrip())
            elif text.strip():
                raise AssertionError(f"line {line}: output before the first `$ ` command")
        elif text.strip() and not text.lstrip().startswith("#"):
            commands.append(Command(line, strip_comment(text).removesuffix("\\").strip()))
            going_on = strip_comment(text).endswith("\\")
    return commands


def table_after(lines: list[str], after: int) -> list[tuple[int, str]]:
    """The body rows of a markdown table that starts right after line ``after`` (1-based,
    blank lines between allowed), as (line, text); [] where none does."""
    k = after
    while k < len(lines) and not lines[k].strip():
        k += 1
    rows = []
    while k < len(lines) and lines[k].lstrip().startswith("|"):
        rows.append((k + 1, lines[k]))
        k += 1
    return rows[2:]     # less the header and its rule


def examples() -> list[Example]:
    found = []
    for page in PAGES:
        lines = page.read_text(encoding="utf-8").split("\n")
        for line, lang, body, end in fences(page):
            if lang in RUN:
                table = table_after(lines, end) if lang == "console" else []
                found.append(Example(page, line, lang, parse_commands(lang, body), table))
    return found


EXAMPLES = examples()


def argv_of(text: str) -> list[str]:
    return shlex.split(text)


def is_set_up(text: str) -> bool:
    return any(text == s or text.startswith(s + " ") for s in SET_UP)


def slow_reason(example: Example) -> str | None:
    for command in example.commands:
        argv = argv_of(command.text)
        if argv[:1] == ["locust"]:
            for why, is_slow in SLOW:
                if is_slow(argv[1:]):
                    return why
    for name in stand_ins_of(example):
        if STAND_INS[name][2]:
            return STAND_INS[name][0]
    return None


def mentions(argv: list[str], name: str) -> int | None:
    """Where ``name`` first appears in ``argv`` (as a word, or a path in a quoted program)."""
    word = re.compile(r"(?<![\w/.-])" + re.escape(name) + r"(?![\w.])")
    return next((k for k, a in enumerate(argv) if word.search(a)), None)


def stand_ins_of(example: Example) -> list[str]:
    """The stand-ins an example reads: each named where its first mention is not an output."""
    wanted = []
    for name in STAND_INS:
        for command in example.commands:
            argv = argv_of(command.text)
            k = mentions(argv, name)
            if k is not None:
                if not (k > 0 and argv[k - 1] in OUTPUT_OPTIONS):
                    wanted.append(name)
                break
    return wanted


def cases():
    for ex in EXAMPLES:
        marks = [pytest.mark.slow, pytest.mark.timeout(3 * 3600)] if slow_reason(ex) else []
        yield pytest.param(ex, id=ex.name, marks=marks)


# -- what a shown line matches -------------------------------------------------------------

def shown_pattern(shown: str) -> tuple[re.Pattern, list[str]]:
    """A regex for the printed line a shown line stands for, and the numbers it shows.

    Words and signs must be the same, whitespace may differ in width, ``...`` is any text and
    each number is captured, to be compared at the digits shown."""
    parts, numbers = [], []
    for piece in re.split(r"(\.\.\.|…|" + NUMBER + r"|\s+)", shown.strip()):
        if not piece:
            continue
        if piece in ("...", "…"):
            parts.append(".*?")
        elif re.fullmatch(NUMBER, piece):
            parts.append(f"({NUMBER})")
            numbers.append(piece)
        elif piece.isspace():
            parts.append(r"\s+")
        else:
            parts.append(re.escape(piece))
    return re.compile("".join(parts)), numbers


def to_the_digits(shown: str, printed: str) -> bool:
    """``printed`` is ``shown`` to the digits shown: 114.7 for 114.73, 0.6029 for 0.60291."""
    mantissa, _, exponent = shown.lower().partition("e")
    decimals = len(mantissa.partition(".")[2])
    step = 10.0 ** (int(exponent or 0) - decimals)
    return math.isclose(abs(float(printed) - float(shown)), 0, abs_tol=step / 2 * (1 + 1e-9))


def line_matches(shown: str, printed: str) -> bool:
    pattern, numbers = shown_pattern(shown)
    m = pattern.fullmatch(printed.strip())
    return bool(m) and all(to_the_digits(s, p) for s, p in zip(numbers, m.groups()))


def check_shown(shown: list[str], printed: list[str]) -> str | None:
    """None when every shown line is among the printed ones, in order; else what is missing."""
    at = 0
    for s in shown:
        if not s.strip() or s.strip() in ("...", "…"):
            continue
        for k in range(at, len(printed)):
            if line_matches(s, printed[k]):
                at = k + 1
                break
        else:
            return s
    return None


def numbers_in(text: str) -> list[str]:
    return re.findall(NUMBER, text)


# -- the working folder ----------------------------------------------------------------------

@pytest.fixture(scope="session")
def flashed(tmp_path_factory) -> Path:
    """A virtual robot flashed once a session; each example gets its own copy."""
    home = tmp_path_factory.mktemp("virtual")
    done = subprocess.run([sys.executable, "-m", "locust.commands", "flash", "--port", "sim"],
                          env=environment(home), capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    return home


def environment(virtual: Path) -> dict[str, str]:
    path = os.pathsep.join([str(ROOT / "host"), *filter(None, [os.environ.get("PYTHONPATH")])])
    return {**os.environ, "PYTHONPATH": path, "LOCUST_VIRTUAL_DIR": str(virtual), "PYTHONUNBUFFERED": "1",
            "MPLBACKEND": "Agg"}


@pytest.fixture(scope="session")
def filmed_hop(tmp_path_factory) -> list[Path]:
    """hop.mp4 with its hop.camera.json and hop.truth.csv: the virtual seed robot, rendered once."""
    folder = tmp_path_factory.mktemp("filmed")
    done = subprocess.run([sys.executable, "-m", "locust.commands", "sim", "--preset", "seed", "--cycles", "1",
                           "--video", "hop.mp4", "--camera", "fixed"], cwd=folder, env=environment(folder),
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr
    return sorted(folder.glob("hop.*"))


def place_stand_ins(example: Example, work: Path, request) -> None:
    for name in stand_ins_of(example):
        what, source, rendered = STAND_INS[name]
        files = request.getfixturevalue("filmed_hop") if rendered else [source]
        if not all(f.is_file() for f in files):
            pytest.skip(f"{name} stands in for the reader's own ({what}): {source} not found")
        for f in files:
            shutil.copy(f, work / (name if not rendered else f.name))


def working_folder(tmp: Path) -> Path:
    """A folder like the checkout's root, for the docs' relative paths, with ../shared beside it."""
    work = tmp / "work"
    work.mkdir()
    for name in ("calibration", "data"):
        shutil.copytree(ROOT / name, work / name)
    if SHARED.is_dir():
        (tmp / "shared").symlink_to(SHARED, target_is_directory=True)
    return work


def board_argv(argv: list[str]) -> list[str]:
    if argv[:1] and argv[0] in BOARD_COMMANDS and "--port" not in argv:
        return [*argv, "--port", "sim"]
    return argv


@pytest.mark.parametrize("example", list(cases()))
def test_the_example_runs_and_prints_the_figures_shown(example: Example, tmp_path, request):
    runnable = [c for c in example.commands if not is_set_up(c.text)]
    if not runnable:
        pytest.skip("install steps only: " + "; ".join(c.text for c in example.commands))
    if any("../shared/" in c.text for c in runnable) and not SHARED.is_dir():
        pytest.skip(f"reference data not found at {SHARED}")
    for option, program in NEEDS.items():
        if any(option in argv_of(c.text) for c in runnable) and shutil.which(program) is None:
            pytest.skip(f"{option} needs {program}, not installed here")
    cwd = working_folder(tmp_path)
    place_stand_ins(example, cwd, request)
    virtual = tmp_path / "virtual"
    words = [argv_of(c.text) for c in runnable]
    board = [w[1] for w in words if w[:1] == ["locust"] and len(w) > 1 and w[1] in BOARD_COMMANDS]
    if board and board[0] != "flash":
        shutil.copytree(request.getfixturevalue("flashed"), virtual)
    env = environment(virtual)
    printed_all: list[str] = []
    for command, argv in zip(runnable, words):
        where = f"{example.page.relative_to(ROOT)}:{command.line}: {command.text}"
        if argv[0] == "cd":
            cwd = (cwd / argv[1]).resolve()
            assert cwd.is_dir(), f"{where}: no such folder"
            continue
        if argv[0] == "locust":
            run = [sys.executable, "-m", "locust.commands", *board_argv(argv[1:])]
        elif argv[0] in ("python", "python3"):
            run = [sys.executable, *argv[1:]]
        else:
            raise AssertionError(f"{where}: the test runs locust and python commands, not {argv[0]!r}")
        t0 = time.monotonic()
        done = subprocess.run(run, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                              timeout=COMMAND_TIMEOUT_S)
        printed = done.stdout.splitlines()
        printed_all += printed
        tail = "\n".join(printed[-60:])
        refused = any(s.lstrip().startswith("error:") for s in command.shown)
        expected = 2 if refused else 0
        assert done.returncode == expected, (f"{where}\nexited {done.returncode}, not {expected}, after "
                                             f"{time.monotonic() - t0:.1f} s; it printed:\n{tail}")
        missing = check_shown(command.shown, printed)
        assert missing is None, f"{where}\nshown but not printed: {missing!r}\nit printed:\n{tail}"
    printed_numbers = [n for line in printed_all for n in numbers_in(line)]
    for line, row in example.table:
        for cell in row.strip().strip("|").split("|")[1:]:      # the first column names the row
            for number in numbers_in(cell):
                assert any(to_the_digits(number, p) for p in printed_numbers), (
                    f"{example.page.relative_to(ROOT)}:{line}: {number} in the table under the example is not "
                    f"a figure its commands printed")


# -- the convention itself -------------------------------------------------------------------

PLACEHOLDER = re.compile(r"\b[A-Z][A-Z0-9_]*\b|\[|<|\.\.\.")


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_block_says_what_it_holds_and_no_example_hides_in_a_text_block(page):
    lines = page.read_text(encoding="utf-8").split("\n")
    fenced = {k for line, _, body, end in fences(page) for k in range(line, end + 1)}
    for k, text in enumerate(lines, 1):
        words = text.split()
        indented = k not in fenced and text.startswith("    ") and k > 1 and not lines[k - 2].strip()
        assert not (indented and words[:1] == ["locust"] and words[1:2] and words[1] in LOCUST_COMMANDS), (
            f"{page.name}:{k}: an indented code block: fence it, as sh or console (an example) or text")
    for line, lang, body, _ in fences(page):
        assert lang in KNOWN, f"{page.name}:{line}: a fence marked {lang!r}: mark it sh or console (an example), " \
                              f"or text (a synopsis, a printout, a diagram)"
        if lang == "text":
            commands = [(k, s) for k, s in body
                        if s.split()[:1] == ["locust"] and len(s.split()) > 1 and s.split()[1] in LOCUST_COMMANDS]
            says_why = any(PLACEHOLDER.search(s) or s.lstrip().startswith("#") for _, s in body)
            assert not commands or says_why, (
                f"{page.name}:{commands[0][0] if commands else line}: `{commands[0][1].strip() if commands else ''}` "
                f"in a text block with no placeholder and no comment saying what it needs: an example to run "
                f"belongs in a sh or console block")


def test_a_shown_figure_matches_only_to_the_digits_shown():
    """The matching rule itself, on known lines: a figure that moved in its last digit shown
    fails, one printed to more digits than shown passes, and words must agree."""
    printed = "  total distance -72.46 mm; highest nose 114.91 mm above the floor"
    assert line_matches("total distance -72.46 mm; highest nose 114.91 mm above the floor", printed)
    assert line_matches("total distance -72.5 mm; highest nose 115 mm above the floor", printed)
    assert line_matches("total distance -72.5 mm; ...", printed)
    assert not line_matches("total distance -72.4 mm; ...", printed)
    assert not line_matches("total distance 72.46 mm; ...", printed)       # the sign is a word
    assert not line_matches("total travel -72.46 mm; ...", printed)
    assert line_matches('"distance_m": 0.6029,', '  "distance_m": 0.6029134479287294,')
    assert not line_matches('"distance_m": 0.6030,', '  "distance_m": 0.6029134479287294,')
    assert line_matches("4.65e-4", "4.6512e-4") and not line_matches("4.66e-4", "4.6512e-4")
    assert check_shown(["a 1", "...", "c 3"], ["a 1", "b 2", "c 3.04"]) is None
    assert check_shown(["c 3", "a 1"], ["a 1", "b 2", "c 3"]) == "a 1"      # in order
