"""The 1 kHz force loop, in its own thread (never the GUI thread).

Every tick: read the device pose (non-blocking), map it into the tunnel, move the body through
the virtual coupling (haptics.virtual_coupling), turn the solver's latest force samples into a smooth
force (haptics.shaping), apply the safety gain (haptics.safety), clamp to the device maximum and
send it. The samples' torque takes the same path (its own hold and low-pass, the same gain, so
the same ramp, pause, stall and NaN zeroing, its own scale and clamp) to a device with a
rotational axis that outputs force (Capabilities.max_torque > 0); to no other. The app talks to it only through thread-safe calls:

    loop = ForceLoop(device, LoopConfig(tunnel_rect=(20, 10, 180, 70), expected_peak=0.02))
    loop.start()                         # ramps force up from zero
    loop.submit_force(ForceSample(fx, fy, time.monotonic()))   # solver thread, any rate
    target = loop.body_target()          # BodyTarget: where the solver should put the body
    loop.pause(); loop.resume(); loop.emergency_stop(); loop.clear_stop()
    loop.status()                        # LoopStatus: rate, jitter, counters, state
    loop.stop()                          # zero force; the device stays open (close it yourself)

`on_disconnect(reason)` (optional) is called from the loop thread when the device goes away:
the app should hop to its GUI thread (e.g. a Qt signal) before touching widgets.
"""
from __future__ import annotations

import math
import os
import sys
import threading
import time
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from feelflow.haptics.virtual_coupling import TunnelMap, VirtualCoupling
from feelflow.haptics.drivers.base import clamp_force
from feelflow.haptics.errors import DeviceDisconnected, DeviceError
from feelflow.haptics.safety import SafetyConfig, SafetyGate
from feelflow.haptics.shaping import ForceInterpolator, ForceScale
from feelflow.haptics.timing import Ticker, try_realtime
from feelflow.haptics.types import BodyTarget, ForceSample, Pose


@dataclass
class LoopConfig:
    """Everything the loop needs besides the device. Scene files may set the force scaling and
    the mapping; none of it can make the device exceed its maximum (the clamp is unconditional)."""

    tunnel_rect: tuple[float, float, float, float] = (0.0, 0.0, 1.0, 1.0)  # lattice nodes
    flip_y: bool | None = None  # None: flip for pantographs (device y points at the student)
    expected_peak: float = 1.0  # lattice force the scene expects at most
    expected_peak_torque: float = 1.0  # lattice torque the scene expects at most (rotational axis)
    comfort_fraction: float = 0.5  # that peak is felt as this fraction of the device maximum
    rate_hz: float = 1000.0
    filter_hz: float = 30.0
    coupling_hz: float = 15.0
    coupling_damping: float = 1.0
    max_body_speed: float = math.inf  # lattice nodes per second
    safety: SafetyConfig = field(default_factory=SafetyConfig)
    disconnect_after: float = 0.25  # s without any pose from a device that answers every tick
    spin_s: float = 0.0003
    realtime: bool = True  # try SCHED_FIFO for the loop thread (needs CAP_SYS_NICE), else nice -10
    gil_switch_interval: float | None = 0.0005  # sys.setswitchinterval while running (None: leave)
    record: bool = False  # keep per-tick arrays for the benchmark (see `recording`)


@dataclass(frozen=True)
class LoopStatus:
    state: str  # idle, ok, ramping, paused, stall, nan, stopped, disconnected
    running: bool
    ticks: int
    rate_hz: float  # measured over the last second
    jitter_p99_ms: float  # |period - nominal| 99th percentile over the last second
    overruns: int
    samples: int
    nan_samples: int
    stalls: int
    gain: float
    force: tuple[float, float]  # last command, newtons, device frame
    max_force_commanded: float
    device_counters: dict
    disconnect_reason: str | None
    scheduling: str


class ForceLoop:
    def __init__(self, device, config: LoopConfig | None = None, on_disconnect=None):
        caps = device.capabilities
        if caps is None:
            raise DeviceError("open the device before starting a force loop on it")
        self.device = device
        self.config = cfg = config or LoopConfig()
        flip = cfg.flip_y if cfg.flip_y is not None else device.driver_name == "haply2diy"
        self.map = TunnelMap(caps.workspace, tuple(cfg.tunnel_rect), flip, caps.dof)
        self.scale = ForceScale(cfg.expected_peak, cfg.comfort_fraction, caps.max_force)
        self.coupling = VirtualCoupling(cfg.coupling_hz, cfg.coupling_damping, cfg.max_body_speed)
        self.shaper = ForceInterpolator(cfg.filter_hz)
        self.torque_scale = ForceScale(cfg.expected_peak_torque, cfg.comfort_fraction, caps.max_torque)
        self.torque_shaper = ForceInterpolator(cfg.filter_hz)  # the torque as (torque, 0)
        self.torque_axis = caps.max_torque > 0   # only then is the torque shaped and sent
        self.torque_sent = 0.0
        self.gate = SafetyGate(cfg.safety)
        self.ticker = Ticker(cfg.rate_hz, cfg.spin_s)
        self.on_disconnect = on_disconnect
        self._lock = threading.Lock()
        self._mailbox: ForceSample | None = None
        self._mailbox_arrival = 0.0
        self._samples = 0
        self._nan = 0
        self._stop_evt = threading.Event()
        self._thread: threading.Thread | None = None
        self._target = BodyTarget(0.0, 0.0, valid=False)
        self._pose: Pose | None = None
        self._pose_time = None
        self._periods = deque(maxlen=int(cfg.rate_hz))
        self.ticks = 0
        self.force_sent = (0.0, 0.0)
        self._max_cmd = 0.0
        self._disconnect_reason = None
        self._old_switch = None
        self.callback_error = None  # what on_disconnect raised, if it did
        self.scheduling = "not started"  # how the loop thread is scheduled (see _raise_priority)
        self.recording: dict[str, list] = {"t": [], "body_x": [], "body_y": [], "fx": [], "fy": [],
                                           "pose_x": []}

    # -- app-facing API (thread-safe) ----------------------------------------------------------
    def start(self) -> None:
        """Start the loop thread; the force ramps up from zero over the ramp time."""
        if self._thread is not None and self._thread.is_alive():
            return
        if self._disconnect_reason is not None:
            raise DeviceDisconnected(self._disconnect_reason)
        self._stop_evt.clear()
        self.gate.gain = 0.0
        if self.config.gil_switch_interval:
            self._old_switch = sys.getswitchinterval()
            sys.setswitchinterval(self.config.gil_switch_interval)
        self._thread = threading.Thread(target=self._run, name="feelflow-haptics", daemon=True)
        self._thread.start()

    def stop(self, timeout: float = 1.0) -> None:
        """Stop the thread and command zero force (the device stays open)."""
        self._stop_evt.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout)
        self._zero_device()
        if self._old_switch is not None:
            sys.setswitchinterval(self._old_switch)
            self._old_switch = None

    def pause(self) -> None:
        """The app paused: fade the force out (within 50 ms); the body keeps following the device."""
        self.gate.set_fault("paused", True)

    def resume(self) -> None:
        self.gate.set_fault("paused", False)

    def emergency_stop(self) -> None:
        """The stop key: zero force at the next tick, latched until `clear_stop()`."""
        self.gate.set_fault("stopped", True)

    def clear_stop(self) -> None:
        self.gate.set_fault("stopped", False)

    def submit_force(self, sample: ForceSample) -> None:
        """A new force sample from the solver (lattice units, tunnel axes); any thread, any rate.
        A non-finite sample zeroes the force at once until a finite one arrives."""
        arrival = time.monotonic()
        with self._lock:
            self._samples += 1
            if not (math.isfinite(sample.fx) and math.isfinite(sample.fy) and math.isfinite(sample.torque)):
                self._nan += 1
                self._mailbox = None
                self.gate.set_fault("nan", True)
                return
            self._mailbox = sample
            self._mailbox_arrival = arrival

    def set_tunnel(self, rect, flip_y: bool | None = None) -> None:
        """Change the tunnel rectangle the device workspace maps onto (lattice nodes)."""
        self.map = TunnelMap(self.map.workspace, tuple(rect),
                             self.map.flip_y if flip_y is None else flip_y, self.map.dof)

    def set_scaling(self, expected_peak: float, comfort_fraction: float | None = None) -> None:
        """Change the force scaling (raises ValueError for nonsense; the clamp always applies)."""
        self.scale = ForceScale(expected_peak, self.scale.comfort_fraction if comfort_fraction is None
                                else comfort_fraction, self.scale.device_max)
        self.torque_scale = ForceScale(self.torque_scale.expected_peak, self.scale.comfort_fraction,
                                       self.torque_scale.device_max)

    def body_target(self) -> BodyTarget:
        """Where the coupled body is now (tunnel coordinates) and how fast it moves."""
        return self._target

    def state_now(self) -> tuple[str, bool]:
        """(state, running), cheaply (status() also computes rate and jitter statistics)."""
        running = self._thread is not None and self._thread.is_alive()
        return (self.gate.state if (running or self._disconnect_reason) else "idle"), running

    def status(self) -> LoopStatus:
        periods = np.array(self._periods, dtype=float)
        if periods.size > 1:
            rate = 1.0 / periods.mean()
            jitter = float(np.percentile(np.abs(periods - self.ticker.period), 99) * 1e3)
        else:
            rate, jitter = 0.0, 0.0
        state, running = self.state_now()
        return LoopStatus(state, running, self.ticks, rate, jitter, self.ticker.overruns,
                          self._samples, self._nan, self.gate.counts["stall"], self.gate.gain,
                          self.force_sent, self._max_cmd, dict(self.device.counters), self._disconnect_reason,
                          self.scheduling)

    # -- the loop -----------------------------------------------------------------------------
    def _zero_device(self) -> None:
        self.force_sent = (0.0, 0.0)
        self.torque_sent = 0.0
        try:
            self.device.write_force(0.0, 0.0)
            self.device.write_torque(0.0)
        except DeviceError:
            pass

    def _disconnected(self, reason: str) -> None:
        self._disconnect_reason = reason
        self.gate.set_fault("disconnected", True)
        self.gate.gain = 0.0
        self._zero_device()
        self._stop_evt.set()
        if self.on_disconnect is not None:
            try:
                self.on_disconnect(reason)
            except Exception as exc:  # the app's bug must not keep a motor driven
                self.callback_error = repr(exc)

    def _raise_priority(self) -> str:
        """Make this (the loop) thread wake on time on a busy machine; returns what worked."""
        if not self.config.realtime:
            return "normal"
        if try_realtime(10):
            return "SCHED_FIFO 10"
        try:
            os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), -10)
            return "nice -10"
        except (OSError, AttributeError):
            return "normal"

    def _run(self) -> None:
        self.scheduling = self._raise_priority()
        prev = None
        rec = self.recording if self.config.record else None
        self._pose_time = time.monotonic()
        try:
            while not self._stop_evt.is_set():
                now = self.ticker.wait()
                if prev is not None:
                    self._periods.append(now - prev)
                dt = self.ticker.period if prev is None else now - prev
                prev = now
                self.ticks += 1
                if not self._tick(now, dt, rec):
                    break
        except DeviceDisconnected as exc:
            self._disconnected(str(exc))
        except Exception as exc:  # never leave a motor driven by a dead loop
            self._disconnected(f"force loop failed: {exc!r}")
            raise

    def _tick(self, now: float, dt: float, rec) -> bool:
        dev = self.device
        # 1. pose -> body
        pose = dev.poll()
        if pose is not None:
            self._pose, self._pose_time = pose, now
        elif dev.continuous and now - self._pose_time > self.config.disconnect_after:
            self._disconnected(f"{dev.url}: no data for {self.config.disconnect_after * 1e3:.0f} ms")
            return False
        p = self._pose
        if p is not None:
            stop_mask = self.config.safety.stop_buttons
            if stop_mask and p.buttons & stop_mask:
                self.gate.set_fault("stopped", True)
            proxy = self.map.to_tunnel(p.x, p.y)
            (bx, by), (vx, vy) = self.coupling.step(proxy, dt)
            self._target = BodyTarget(bx, by, vx, vy, now, p.buttons, True)
        # 2. solver samples -> smooth force
        with self._lock:  # (clearing 'nan' under the lock: a NaN submitted meanwhile wins)
            sample, arrival = self._mailbox, self._mailbox_arrival
            self._mailbox = None
            if sample is not None:
                self.gate.set_fault("nan", False)
        if sample is not None:
            self.shaper.add(sample.fx, sample.fy, arrival)
            if self.torque_axis:
                self.torque_shaper.add(sample.torque, 0.0, arrival)
        due = self.shaper.next_due
        stalled = due is None or now > due + self.config.safety.stall_timeout
        self.gate.set_fault("stall", stalled)
        lx, ly = self.shaper.evaluate(now)
        # 3. safety gain, scale, map to device axes, clamp
        g = self.gate.update(now)
        k = self.scale.gain * g
        fx, fy = self.map.vector_to_device(lx * k, ly * k)
        fx, fy = clamp_force(fx, fy, dev.capabilities.max_force)
        # 4. command
        self.force_sent = dev.write_force(fx, fy)
        if self.torque_axis:   # the same gain g: ramp, pause, stall, NaN zero it too
            lt, _ = self.torque_shaper.evaluate(now)
            self.torque_sent = dev.write_torque(self.map.torque_to_device(lt * self.torque_scale.gain * g))
        self._max_cmd = max(self._max_cmd, math.hypot(*self.force_sent))
        if rec is not None:
            rec["t"].append(now)
            rec["body_x"].append(self._target.x)
            rec["body_y"].append(self._target.y)
            rec["fx"].append(self.force_sent[0])
            rec["fy"].append(self.force_sent[1])
            rec["pose_x"].append(p.x if p is not None else math.nan)
        return True
