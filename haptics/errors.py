"""Errors the haptics package raises (one line, meant for the user)."""


class DeviceError(Exception):
    """A device could not be opened or spoke nonsense it could not recover from."""


class DeviceDisconnected(DeviceError):
    """The device went away (cable pulled, port closed, simulator stopped)."""


class BadDeviceURL(DeviceError, ValueError):
    """A device URL that names no transport or driver we know."""
