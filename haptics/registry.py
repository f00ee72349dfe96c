"""Finding and opening devices by URL.

  serial:///dev/ttyACM0[?driver=haply2diy|hapkit][&baud=N]   a serial port (driver guessed
                                                    from USB ids; baud defaults to the firmware's)
  hid://VID:PID[?driver=spacemouse|diyhid]          a HID device (hex ids)
  sim://haply2diy | sim://hapkit | sim://spacemouse | sim://diyhid   simulators (no hardware)
  loop://?driver=hapkit                             pyserial's loopback, for tests
"""
from __future__ import annotations

import urllib.parse

from feelflow.haptics.errors import BadDeviceURL, DeviceError
from feelflow.haptics.protocols import diyhid
from feelflow.haptics.protocols import spacemouse as sm
from feelflow.haptics.types import DeviceInfo

SIMULATORS = {
    "haply2diy": "Haply 2DIY pantograph (simulated, hAPI serial over a pseudo-terminal)",
    "hapkit": "Hapkit 1-DOF paddle (simulated, FeelFlow serial protocol over a pseudo-terminal)",
    "spacemouse": "3Dconnexion SpaceMouse (simulated HID, input only)",
    "diyhid": "DIY HID force board (simulated, FeelFlow HID reports)",
}
#: USB (vid, pid) of serial boards whose firmware we know by default
SERIAL_IDS = {(0x2341, 0x003E): "haply2diy",  # Arduino Due native port (Haply M3 board)
              (0x2341, 0x003D): "haply2diy"}


def _drivers():
    from feelflow.haptics.drivers.diyhid import DiyHid
    from feelflow.haptics.drivers.hapkit import Hapkit
    from feelflow.haptics.drivers.haply2diy import Haply2DIY
    from feelflow.haptics.drivers.spacemouse import SpaceMouse
    return {"haply2diy": Haply2DIY, "hapkit": Hapkit, "spacemouse": SpaceMouse, "diyhid": DiyHid}


def hid_driver_for(vid: int, pid: int, usage_page: int | None = None) -> str | None:
    if (vid, pid) in sm.PRODUCTS:
        return "spacemouse"
    if usage_page == diyhid.USAGE_PAGE or (usage_page is None and (vid, pid) == (diyhid.DEFAULT_VID, diyhid.DEFAULT_PID)):
        return "diyhid"
    return None


def list_devices(include_sim: bool = True) -> list[DeviceInfo]:
    """Serial ports (serial.tools.list_ports), HID devices we have a driver for (hid.enumerate),
    and the simulators."""
    out: list[DeviceInfo] = []
    try:
        from serial.tools import list_ports

        for p in sorted(list_ports.comports(), key=lambda p: p.device):
            driver = SERIAL_IDS.get((p.vid, p.pid)) if p.vid is not None else None
            name = p.description if p.description and p.description != "n/a" else f"{p.device} (no USB id)"
            out.append(DeviceInfo(f"serial://{p.device}", name, "serial", driver,
                                  {"vid": p.vid, "pid": p.pid, "hwid": p.hwid}))
    except (ImportError, OSError):
        pass
    try:
        import hid

        seen = set()
        for d in hid.enumerate():
            vid, pid = d.get("vendor_id", 0), d.get("product_id", 0)
            driver = hid_driver_for(vid, pid, d.get("usage_page"))
            if driver is None or (vid, pid) in seen:
                continue
            seen.add((vid, pid))
            name = sm.PRODUCTS.get((vid, pid)) or d.get("product_string") or "HID device"
            out.append(DeviceInfo(f"hid://{vid:04x}:{pid:04x}", name, "hid", driver,
                                  {"path": (d.get("path") or b"").decode(errors="replace")}))
    except (ImportError, OSError):
        pass
    if include_sim:
        out += [DeviceInfo(f"sim://{k}", v, "sim", k) for k, v in SIMULATORS.items()]
    return out


def _parse(url: str):
    u = urllib.parse.urlsplit(url)
    q = dict(urllib.parse.parse_qsl(u.query))
    return u, q


def open_device(url: str):
    """Open and hand-shake the device at `url`; returns a `feelflow.haptics.drivers.base.Device`.

    Raises BadDeviceURL for a URL we do not understand and DeviceError when the device does
    not answer. The caller closes it (`with open_device(url) as dev:` works).
    """
    from feelflow.haptics.transport import HidTransport, SerialTransport

    drivers = _drivers()
    u, q = _parse(url)
    driver_name = q.get("driver")
    if driver_name is not None and driver_name not in drivers:
        raise BadDeviceURL(f"unknown driver '{driver_name}' in {url} (known: {', '.join(drivers)})")
    if u.scheme == "sim":
        kind = u.netloc or u.path.strip("/")
        if kind not in SIMULATORS:
            raise BadDeviceURL(f"unknown simulator '{kind}' (known: {', '.join(SIMULATORS)})")
        return _open_sim(kind, url, drivers)
    if u.scheme == "serial":
        port = u.path or u.netloc
        if not port:
            raise BadDeviceURL(f"no port in {url} (expected serial:///dev/ttyACM0)")
        if driver_name is None:
            driver_name = _guess_serial_driver(port)
        try:
            baud = int(q.get("baud", drivers[driver_name].baudrate))
        except ValueError:
            raise BadDeviceURL(f"baud must be a whole number in {url}") from None
        dev = drivers[driver_name](SerialTransport(port, baud), url)
    elif u.scheme == "loop":
        dev = drivers[driver_name or "hapkit"](SerialTransport("loop://"), url)
    elif u.scheme == "hid":
        try:
            vid_s, pid_s = u.netloc.split(":")
            vid, pid = int(vid_s, 16), int(pid_s, 16)
        except ValueError:
            raise BadDeviceURL(f"expected hid://VID:PID in hex, got {url}") from None
        driver_name = driver_name or hid_driver_for(vid, pid)
        if driver_name not in ("spacemouse", "diyhid"):
            raise BadDeviceURL(f"no HID driver for {vid:04x}:{pid:04x}; add ?driver=diyhid for a DIY board")
        transport = HidTransport(vid, pid)
        dev = drivers[driver_name](transport, url)
        if driver_name == "spacemouse":
            dev.name = sm.PRODUCTS.get((vid, pid), "SpaceMouse")
    else:
        raise BadDeviceURL(f"unknown device URL scheme in '{url}' (serial://, hid://, sim://, loop://)")
    return _opened(dev)


def _opened(dev):
    """Open a device; if that fails, close what it had opened (transport, simulator) and re-raise."""
    try:
        dev.open()
    except DeviceError:
        dev.close()
        raise
    return dev


def _guess_serial_driver(port: str) -> str:
    try:
        from serial.tools import list_ports

        for p in list_ports.comports():
            if p.device == port and (p.vid, p.pid) in SERIAL_IDS:
                return SERIAL_IDS[(p.vid, p.pid)]
    except (ImportError, OSError):
        pass
    return "hapkit"


def _open_sim(kind: str, url: str, drivers):
    from feelflow.haptics.transport import HidTransport, SerialTransport

    if kind in ("haply2diy", "hapkit"):  # serial boards: a simulator process behind a pty
        from feelflow.haptics.drivers.haply2diy import WORKSPACE
        from feelflow.haptics.sim.hapkit_sim import INFO
        from feelflow.haptics.sim.serve import RemoteSim
        ws = WORKSPACE if kind == "haply2diy" else ((INFO.x_min, INFO.x_max), (0.0, 0.0))
        sim = RemoteSim(kind, ws)
        try:
            dev = drivers[kind](SerialTransport(sim.port), url)
        except DeviceError:
            sim.stop()
            raise
    else:
        from feelflow.haptics.sim.hid_sim import DiyHidSim, SpaceMouseSim
        sim = SpaceMouseSim() if kind == "spacemouse" else DiyHidSim()
        dev = drivers[kind](HidTransport(device=sim, name=url), url)
    dev.simulator = sim
    return _opened(dev)
