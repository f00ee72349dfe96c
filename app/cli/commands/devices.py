"""`feelflow devices [--json]`: the haptic devices this machine can use.

Serial ports (serial.tools.list_ports), HID devices FeelFlow has a driver for (hid.enumerate),
and the simulators that need no hardware.
"""
from __future__ import annotations

import dataclasses
import json


def add_arguments(parser):
    parser.add_argument("--json", action="store_true", help="print the list as JSON")
    parser.add_argument("--no-sim", action="store_true", help="leave out the simulators")


def main(args) -> int:
    from feelflow.haptics import list_devices

    devices = list_devices(include_sim=not args.no_sim)
    if args.json:
        print(json.dumps([dataclasses.asdict(d) for d in devices], indent=2, default=str))
        return 0
    if not devices:
        print("no devices found")
        return 0
    width = max(len(d.url) for d in devices)
    for d in devices:
        driver = d.driver or "no driver (add ?driver=haply2diy or ?driver=hapkit)"
        print(f"{d.url:<{width}}  {d.kind:<6}  {d.name}  [{driver}]")
    return 0
