"""The project's home is declared once, pyproject.toml's [project.urls] Repository; every place
that names it agrees: README's Colab badge and link and its pip line, the notebook's Colab link
(in its first cell) and its install cell. A move is one edit in pyproject.toml, and this test
then names each file still pointing at the old home."""

from __future__ import annotations

import json
import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOK = "docs/python-api.ipynb"
BRANCH = "main"     # the branch Colab opens the notebook from

COLAB_LINK = re.compile(r"https://colab\.research\.google\.com/github/([^/\s)]+)/([^/\s)]+)/blob/([^/\s)]+)/([^\s)]+)")
GIT_INSTALL = re.compile(r"git\+(https://[^\s\"'}]+)|LOCUST_GIT_URL = \"(https://[^\"]+)\"")


def repository() -> str:
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["urls"]["Repository"]


def notebook_cells() -> list[str]:
    return ["".join(c["source"]) for c in json.loads((ROOT / NOTEBOOK).read_text(encoding="utf-8"))["cells"]]


def colab_links(text: str) -> list[tuple[str, str]]:
    """(repository URL, branch/path) of each Open-in-Colab link in ``text``."""
    return [(f"https://github.com/{owner}/{repo}", f"{branch}/{path}")
            for owner, repo, branch, path in COLAB_LINK.findall(text)]


def git_installs(text: str) -> list[str]:
    return [a or b for a, b in GIT_INSTALL.findall(text)]


def test_pyproject_declares_a_github_repository():
    assert re.fullmatch(r"https://github\.com/[\w.-]+/[\w.-]+", repository()), repository()


def test_readme_and_notebook_name_the_declared_repository():
    home, wrong = repository(), []
    texts = {"README.md": (ROOT / "README.md").read_text(encoding="utf-8"), NOTEBOOK: "\n".join(notebook_cells())}
    texts |= {f"docs/{p.name}": p.read_text(encoding="utf-8") for p in sorted((ROOT / "docs").glob("*.md"))}
    for name, text in texts.items():
        wrong += [(name, url, where) for url, where in colab_links(text)
                  if url != home or where != f"{BRANCH}/{NOTEBOOK}"]
        wrong += [(name, url) for url in git_installs(text) if url != home]
    assert not wrong, f"pyproject.toml's Repository is {home}; these name another: {wrong}"


def test_readme_has_the_colab_link_near_the_top_and_a_pip_line():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    top = readme.split("\n## ", 1)[0]      # before the first section
    assert colab_links(top) and "docs/python-api.ipynb" in top
    assert git_installs(top) == [repository()]
    python_api = readme.split("## Python API", 1)[1].split("\n## ", 1)[0]
    assert colab_links(python_api)        # beside the notebook's mention there too


def test_notebook_opens_with_its_colab_link_and_installs_from_the_repository():
    cells = notebook_cells()
    assert colab_links(cells[0]) == [(repository(), f"{BRANCH}/{NOTEBOOK}")]
    install = next(c for c in cells if "google.colab" in c)
    assert git_installs(install) == [repository()]
    assert "input(" not in install and "OWNER" not in install      # nothing to type by hand
