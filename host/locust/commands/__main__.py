"""``python -m locust.commands``: the ``locust`` command."""

from . import main

main()
