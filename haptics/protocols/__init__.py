"""Wire formats, as pure functions (bytes in, values out): no I/O, no threads.

haply: the Haply hAPI serial protocol (M3 board firmware v1.5), as the 2DIY speaks it.
hapkit: FeelFlow's framed serial protocol for a Hapkit-style 1-DOF paddle (docs/guide/haptic-devices.md).
spacemouse: the 3Dconnexion SpaceMouse HID input reports.
diyhid: FeelFlow's vendor-defined 64-byte HID reports for do-it-yourself boards.
"""
