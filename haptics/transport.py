"""Byte transports the drivers talk through: a serial port (pyserial) or a HID device (hidapi).

Drivers never open ports themselves; they are handed a transport, so the same driver runs on a
real port, on a pseudo-terminal with a simulator behind it, or on pyserial's `loop://`.
Every I/O error becomes `DeviceDisconnected`, so the force loop has one thing to catch.
"""
from __future__ import annotations

import os

from feelflow.haptics.errors import DeviceDisconnected, DeviceError
from feelflow.haptics.permissions import hid_fix, is_permission_error, serial_fix


class SerialTransport:
    """A serial port opened through pyserial (`serial.serial_for_url`, so `loop://` works too)."""

    kind = "serial"

    def __init__(self, port: str, baudrate: int = 115200, port_object=None):
        import serial  # pyserial

        self.name = port
        self._serial_exc = serial.SerialException
        self._pending = bytearray()
        if port_object is not None:
            self._port = port_object
        else:
            try:
                self._port = serial.serial_for_url(port, baudrate=baudrate, timeout=0, write_timeout=0.5)
            except (serial.SerialException, OSError, ValueError) as exc:
                if is_permission_error(exc):
                    raise DeviceError(serial_fix(port)) from None
                raise DeviceError(f"cannot open serial port {port}: {exc}") from None
        # On POSIX ports, write to the (non-blocking) descriptor ourselves: pyserial's write
        # with a timeout raises 'Write timeout' AFTER writing when the calling thread was merely
        # descheduled for longer than the timeout, and with timeout 0 it spins on EAGAIN.
        try:
            self._fd = self._port.fileno() if hasattr(self._port, "fileno") else None
        except Exception:  # loop:// and Windows ports have no usable descriptor
            self._fd = None

    #: bytes the device may leave unread before it counts as hung (about 0.3 s of commands)
    MAX_PENDING = 4096

    def write(self, data: bytes) -> None:
        """Queue and send without blocking; what the port cannot take now goes out next time."""
        if self._fd is None:
            try:
                self._port.write(data)
            except (self._serial_exc, OSError, TypeError, AttributeError) as exc:
                raise DeviceDisconnected(f"serial port {self.name} lost: {exc}") from None
            return
        self._pending += data
        try:
            n = os.write(self._fd, self._pending)
        except BlockingIOError:
            n = 0
        except (OSError, TypeError, ValueError) as exc:
            raise DeviceDisconnected(f"serial port {self.name} lost: {exc}") from None
        del self._pending[:n]
        if len(self._pending) > self.MAX_PENDING:
            raise DeviceDisconnected(f"serial port {self.name}: the device stopped reading")

    def read_available(self) -> bytes:
        """Whatever bytes have arrived, without waiting (b'' if none)."""
        try:
            n = self._port.in_waiting
            return self._port.read(n) if n else b""
        except (self._serial_exc, OSError, TypeError, AttributeError) as exc:
            raise DeviceDisconnected(f"serial port {self.name} lost: {exc}") from None

    def reset_input(self) -> None:
        try:
            self._port.reset_input_buffer()
        except (self._serial_exc, OSError, AttributeError):
            pass

    def close(self) -> None:
        try:
            self._port.close()
        except (self._serial_exc, OSError):
            pass


class HidTransport:
    """A HID device behind hidapi's `hid.device` interface (or anything with the same methods:
    the simulators in `feelflow.haptics.sim` provide exactly the methods used here)."""

    kind = "hid"

    def __init__(self, vid: int | None = None, pid: int | None = None, path: bytes | None = None,
                 device=None, name: str | None = None):
        self.name = name or (f"hid://{vid:04x}:{pid:04x}" if vid is not None else "hid")
        if device is None:
            import hid

            device = hid.device()
            try:
                if path is not None:
                    device.open_path(path)
                else:
                    device.open(vid, pid)
            except (OSError, IOError, ValueError) as exc:
                nodes = [path] if path is not None else [d.get("path") for d in hid.enumerate(vid, pid)]
                fix = hid_fix([p.decode(errors="replace") if isinstance(p, bytes) else p for p in nodes if p])
                if fix is not None:
                    raise DeviceError(f"cannot open HID device {self.name}: {fix}") from None
                raise DeviceError(f"cannot open HID device {self.name}: {exc} "
                                  "(is it plugged in, and may this user read /dev/hidraw*?)") from None
        self._dev = device
        try:
            self._dev.set_nonblocking(1)
        except (OSError, ValueError) as exc:
            raise DeviceDisconnected(f"HID device {self.name} lost: {exc}") from None

    def read_report(self, size: int = 64) -> bytes:
        """One input report (report id first when the device uses ids), b'' if none waiting."""
        try:
            data = self._dev.read(size)
        except (OSError, IOError, ValueError) as exc:
            raise DeviceDisconnected(f"HID device {self.name} lost: {exc}") from None
        return bytes(data) if data else b""

    def write_report(self, data: bytes) -> None:
        """Send an output report; data[0] is the report id (0 when the device uses none)."""
        try:
            n = self._dev.write(bytes(data))
        except (OSError, IOError, ValueError) as exc:
            raise DeviceDisconnected(f"HID device {self.name} lost: {exc}") from None
        if n is not None and n < 0:
            raise DeviceDisconnected(f"HID device {self.name} lost: write failed")

    def get_feature_report(self, report_id: int, size: int) -> bytes:
        try:
            return bytes(self._dev.get_feature_report(report_id, size))
        except (OSError, IOError, ValueError) as exc:
            raise DeviceDisconnected(f"HID device {self.name} lost: {exc}") from None

    def close(self) -> None:
        try:
            self._dev.close()
        except (OSError, IOError, ValueError):
            pass
