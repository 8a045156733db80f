"""locust: firmware-plus-host toolkit for a foldable four-bar hopping robot."""

__version__ = "0.1.0"
