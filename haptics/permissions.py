"""Device permissions on Linux: the exact fix when this user may not open a haptic device.

A serial port (/dev/ttyACM*, /dev/ttyUSB*) belongs to a group (`dialout` on Debian, Ubuntu and
Fedora): its members may open it. A HID device (/dev/hidraw*) is root's alone unless a udev
rule opens it up: feelflow.haptics.udev writes FeelFlow's rule for every device it has a driver
for (`python -m feelflow.haptics.udev` prints it; `installer/install-desktop.sh --udev` installs
it as RULES_FILE).
"""
from __future__ import annotations

import errno
import os
import stat

RULES_FILE = "70-feelflow.rules"
SERIAL_GROUP = "dialout"
UDEV_FIX = ("install FeelFlow's udev rule (sudo installer/install-desktop.sh --udev, "
            "then unplug and replug the device)")


def is_permission_error(exc: BaseException) -> bool:
    """An open refused for want of permission (pyserial keeps the errno of the failed open)."""
    return isinstance(exc, PermissionError) or getattr(exc, "errno", None) in (errno.EACCES, errno.EPERM)


def _group_of(path: str) -> tuple[str | None, int]:
    try:
        st = os.stat(path)
    except OSError:
        return None, 0
    try:
        import grp   # POSIX only: this module is imported on Windows too

        name = grp.getgrgid(st.st_gid).gr_name
    except (ImportError, KeyError):
        name = str(st.st_gid)
    return name, stat.S_IMODE(st.st_mode)


def serial_fix(port: str) -> str:
    """What to do when `port` may not be opened: join its group, or (a node its group cannot
    open either) install the udev rule and join `dialout`."""
    group, mode = _group_of(port)
    if group is not None and group != "root" and mode & 0o060 == 0o060:
        return (f"no permission to open {port}: add this user to the '{group}' group "
                f"(sudo usermod -aG {group} $USER), then log out and in again")
    return (f"no permission to open {port} (mode {mode:03o}, group {group or '?'}): {UDEV_FIX}, "
            f"and add this user to the '{SERIAL_GROUP}' group (sudo usermod -aG {SERIAL_GROUP} $USER), "
            "then log out and in again")


def hid_fix(nodes: list[str]) -> str | None:
    """The fix when hidapi could not open a device at these nodes (hidapi's Linux paths are
    /dev/hidraw*): None where none of them is refused to this user."""
    denied = [n for n in nodes if os.path.exists(n) and not os.access(n, os.R_OK | os.W_OK)]
    if not denied:
        return None
    return f"no permission to use {', '.join(denied)}: {UDEV_FIX}"
