"""Before installing: refuse an environment that holds the load-testing tool "locust".

It and this toolkit (distribution locust-hopper) install the same package and command name,
`locust`; installing one over the other would silently break it. An earlier install of this
toolkit under the old distribution name "locust" is removed instead.
"""

from __future__ import annotations

import importlib.metadata as md
import subprocess
import sys

OUR_SUMMARY = "Firmware-plus-host toolkit for a foldable four-bar hopping robot"


def main() -> int:
    """1 (saying why) when the load-testing tool "locust" is installed here; 0 otherwise, after
    removing an earlier install of this toolkit under that name."""
    venv = sys.argv[1] if len(sys.argv) > 1 else "this environment"
    try:
        meta = md.metadata("locust")
    except md.PackageNotFoundError:
        return 0
    if (meta.get("Summary") or "").startswith(OUR_SUMMARY):
        subprocess.run([sys.executable, "-m", "pip", "uninstall", "-q", "-y", "locust"], check=True)
        return 0
    print(f"error: the load-testing tool 'locust' {meta.get('Version', '?')} is installed in {venv}; "
          "locust-hopper installs the same package and command name and would shadow it", file=sys.stderr)
    print(f"  hint: use another environment (make VENV=.venv-hopper ...), or remove it: "
          f"{sys.executable} -m pip uninstall locust", file=sys.stderr)
    return 1


if __name__ == "__main__":
    sys.exit(main())
