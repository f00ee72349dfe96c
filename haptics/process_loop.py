"""The force loop in its own PROCESS, for apps whose other threads run Python.

Why: CPython threads share one interpreter lock (GIL). A GUI or solver thread that holds it and
is descheduled by a busy OS, or sits in a long C call that keeps it (GL calls do), stalls the
1 kHz loop thread for milliseconds (measured on the loaded 2-core dev machine: a pure-Python busy
thread next to the loop took the p99 period jitter from 0.02 ms to 4.3 ms; docs/guide/haptic-devices.md).
A child process has its own interpreter, where the loop competes with nothing of the app.

`ProcessForceLoop(url, config)` offers the ForceLoop API (start, stop, pause, resume,
emergency_stop, clear_stop, submit_force, body_target, status, set_tunnel, set_scaling,
capabilities) plus close(). The child (`python -m feelflow.haptics.process_loop`, started with
subprocess: no multiprocessing, so the app's __main__ is never re-run, and nothing is pickled)
opens the device itself; sim:// simulators live there too.
  parent -> child: its stdin, length-prefixed messages: b'F' + 4 doubles (a force sample: fx,
                   fy, t, torque) or
                   JSON commands;
  child -> parent: body target and status in a shared memory-mapped file (a seqlock over
                   doubles), and rare length-prefixed JSON on its stdout (ready, error,
                   disconnected, counters), read by a watcher thread that also calls
                   `on_disconnect(reason)` (from that thread).
If the parent dies, the child reads EOF, zeroes the force and exits.
"""
from __future__ import annotations

import dataclasses
import json
import mmap
import os
import struct
import subprocess
import sys
import tempfile
import threading
import time

from feelflow.haptics.errors import DeviceDisconnected, DeviceError
from feelflow.haptics.loop import LoopConfig, LoopStatus
from feelflow.haptics.safety import SafetyConfig
from feelflow.haptics.timing import try_realtime
from feelflow.haptics.types import BodyTarget, Capabilities, ForceSample

_LEN = struct.Struct("<I")
_SAMPLE = struct.Struct("<cdddd")
_FIELDS = ("seq", "x", "y", "vx", "vy", "t", "buttons", "valid", "running", "ticks", "rate_hz",
           "jitter_p99_ms", "overruns", "samples", "nan_samples", "stalls", "gain", "fx", "fy",
           "max_force_commanded", "state")
_IDX = {k: i for i, k in enumerate(_FIELDS)}
_ARRAY = struct.Struct(f"<{len(_FIELDS)}d")
_STATES = ("idle", "ok", "ramping", "paused", "stall", "nan", "stopped", "disconnected")


def _config_to_json(cfg: LoopConfig) -> str:
    d = dataclasses.asdict(cfg)
    d["record"] = False  # recordings stay in the child; benchmarks use ForceLoop directly
    return json.dumps(d)


def _config_from_json(text: str) -> LoopConfig:
    d = json.loads(text)
    d["safety"] = SafetyConfig(**d["safety"])
    d["tunnel_rect"] = tuple(d["tunnel_rect"])
    return LoopConfig(**d)


def _write_msg(stream, payload: bytes) -> None:
    stream.write(_LEN.pack(len(payload)) + payload)
    stream.flush()


def _read_msg(stream) -> bytes | None:
    head = stream.read(_LEN.size)
    if len(head) < _LEN.size:
        return None
    (n,) = _LEN.unpack(head)
    body = stream.read(n)
    return body if len(body) == n else None


# --- the child -------------------------------------------------------------------------------------
def _publish(mm, loop, seq: list, vals: list, st=None) -> None:
    """Write the body target (and, when `st` is given, the status) under the seqlock; `vals`
    is the publisher's own copy of the block (it is the only writer), so the status fields of
    the last status publish stay as they were."""
    bt = loop.body_target()
    fields = [("x", bt.x), ("y", bt.y), ("vx", bt.vx), ("vy", bt.vy), ("t", bt.t),
              ("buttons", bt.buttons), ("valid", bt.valid), ("fx", loop.force_sent[0]), ("fy", loop.force_sent[1]),
              ("ticks", loop.ticks), ("gain", loop.gate.gain)]
    state, running = loop.state_now()
    fields += [("running", running), ("state", _STATES.index(state) if state in _STATES else 0)]
    if st is not None:
        fields += [("rate_hz", st.rate_hz), ("jitter_p99_ms", st.jitter_p99_ms),
                   ("overruns", st.overruns), ("samples", st.samples), ("nan_samples", st.nan_samples),
                   ("stalls", st.stalls), ("max_force_commanded", st.max_force_commanded)]
    for k, v in fields:
        vals[_IDX[k]] = float(v)
    seq[0] += 1
    mm[0:8] = struct.pack("<d", seq[0])  # odd: being written
    mm[8:_ARRAY.size] = _ARRAY.pack(*vals)[8:]
    seq[0] += 1
    mm[0:8] = struct.pack("<d", seq[0])  # even: consistent


def child_main(argv) -> int:
    from feelflow.haptics.loop import ForceLoop
    from feelflow.haptics.registry import open_device

    url, shm_path = argv[0], argv[1]
    out = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)  # anything printed by accident goes to stderr, never into the message stream
    inp = sys.stdin.buffer
    out_lock = threading.Lock()

    def send(msg: dict) -> None:
        with out_lock:
            try:
                _write_msg(out, json.dumps(msg).encode())
            except (OSError, ValueError):
                pass

    cfg_bytes = _read_msg(inp)
    if cfg_bytes is None:
        return 1
    with open(shm_path, "r+b") as fh:
        mm = mmap.mmap(fh.fileno(), _ARRAY.size)
    try:
        dev = open_device(url)
    except (DeviceError, ValueError) as exc:
        send({"error": str(exc)})
        return 2
    loop = ForceLoop(dev, _config_from_json(cfg_bytes.decode()),
                     on_disconnect=lambda reason: send({"disconnected": reason}))
    send({"ready": dataclasses.asdict(dev.capabilities), "driver": dev.driver_name})
    seq = [0.0]
    vals = list(_ARRAY.unpack(mm[:_ARRAY.size]))
    done = threading.Event()

    def publisher():  # body target 500 times a second; the (costlier) status 10 times
        try_realtime(8)  # threads of the child that touch the GIL must not be preempted holding it
        last_status = last_counters = 0.0
        while not done.wait(0.002):
            now = time.monotonic()
            st = None
            if now - last_status > 0.1:
                last_status, st = now, loop.status()
            _publish(mm, loop, seq, vals, st)
            if st is not None and now - last_counters > 0.25:
                last_counters = now
                send({"counters": st.device_counters, "scheduling": st.scheduling})

    pub = threading.Thread(target=publisher, daemon=True)
    pub.start()
    try_realtime(8)  # this (the command) thread
    try:
        while True:
            data = _read_msg(inp)
            if data is None:
                break  # the parent is gone: zero the force and leave
            if data[:1] == b"F" and len(data) == _SAMPLE.size:
                _, fx, fy, t, torque = _SAMPLE.unpack(data)
                loop.submit_force(ForceSample(fx, fy, t, torque=torque))
                continue
            cmd = json.loads(data)
            op = cmd.get("op")
            if op == "quit":
                break
            try:
                if op in ("start", "stop", "pause", "resume", "emergency_stop", "clear_stop"):
                    getattr(loop, op)()
                elif op == "set_tunnel":
                    loop.set_tunnel(cmd["rect"], cmd.get("flip_y"))
                elif op == "set_scaling":
                    loop.set_scaling(cmd["expected_peak"], cmd.get("comfort_fraction"))
                elif op == "simulate_unplug":
                    simulator = getattr(dev, "simulator", None)
                    if simulator is None:
                        raise DeviceError(f"{dev.url if hasattr(dev, 'url') else 'device'}: not a simulator")
                    simulator.unplug()
            except (ValueError, DeviceError) as exc:
                send({"command_error": str(exc)})
    finally:
        loop.stop()
        dev.close()
        done.set()
        pub.join(1.0)
        _publish(mm, loop, seq, vals, loop.status())
    return 0


# --- the parent ------------------------------------------------------------------------------------
class ProcessForceLoop:
    """A ForceLoop running in a child process (see the module docstring)."""

    def __init__(self, url: str, config: LoopConfig | None = None, on_disconnect=None,
                 start_timeout: float = 30.0):
        self.url = url
        self.config = config or LoopConfig()
        self.on_disconnect = on_disconnect
        self._reason = None
        self._counters: dict = {}
        self._scheduling = "not started"
        self.command_errors: list[str] = []
        shm_dir = "/dev/shm" if os.path.isdir("/dev/shm") else None
        fd, self._shm_path = tempfile.mkstemp(prefix="feelflow-haptics-", dir=shm_dir)
        os.write(fd, bytes(_ARRAY.size))
        os.close(fd)
        with open(self._shm_path, "r+b") as fh:
            self._mm = mmap.mmap(fh.fileno(), _ARRAY.size)
        self._proc = subprocess.Popen([sys.executable, "-m", "feelflow.haptics.process_loop", url, self._shm_path],
                                      stdin=subprocess.PIPE, stdout=subprocess.PIPE)
        self._send_lock = threading.Lock()
        self._send(_config_to_json(self.config).encode())
        self._ready = threading.Event()
        self._ready_msg: dict = {}
        self._watcher = threading.Thread(target=self._watch, name="feelflow-haptics-watch", daemon=True)
        self._watcher.start()
        if not self._ready.wait(start_timeout):
            self._kill()
            raise DeviceError(f"{url}: the haptics process did not start within {start_timeout:.0f} s")
        msg = self._ready_msg
        if "error" in msg or "ready" not in msg:
            self._kill()
            raise DeviceError(msg.get("error") or f"{url}: the haptics process ended while opening the device")
        caps = msg["ready"]
        caps["workspace"] = tuple(tuple(v) for v in caps["workspace"])
        self.capabilities = Capabilities(**caps)
        self.driver_name = msg.get("driver")

    def _watch(self) -> None:
        while True:
            data = _read_msg(self._proc.stdout)
            if data is None:
                if not self._ready.is_set():
                    self._ready.set()
                elif self._reason is None and not self._closing:
                    self._reason = f"the haptics process ended (exit code {self._proc.poll()})"
                    self._notify()
                return
            msg = json.loads(data)
            if "ready" in msg or "error" in msg:
                self._ready_msg = msg
                self._ready.set()
            elif "disconnected" in msg:
                self._reason = msg["disconnected"]
                self._notify()
            elif "counters" in msg:
                self._counters, self._scheduling = msg["counters"], msg["scheduling"]
            elif "command_error" in msg:
                self.command_errors.append(msg["command_error"])

    _closing = False

    def _notify(self) -> None:
        if self.on_disconnect is not None:
            try:
                self.on_disconnect(self._reason)
            except Exception:  # the app's callback must not kill the watcher
                pass

    def _send(self, payload: bytes) -> None:
        with self._send_lock:
            try:
                _write_msg(self._proc.stdin, payload)
            except (OSError, ValueError):
                raise DeviceDisconnected(self._reason or f"{self.url}: the haptics process is gone") from None

    def _cmd(self, op: str, **kw) -> None:
        self._send(json.dumps({"op": op, **kw}).encode())

    def _read(self) -> tuple:
        vals = _ARRAY.unpack(self._mm[:_ARRAY.size])
        for _ in range(1000):
            if int(vals[0]) % 2 == 0 and struct.unpack("<d", self._mm[0:8])[0] == vals[0]:
                break
            vals = _ARRAY.unpack(self._mm[:_ARRAY.size])
        return vals

    def _kill(self) -> None:
        self._closing = True
        if self._proc.poll() is None:
            self._proc.terminate()
        try:
            self._proc.wait(3.0)
        except subprocess.TimeoutExpired:
            self._proc.kill()
        self._cleanup()

    def _cleanup(self) -> None:
        try:
            os.unlink(self._shm_path)
        except OSError:
            pass

    # -- the ForceLoop API ---------------------------------------------------------------------------
    def start(self) -> None:
        self._cmd("start")

    def stop(self) -> None:
        self._cmd("stop")

    def pause(self) -> None:
        self._cmd("pause")

    def resume(self) -> None:
        self._cmd("resume")

    def emergency_stop(self) -> None:
        self._cmd("emergency_stop")

    def clear_stop(self) -> None:
        self._cmd("clear_stop")

    def simulate_unplug(self) -> None:
        """sim:// devices only: unplug the simulated board (its real disconnect path, in the child)."""
        self._cmd("simulate_unplug")

    def set_tunnel(self, rect, flip_y: bool | None = None) -> None:
        self._cmd("set_tunnel", rect=[float(v) for v in rect], flip_y=flip_y)

    def set_scaling(self, expected_peak: float, comfort_fraction: float | None = None) -> None:
        from feelflow.haptics.shaping import ForceScale

        # validate here, so a bad scene value raises in the caller as with ForceLoop
        ForceScale(expected_peak, 0.5 if comfort_fraction is None else comfort_fraction, 1.0)
        self._cmd("set_scaling", expected_peak=expected_peak, comfort_fraction=comfort_fraction)

    def submit_force(self, sample: ForceSample) -> None:
        self._send(_SAMPLE.pack(b"F", sample.fx, sample.fy, sample.t, sample.torque))

    def body_target(self) -> BodyTarget:
        v = self._read()
        g = lambda k: v[_IDX[k]]  # noqa: E731
        return BodyTarget(g("x"), g("y"), g("vx"), g("vy"), g("t"), int(g("buttons")), bool(g("valid")))

    def status(self) -> LoopStatus:
        v = self._read()
        g = lambda k: v[_IDX[k]]  # noqa: E731
        state = _STATES[int(g("state"))] if self._reason is None else "disconnected"
        return LoopStatus(state, bool(g("running")) and self._reason is None, int(g("ticks")), g("rate_hz"),
                          g("jitter_p99_ms"), int(g("overruns")), int(g("samples")), int(g("nan_samples")),
                          int(g("stalls")), g("gain"), (g("fx"), g("fy")), g("max_force_commanded"),
                          dict(self._counters), self._reason, self._scheduling)

    def close(self, timeout: float = 3.0) -> None:
        """Stop the loop (zero force), close the device, end the child process."""
        self._closing = True
        try:
            self._cmd("quit")
            self._proc.stdin.close()
        except (DeviceDisconnected, OSError):
            pass
        try:
            self._proc.wait(timeout)
        except subprocess.TimeoutExpired:
            self._kill()
        self._watcher.join(1.0)
        self._cleanup()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


if __name__ == "__main__":
    sys.exit(child_main(sys.argv[1:]))
