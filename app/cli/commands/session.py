"""`feelflow session info|replay|export|render FILE`: look into, re-simulate, export a session
file, or render its replay to a video (MP4 or animated GIF, without a window: app/gui/video_export.py
paints offscreen, PyAV encodes).

Format: docs/reference/session-format.md. A bad file is one line on stderr and exit 2 (app.cli.UserError).
`replay --check` exits 1 when the replay deviates from the recorded forces by more than
`--tolerance` (relative to the largest recorded force).
"""
from __future__ import annotations

import json
import math
import sys

import numpy as np

from feelflow.app.errors import UserError
from feelflow.app.files import check_output


def add_arguments(parser):
    sub = parser.add_subparsers(dest="action", metavar="ACTION", required=True)
    p = sub.add_parser("info", help="print what a session file holds")
    p.add_argument("file", metavar="FILE")
    p.add_argument("--json", action="store_true", help="print the whole manifest as JSON")
    p = sub.add_parser("replay", help="re-simulate a session and compare with the recorded forces")
    p.add_argument("file", metavar="FILE")
    p.add_argument("--backend", default=None, metavar="numpy|gl", help="backend (default: the recorded one)")
    p.add_argument("--out", default=None, metavar="PATH", help="write the replayed forces as CSV")
    p.add_argument("--check", action="store_true",
                   help="exit 1 unless the replay reproduces the recorded forces within --tolerance")
    p.add_argument("--tolerance", default="1e-12", metavar="REL",
                   help="--check: largest deviation relative to the largest recorded force (default 1e-12)")
    p.add_argument("--force", action="store_true",
                   help="replace --out if it exists (never the session itself)")
    p = sub.add_parser("export", help="write the recorded force series as CSV and/or the manifest as JSON")
    p.add_argument("file", metavar="FILE")
    p.add_argument("--csv", default=None, metavar="PATH", help="the force series (columns as `feelflow run`)")
    p.add_argument("--manifest", default=None, metavar="PATH", help="the manifest as JSON")
    p.add_argument("--force", action="store_true",
                   help="replace --csv / --manifest if they exist (never the session itself)")
    p = sub.add_parser("render", help="replay a session into a video file (MP4 or animated GIF), no window needed")
    p.add_argument("file", metavar="FILE")
    p.add_argument("--out", default=None, metavar="CLIP.mp4|CLIP.gif", help="the video to write (.mp4 or .gif; required)")
    p.add_argument("--steps-per-frame", default="50", metavar="N",
                   help="solver steps replayed between two frames (default 50)")
    p.add_argument("--fps", default="25", metavar="F", help="frames per second of the video (default 25)")
    p.add_argument("--width", default="960", metavar="PX", help="width of the picture in pixels (default 960)")
    p.add_argument("--show", default="speed", choices=("speed", "vorticity", "pressure"),
                   help="what the colours show (default speed)")
    p.add_argument("--backend", default=None, metavar="numpy|cpu|gl", help="backend (default: the recorded one)")
    p.add_argument("--force", action="store_true", help="replace --out if it exists (never the session itself)")


def _load(path):
    from feelflow.app.sessions import SessionError, load_session

    try:
        return load_session(path)
    except SessionError as exc:
        raise UserError(str(exc)) from None


def _write(fn, *args):
    from feelflow.app.sessions import SessionError

    try:
        return fn(*args)
    except SessionError as exc:
        raise UserError(str(exc)) from None


def _make_factory(backend: str):
    """Backends by name for the replay, through `feelflow.app.headless.make_solver` (gl gets the
    process's EGL context); UserError (one line) when the backend cannot run here."""
    from feelflow.app.headless import make_solver

    def factory(config):
        return make_solver(backend, config)
    return factory


def info(args) -> int:
    s = _load(args.file)
    m = s.manifest
    if args.json:
        print(json.dumps(m, indent=2))
        return 0
    c, counts = s.config, m["counts"]
    body = s.body.to_dict() if s.body is not None else None
    kind = body.pop("kind") if body else "none"
    body_text = kind + (" " + ", ".join(f"{k}={v}" for k, v in body.items() if k != "vertices") if body else "")
    print(f"{args.file}: FeelFlow session, format version {m['version']} (FeelFlow {m['feelflow_version']})")
    print(f"  created   {m['created']}")
    print(f"  backend   {m['backend']} (renderer: {m['renderer']})")
    print(f"  scene     {m['scene'].get('source') or '(no file)'}: grid {c.nx} x {c.ny}, nu {c.nu:g}, "
          f"{c.collision}, inflow {c.inflow_speed:g} ({c.inflow_profile}), walls {c.y_boundary}")
    print(f"  body      {body_text}")
    print(f"  forces    {', '.join(s.models) or 'none'}")
    start = "from the scene's initial flow" if s.start is None else \
        f"from a running flow at solver step {s.start['time']} (state saved)"
    print(f"  recorded  {counts['steps']} steps {start}: {counts['inputs']} input samples, "
          f"{counts['parameters']} parameter changes, {counts['forces']} force rows")
    return 0


def replay(args) -> int:
    from feelflow.app.sessions import SessionError, export_csv, replay as run_replay
    from feelflow.app.sessions.replay import check_replay_memory

    try:
        tolerance = float(args.tolerance)
    except ValueError:
        raise UserError(f"--tolerance: must be a number, got {args.tolerance!r}") from None
    if not tolerance >= 0 or not math.isfinite(tolerance):
        raise UserError(f"--tolerance: must be a finite number, zero or positive, got {args.tolerance!r}")
    if args.out:
        check_output(args.out, "--out", inputs=[args.file], force=args.force)
    s = _load(args.file)
    try:
        check_replay_memory(s, args.file)
    except SessionError as exc:
        raise UserError(str(exc)) from None
    backend = args.backend or s.backend
    factory = _make_factory(backend)
    try:
        result = run_replay(s, backend, factory=factory)
    except SessionError as exc:
        raise UserError(str(exc)) from None
    rows = None
    if result.diverged_at is not None:   # rows after the last physical one are dropped
        rows = int(np.count_nonzero(s.forces["step"] < result.diverged_at))
    if args.out:
        _write(export_csv, s, args.out, result.values, rows, result.torques)
    same = "same backend" if backend == s.backend else f"recorded on {s.backend}"
    print(f"{args.file}: replayed {s.steps} steps on {backend} ({same}); largest force deviation "
          f"{result.max_deviation:.3g} ({result.relative_deviation:.3g} of the largest recorded force "
          f"{result.max_force:.4g})" + (f"; wrote {args.out}" if args.out else ""))
    if result.diverged_at is not None:
        kept = f"; the {rows} rows before it are in {args.out}" if args.out else ""
        print(f"feelflow: the replay diverged at step {result.diverged_at} (the flow left the physical "
              f"range){kept}", file=sys.stderr)
        return 1
    if args.check and not result.relative_deviation <= tolerance:
        print(f"feelflow: replay check failed: relative deviation {result.relative_deviation:.3g} "
              f"> tolerance {tolerance:g}", file=sys.stderr)
        return 1
    return 0


def export(args) -> int:
    from feelflow.app.sessions import export_csv, export_manifest

    if not args.csv and not args.manifest:
        raise UserError("session export: give --csv PATH and/or --manifest PATH")
    if args.csv:
        check_output(args.csv, "--csv", inputs=[args.file], force=args.force)
    if args.manifest:
        check_output(args.manifest, "--manifest", inputs=[args.file], others=[args.csv], force=args.force)
    s = _load(args.file)
    if args.csv:
        _write(export_csv, s, args.csv)
        print(f"{args.csv}: {len(s.forces['step'])} rows, columns step,x,y,vx,vy + fx/fy, then torque, for {', '.join(s.models) or 'no model'}")
    if args.manifest:
        _write(export_manifest, s, args.manifest)
        print(f"{args.manifest}: manifest")
    return 0


def main(args) -> int:
    return {"info": info, "replay": replay, "export": export, "render": render}[args.action](args)


def _number(option, text, lo, integer=False):
    try:
        value = int(text) if integer else float(text)
    except ValueError:
        raise UserError(f"{option}: must be {'a whole number' if integer else 'a number'}, got {text!r}") from None
    if not math.isfinite(value) or value < lo:
        raise UserError(f"{option}: must be at least {lo:g}, got {text!r}")
    return value


def render(args) -> int:
    """Replay FILE into a video: headless (Qt's offscreen platform, the numpy canvas's colours)."""
    import os
    import time

    from feelflow.app.video import video_format

    if not args.out:
        raise UserError("session render: give --out CLIP.mp4 (or CLIP.gif), the video to write")
    out = check_output(args.out, "--out", inputs=[args.file], force=args.force)
    video_format(out)
    steps = _number("--steps-per-frame", args.steps_per_frame, 1, integer=True)
    fps = _number("--fps", args.fps, 1)
    width = _number("--width", args.width, 64, integer=True)
    s = _load(args.file)
    backend = args.backend or s.backend
    factory = _make_factory(backend)
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")   # no window: the pictures are painted offscreen
    from PySide6.QtWidgets import QApplication

    app = QApplication.instance() or QApplication(["feelflow"])  # noqa: F841 - QPainter and fonts need it
    from feelflow.app.cli.commands.exercise import ProgressBar
    from feelflow.app.gui.video_export import SessionRender
    from feelflow.app.sessions import SessionError

    start = time.perf_counter()
    try:
        job = SessionRender(s, out, backend=backend, steps_per_frame=steps, fps=fps, width=width,
                            mode=args.show, factory=factory)
        bar = ProgressBar("of the session")
        job.run(progress=lambda f: bar(int(round(1000 * f)), 1000))
    except SessionError as exc:
        raise UserError(str(exc)) from None
    wall = time.perf_counter() - start
    w, h = job.renderer.size
    n = job.frames
    print(f"{out}: {n} frames ({w} x {h}, {fps:g} fps, one every {steps} steps of {s.steps}) replayed on "
          f"{backend}: {1000 * job.seconds / n:.0f} ms a frame ({1000 * job.replay_seconds / n:.0f} ms replaying, "
          f"{1000 * job.draw_seconds / n:.0f} ms drawing, {1000 * job.encode_seconds / n:.0f} ms encoding); "
          f"{wall:.1f} s in all, start-up included")
    return 0
