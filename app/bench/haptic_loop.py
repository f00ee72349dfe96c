"""`feelflow bench haptics [--device URL] [--seconds S] [--json PATH]`: the force loop, measured.

Runs the real loop against a device (a simulator by default) while a feeder thread plays the
solver (force samples at 60 Hz with steps, and a burst far above the scene's expected peak),
and, on simulators, a scripted hand that steps the handle. Reports the loop rate, the period
jitter |period - 1 ms| (median, p99, max), the latency from a pose change to the body moving
and from a solver force change to the device command (first response and 50 % of the step),
and the largest force commanded (by the loop, and as the simulated device received it).
Targets: rate within 1 % of 1 kHz, p99 jitter < 1 ms, force never above the maximum.
"""
from __future__ import annotations

import math
import os
import platform
import threading
import time

import numpy as np

from feelflow.app.errors import UserError

FEED_HZ = 60.0


def _load() -> str:
    try:
        return "load average " + " ".join(f"{v:.2f}" for v in os.getloadavg())
    except OSError:
        return "load unknown"


def _first_crossing(t, y, t0, y_before, y_after, fraction):
    """First time >= t0 where y has moved `fraction` of the way from y_before to y_after."""
    step = y_after - y_before
    if step == 0:
        return None
    i0 = int(np.searchsorted(t, t0))
    moved = (y[i0:] - y_before) / step
    hit = np.nonzero(moved >= fraction)[0]
    return None if hit.size == 0 else float(t[i0 + hit[0]] - t0)


def _stats_ms(values):
    v = [x for x in values if x is not None]
    if not v:
        return None
    a = np.array(v) * 1e3
    return {"median": float(np.median(a)), "max": float(a.max()), "n": len(v)}


def run(url: str, seconds: float) -> dict:
    from feelflow.haptics import DeviceError, ForceLoop, ForceSample, LoopConfig, open_device

    try:
        dev = open_device(url)
    except (DeviceError, ValueError) as exc:
        raise UserError(str(exc)) from None
    caps = dev.capabilities
    sim = dev.simulator
    hand = getattr(sim, "hand", None)
    peak = 1.0  # lattice units: the feeder's "expected peak"
    cfg = LoopConfig(tunnel_rect=(0.0, 0.0, 400.0, 200.0), expected_peak=peak, comfort_fraction=0.5,
                     record=True)
    loop = ForceLoop(dev, cfg)
    force_steps = []  # (t_submitted, lattice value before, after)
    stop = threading.Event()
    level = {"value": 0.2 * peak}
    sent = {"value": level["value"]}

    def feeder():
        try:  # the solver stand-in must not be starved by the machine's load (that is a stall)
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(5))
        except (OSError, AttributeError):
            pass
        next_t = time.monotonic()
        while not stop.is_set():
            value = level["value"]
            now = time.monotonic()
            if value != sent["value"]:  # the solver's force changed: latency is measured from here
                force_steps.append((now, sent["value"], value))
                sent["value"] = value
            loop.submit_force(ForceSample(value, 0.0, now))
            next_t += 1.0 / FEED_HZ
            time.sleep(max(0.0, next_t - time.monotonic()))

    feed = threading.Thread(target=feeder, daemon=True)
    pose_steps = []  # (t_set, x_before, x_after) device metres
    t_start = time.monotonic()
    loop.start()
    feed.start()
    try:
        time.sleep(min(1.0, 0.2 * seconds))  # ramp-up
        (x0, x1), (y0, y1) = caps.workspace
        xs = [x0 + 0.35 * (x1 - x0), x0 + 0.65 * (x1 - x0)]
        yc = 0.5 * (y0 + y1)
        end_measure = t_start + 0.85 * seconds
        k = 0
        while time.monotonic() < end_measure:
            if hand is not None and caps.input_mode == "position":
                before = hand.get()[0]
                hand.set(xs[k % 2], yc)
                pose_steps.append((hand.moved_at, before, xs[k % 2]))
            time.sleep(0.12)
            level["value"] = (0.8 if k % 2 == 0 else 0.2) * peak
            time.sleep(0.18)
            k += 1
        time.sleep(0.05)
        n_steps = len(force_steps)
        level["value"] = 20.0 * peak  # a scene gone wild: 20x its expected peak
        time.sleep(max(0.1, t_start + seconds - time.monotonic()))
    finally:
        stop.set()
        feed.join(1.0)
        loop.stop()
        status = loop.status()
        dev_max = sim.forces.max_magnitude if sim is not None and hasattr(sim, "forces") else None
        dev.close()
    rec = {k: np.array(v, dtype=float) for k, v in loop.recording.items()}
    t = rec["t"]
    periods = np.diff(t)
    jitter = np.abs(periods - 1.0 / cfg.rate_hz) * 1e3
    span = t[-1] - t[0] if t.size > 1 else float("nan")
    # latencies: pose step -> body x; force step -> commanded fx
    pose_first, pose_half = [], []
    for t0, before, after in pose_steps:
        bx_before = loop.map.to_tunnel(before, 0.0)[0]
        bx_after = loop.map.to_tunnel(after, 0.0)[0]
        pose_first.append(_first_crossing(t, rec["body_x"], t0, bx_before, bx_after, 0.01))
        pose_half.append(_first_crossing(t, rec["body_x"], t0, bx_before, bx_after, 0.5))
    force_first, force_half = [], []
    gain = loop.scale.gain
    for t0, before, after in force_steps[:n_steps]:
        fb, fa = before * gain, after * gain
        force_first.append(_first_crossing(t, rec["fx"], t0, fb, fa, 0.05))
        force_half.append(_first_crossing(t, rec["fx"], t0, fb, fa, 0.5))
    largest = float(np.max(np.hypot(rec["fx"], rec["fy"]))) if t.size else 0.0
    return {
        "device": url,
        "device_name": caps.name,
        "device_max_force_N": caps.max_force,
        "seconds": seconds,
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, {_load()} at the end",
        "ticks": int(t.size),
        "rate_hz": float((t.size - 1) / span) if t.size > 1 else 0.0,
        "jitter_ms": {"median": float(np.median(jitter)), "p99": float(np.percentile(jitter, 99)),
                      "max": float(jitter.max())} if jitter.size else None,
        "overruns": status.overruns,
        "scheduling": status.scheduling,
        "latency_pose_to_body_ms": {"first_motion": _stats_ms(pose_first), "half_step": _stats_ms(pose_half)},
        "latency_force_to_command_ms": {"first_response": _stats_ms(force_first),
                                        "half_step": _stats_ms(force_half)},
        "largest_force_commanded_N": largest,
        "largest_force_at_device_N": dev_max,
        "force_within_max": bool(largest <= caps.max_force + 1e-9
                                 and (dev_max is None or dev_max <= caps.max_force + 1e-6)),
        "device_counters": status.device_counters,
        "state_at_end": status.state,
        "disconnect_reason": status.disconnect_reason,
    }


def _busy_python(stop: threading.Event) -> None:
    """An app-like neighbour: a thread running pure-Python work in bursts (GUI handlers,
    solver bookkeeping) that holds the interpreter lock most of the time."""
    while not stop.is_set():
        s = 0
        for i in range(20000):
            s += i
        time.sleep(0.001)


def app_load_comparison(url: str, seconds: float) -> dict:
    """p99 jitter of the loop as a thread and as a child process (haptics.process_loop) while
    a busy Python thread runs in this process; worst one-second window of each."""
    from feelflow.haptics import ForceLoop, ForceSample, LoopConfig, open_device
    from feelflow.haptics.process_loop import ProcessForceLoop

    out = {}
    stop = threading.Event()
    busy = threading.Thread(target=_busy_python, args=(stop,), daemon=True)
    busy.start()
    try:
        for mode in ("thread", "process"):
            if mode == "thread":
                dev = open_device(url)
                loop = ForceLoop(dev, LoopConfig(expected_peak=1.0))
            else:
                dev, loop = None, ProcessForceLoop(url, LoopConfig(expected_peak=1.0))
            loop.start()
            t0 = time.monotonic()
            worst, next_read = 0.0, t0 + 1.1
            while time.monotonic() - t0 < seconds:
                loop.submit_force(ForceSample(0.5, 0.0, time.monotonic()))
                time.sleep(0.01)
                if time.monotonic() >= next_read:  # status: p99 over the last second
                    worst = max(worst, loop.status().jitter_p99_ms)
                    next_read += 0.5
            st = loop.status()
            if dev is not None:
                loop.stop()
                dev.close()
            else:
                loop.close()
            out[mode] = {"rate_hz": float(st.rate_hz), "worst_p99_jitter_ms": float(worst)}
    finally:
        stop.set()
        busy.join(1.0)
    return out


def _fmt(d, key):
    v = d.get(key) if d else None
    return "n/a" if v is None else f"{v:.2f} ms"


def main(args) -> int:
    seconds = args.seconds if args.seconds is not None else 5.0
    if not (math.isfinite(seconds) and seconds >= 1.0):
        raise UserError(f"--seconds must be at least 1, got {seconds}")
    r = run(args.device, seconds)
    r["with_busy_python_thread"] = app_load_comparison(args.device, max(1.6, min(3.0, 0.5 * seconds)))
    j = r["jitter_ms"] or {}
    pl, fl = r["latency_pose_to_body_ms"], r["latency_force_to_command_ms"]
    print(f"haptic loop on {r['device']} ({r['device_name']}), {r['seconds']:.1f} s; {r['machine']}")
    print(f"  rate            {r['rate_hz']:.1f} Hz ({(r['rate_hz'] / 1000 - 1) * 100:+.2f} % of 1 kHz), "
          f"{r['ticks']} ticks, {r['overruns']} overruns, loop thread {r['scheduling']}")
    print(f"  period jitter   median {_fmt(j, 'median')}, p99 {_fmt(j, 'p99')}, max {_fmt(j, 'max')}")
    print(f"  pose -> body    first motion {_fmt(pl['first_motion'], 'median')}, "
          f"half step {_fmt(pl['half_step'], 'median')} (median of steps)")
    print(f"  force -> device first response {_fmt(fl['first_response'], 'median')}, "
          f"half step {_fmt(fl['half_step'], 'median')} (median of steps)")
    dev_max = r["largest_force_at_device_N"]
    print(f"  largest force   {r['largest_force_commanded_N']:.3f} N commanded"
          + (f", {dev_max:.3f} N at the device" if dev_max is not None else "")
          + f" (max {r['device_max_force_N']:.3f} N): {'OK' if r['force_within_max'] else 'EXCEEDED'}")
    print(f"  device counters {r['device_counters']}")
    if r["disconnect_reason"]:
        print(f"  DISCONNECTED during the run: {r['disconnect_reason']}")
    c = r["with_busy_python_thread"]
    print("  next to a busy Python thread (worst 1-s p99 jitter): "
          f"loop as a thread {c['thread']['worst_p99_jitter_ms']:.2f} ms, "
          f"as a child process {c['process']['worst_p99_jitter_ms']:.2f} ms")
    if args.json:
        from feelflow.app.files import save_json

        save_json(args.json, r)
    return 0 if r["force_within_max"] else 1
