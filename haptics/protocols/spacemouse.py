"""3Dconnexion SpaceMouse input reports (what the device sends; it takes no force).

Report 1: translation x, y, z as int16 little-endian (7 bytes with the id); newer models
(SpaceMouse Wireless/Pro/Compact family) send report 1 with translation AND rotation (13 bytes).
Report 2: rotation rx, ry, rz int16 (7 bytes). Report 3: buttons, a bit mask (bit 0 = button 1).
Deflections reach about +-350 counts at full push. Axes as the device reports them: x right,
y towards the user, z down (docs/guide/haptic-devices.md cites where this layout was read).
"""
from __future__ import annotations

import struct
from dataclasses import dataclass

VENDORS = (0x046D, 0x256F)  # Logitech (older 3Dconnexion), 3Dconnexion
#: (vendor, product) -> model name, the ones whose report layout is as above
PRODUCTS = {
    (0x046D, 0xC626): "SpaceNavigator",
    (0x046D, 0xC627): "SpaceExplorer",
    (0x046D, 0xC628): "SpaceNavigator for Notebooks",
    (0x046D, 0xC62B): "SpaceMouse Pro",
    (0x256F, 0xC62E): "SpaceMouse Wireless (cable)",
    (0x256F, 0xC62F): "SpaceMouse Wireless (receiver)",
    (0x256F, 0xC631): "SpaceMouse Pro Wireless (cable)",
    (0x256F, 0xC632): "SpaceMouse Pro Wireless (receiver)",
    (0x256F, 0xC635): "SpaceMouse Compact",
    (0x256F, 0xC652): "3Dconnexion Universal Receiver",
}
FULL_SCALE = 350.0


@dataclass(frozen=True)
class Motion:
    """Decoded report content; fields not carried by this report are None."""

    translation: tuple[int, int, int] | None = None
    rotation: tuple[int, int, int] | None = None
    buttons: int | None = None


def decode_report(report: bytes) -> Motion | None:
    """One input report (id first) -> Motion, or None if it is unknown or truncated."""
    if not report:
        return None
    rid = report[0]
    if rid == 1 and len(report) >= 13:
        v = struct.unpack_from("<6h", report, 1)
        return Motion(translation=v[:3], rotation=v[3:])
    if rid == 1 and len(report) >= 7:
        return Motion(translation=struct.unpack_from("<3h", report, 1))
    if rid == 2 and len(report) >= 7:
        return Motion(rotation=struct.unpack_from("<3h", report, 1))
    if rid == 3 and len(report) >= 2:
        return Motion(buttons=int.from_bytes(report[1:], "little"))
    return None


def encode_translation(x: int, y: int, z: int) -> bytes:
    return b"\x01" + struct.pack("<3h", x, y, z)


def encode_rotation(rx: int, ry: int, rz: int) -> bytes:
    return b"\x02" + struct.pack("<3h", rx, ry, rz)


def encode_buttons(mask: int) -> bytes:
    return b"\x03" + mask.to_bytes(2, "little")
