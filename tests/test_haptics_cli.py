"""`feelflow devices` and `feelflow bench haptics`, run as a user runs them."""
import json
import subprocess
import sys

import pytest

from feelflow.haptics import BadDeviceURL, list_devices, open_device


def run(*args):
    return subprocess.run([sys.executable, "-m", "feelflow.app", *args], capture_output=True, text=True, timeout=120)


def test_devices_json_lists_the_simulators():
    r = run("devices", "--json")
    assert r.returncode == 0, r.stderr
    urls = {d["url"] for d in json.loads(r.stdout)}
    assert {"sim://haply2diy", "sim://hapkit", "sim://spacemouse", "sim://diyhid"} <= urls


def test_list_devices_matches_the_serial_ports():
    from serial.tools import list_ports

    ports = {f"serial://{p.device}" for p in list_ports.comports()}
    assert ports == {d.url for d in list_devices() if d.kind == "serial"}


@pytest.mark.parametrize("url", ["sim://nothing", "ftp://x", "hid://zz:1", "hid://1234:5678",
                                 "serial:///dev/ttyACM0?driver=teapot"])
def test_bad_urls_are_one_line_errors(url):
    with pytest.raises(BadDeviceURL):
        open_device(url)


def test_bench_haptics_reports_and_writes_json(tmp_path):
    out = tmp_path / "bench.json"
    r = run("bench", "haptics", "--device", "sim://hapkit", "--seconds", "1.5", "--json", str(out))
    assert r.returncode == 0, r.stdout + r.stderr
    assert "period jitter" in r.stdout and "Traceback" not in r.stderr
    data = json.loads(out.read_text())
    assert data["force_within_max"] is True
    assert data["largest_force_commanded_N"] <= data["device_max_force_N"]
    for key in ("rate_hz", "jitter_ms", "latency_pose_to_body_ms", "latency_force_to_command_ms"):
        assert key in data


def test_bench_bad_device_is_a_user_error():
    r = run("bench", "haptics", "--device", "sim://nothing", "--seconds", "1")
    assert r.returncode == 2 and "Traceback" not in r.stderr and r.stderr.count("\n") == 1
