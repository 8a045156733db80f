# The firmware files run on the ESP32 as top-level modules (main.py, protocol.py, ...).
# This file only lets the host import them as ``locust.firmware``; it is not flashed.
