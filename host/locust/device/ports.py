"""Serial ports: list them with USB ids, mark the likely ESP32, pick one for --port."""

from __future__ import annotations

from dataclasses import dataclass

from serial.tools import list_ports

from ..errors import DeviceError

SIM = "sim"

# (vid, pid or None for any) -> what it is. USB-UART bridges are on other boards too,
# hence "likely": the handshake decides.
ESP32_USB: dict[tuple[int, int | None], str] = {
    (0x303A, None): "Espressif native USB (ESP32-S2/S3/C3/C6)",
    (0x10C4, 0xEA60): "Silicon Labs CP210x (ESP32 DevKit)",
    (0x1A86, 0x7523): "WCH CH340 (ESP32 clone boards)",
    (0x1A86, 0x55D4): "WCH CH9102 (ESP32 DevKit v4)",
    (0x0403, 0x6001): "FTDI FT232R (ESP-Prog)",
    (0x0403, 0x6010): "FTDI FT2232 (ESP-Prog)",
}


@dataclass(frozen=True)
class PortInfo:
    """One serial port as the operating system lists it.

    Attributes
    ----------
    device : str
        The port's path, e.g. ``/dev/ttyUSB0``.
    vid, pid : int or None
        USB vendor and product ids (None for a port that is not USB).
    serial_number : str or None
        The USB serial number, when the device has one.
    description : str
        The operating system's description of the port.
    esp32_hint : str or None
        Why it looks like an ESP32 (the USB bridge it is), None if it does not.
    """

    device: str
    vid: int | None
    pid: int | None
    serial_number: str | None
    description: str
    esp32_hint: str | None     # why it looks like an ESP32, None if it does not

    @property
    def vid_pid(self) -> str:
        """The USB ids as ``VVVV:PPPP`` in hex, or ``-`` when either is unknown."""
        return f"{self.vid:04X}:{self.pid:04X}" if self.vid is not None and self.pid is not None else "-"


def esp32_hint(vid: int | None, pid: int | None) -> str | None:
    """Whether a USB device is a bridge ESP32 boards use.

    Parameters
    ----------
    vid, pid : int or None
        USB vendor and product ids.

    Returns
    -------
    str or None
        The bridge's name (from ``ESP32_USB``), None when the ids are not one of them.
    """
    if vid is None:
        return None
    return ESP32_USB.get((vid, pid)) or ESP32_USB.get((vid, None))


def list_serial_ports() -> list[PortInfo]:
    """Every serial port on this machine, sorted by path.

    Returns
    -------
    list of PortInfo
        Each port with its USB ids and whether it looks like an ESP32.
    """
    out = []
    for p in sorted(list_ports.comports(), key=lambda p: p.device):
        out.append(PortInfo(p.device, p.vid, p.pid, p.serial_number, p.description or "",
                            esp32_hint(p.vid, p.pid)))
    return out


def autodetect(ports: list[PortInfo]) -> str:
    """The one port that looks like an ESP32.

    Parameters
    ----------
    ports : list of PortInfo
        From :func:`list_serial_ports`.

    Returns
    -------
    str
        The device path of the only likely ESP32.

    Raises
    ------
    DeviceError
        No port or more than one port looks like an ESP32.
    """
    likely = [p for p in ports if p.esp32_hint]
    if len(likely) == 1:
        return likely[0].device
    if not likely:
        raise DeviceError("no ESP32 found on any serial port",
                          "plug the robot in and check `locust ports`, pass --port /dev/ttyUSB0, "
                          "or use --port sim for the virtual robot")
    names = ", ".join(p.device for p in likely)
    raise DeviceError(f"several serial ports look like an ESP32: {names}", "choose one with --port")
