"""A device node this user may not open gives the exact fix (haptics/permissions.py), provoked
for real: a pseudo-terminal and a file of mode 000 opened through the real transports in a
child process that runs as an ordinary user (root may open anything, so the child drops to
`nobody` when the tests run as root)."""
from __future__ import annotations

import grp
import os
import shutil
import subprocess
import sys
import tempfile
import textwrap

import pytest

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux device nodes")

CHILD = textwrap.dedent("""
    import os, sys
    import grp, hid, serial, serial.serialposix   # loaded before the privileges go (root's Python)
    from feelflow.haptics.errors import DeviceError
    from feelflow.haptics.transport import HidTransport, SerialTransport
    if os.geteuid() == 0:
        os.setgroups([])
        os.setgid(65534)
        os.setuid(65534)
    kind, node = sys.argv[1], sys.argv[2]
    try:
        if kind == "serial":
            SerialTransport(node).close()
        else:
            HidTransport(path=node.encode(), name="hid://16c0:0486")
    except DeviceError as exc:
        print(exc)
        sys.exit(3)
    print("opened")
""")


def open_as_user(kind: str, node: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", CHILD, kind, node], capture_output=True, text=True, timeout=60)


@pytest.fixture
def pty_node():
    master, slave = os.openpty()
    name = os.ttyname(slave)
    yield name
    os.close(slave)
    os.close(master)


def test_serial_port_of_mode_000_names_the_udev_rule_and_dialout(pty_node):
    os.chmod(pty_node, 0)
    out = open_as_user("serial", pty_node)
    assert out.returncode == 3, out.stdout + out.stderr
    line = out.stdout.strip()
    assert "\n" not in line and "Traceback" not in out.stderr
    assert line.startswith(f"no permission to open {pty_node} (mode 000")
    assert "sudo installer/install-desktop.sh --udev" in line
    assert "sudo usermod -aG dialout $USER" in line


@pytest.mark.skipif(os.geteuid() != 0, reason="giving the node to the dialout group needs root")
def test_serial_port_of_a_group_names_that_group(pty_node):
    try:
        gid = grp.getgrnam("dialout").gr_gid
    except KeyError:
        pytest.skip("no dialout group on this machine")
    os.chown(pty_node, 0, gid)
    os.chmod(pty_node, 0o660)
    out = open_as_user("serial", pty_node)
    assert out.returncode == 3, out.stdout + out.stderr
    assert out.stdout.strip() == (f"no permission to open {pty_node}: add this user to the 'dialout' group "
                                  "(sudo usermod -aG dialout $USER), then log out and in again")


def test_serial_port_this_user_may_open_opens(pty_node):
    os.chmod(pty_node, 0o666)
    out = open_as_user("serial", pty_node)
    assert out.returncode == 0 and out.stdout.strip() == "opened", out.stdout + out.stderr


def test_hid_node_of_mode_000_names_the_udev_rule():
    folder = tempfile.mkdtemp(prefix="feelflow-hid-")   # pytest's tmp_path is root's alone
    os.chmod(folder, 0o755)
    node = os.path.join(folder, "hidraw-refused")
    open(node, "wb").close()
    os.chmod(node, 0)
    try:
        out = open_as_user("hid", node)
    finally:
        shutil.rmtree(folder)
    assert out.returncode == 3, out.stdout + out.stderr
    assert out.stdout.strip() == (f"cannot open HID device hid://16c0:0486: no permission to use {node}: "
                                  "install FeelFlow's udev rule (sudo installer/install-desktop.sh --udev, "
                                  "then unplug and replug the device)")


def test_udev_rules_cover_every_device_with_a_driver():
    from feelflow.haptics.udev import udev_rules
    from feelflow.haptics.protocols import diyhid, spacemouse
    from feelflow.haptics.registry import SERIAL_IDS, hid_driver_for

    text = udev_rules()
    for vid, pid in list(spacemouse.PRODUCTS) + [(diyhid.DEFAULT_VID, diyhid.DEFAULT_PID)]:
        assert hid_driver_for(vid, pid) is not None
        assert (f'KERNEL=="hidraw*", ATTRS{{idVendor}}=="{vid:04x}", ATTRS{{idProduct}}=="{pid:04x}", '
                'MODE="0660", TAG+="uaccess"') in text
    for vid, pid in SERIAL_IDS:
        assert f'SUBSYSTEM=="tty", ATTRS{{idVendor}}=="{vid:04x}", ATTRS{{idProduct}}=="{pid:04x}"' in text
    rules = [line for line in text.splitlines() if line and not line.startswith("#")]
    assert len(rules) == len(set(spacemouse.PRODUCTS) | {(diyhid.DEFAULT_VID, diyhid.DEFAULT_PID)}) + len(SERIAL_IDS)
