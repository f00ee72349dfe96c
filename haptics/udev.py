"""The udev rule that lets the logged-in user (and the dialout group) open every device FeelFlow
has a driver for: `python -m feelflow.haptics.udev` prints it; installer/install-desktop.sh
--udev writes it to RULES_FILE (feelflow.haptics.permissions)."""
from __future__ import annotations

import sys

from feelflow.haptics.permissions import SERIAL_GROUP
from feelflow.haptics.protocols import diyhid, spacemouse
from feelflow.haptics.registry import SERIAL_IDS


def udev_rules() -> str:
    """The udev rule text for every device FeelFlow has a driver for (registry ids)."""
    lines = ["# FeelFlow's haptic devices: the logged-in user (uaccess) and the dialout group may",
             "# open them. Written by installer/install-desktop.sh --udev; --uninstall --udev removes it."]
    hid = sorted(set(spacemouse.PRODUCTS) | {(diyhid.DEFAULT_VID, diyhid.DEFAULT_PID)})
    for vid, pid in hid:
        lines.append(f'KERNEL=="hidraw*", ATTRS{{idVendor}}=="{vid:04x}", ATTRS{{idProduct}}=="{pid:04x}", '
                     'MODE="0660", TAG+="uaccess"')
    for vid, pid in sorted(SERIAL_IDS):
        lines.append(f'SUBSYSTEM=="tty", ATTRS{{idVendor}}=="{vid:04x}", ATTRS{{idProduct}}=="{pid:04x}", '
                     f'MODE="0660", GROUP="{SERIAL_GROUP}", TAG+="uaccess"')
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.stdout.write(udev_rules())
