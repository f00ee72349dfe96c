"""`feelflow report seed`: the whole chain (scenes -> runs -> analysis -> plots -> Markdown) in its
--quick smoke mode, and its errors for a user."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def feelflow(*args, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "feelflow.app", *args], cwd=cwd, capture_output=True, text=True, timeout=600)


def test_quick_report_writes_markdown_and_plots(tmp_path):
    r = feelflow("report", "seed", "--quick", "--out", str(tmp_path))
    assert r.returncode == 0, r.stderr
    text = (tmp_path / "seed-report.md").read_text()
    for heading in ("protocol", "frontal area", "relative speed", "per shape", "Lift", "Each model, measured"):
        assert heading in text
    assert "--quick smoke run" in text
    for model in ("momentum_exchange", "momentum_exchange_classic", "macroscopic", "pressure"):
        assert f"**{model}**" in text
        png = tmp_path / "seed-report" / f"protocol_{model}.png"
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    for name in ("drag_vs_speed.png", "drag_per_shape.png", "lift.png"):
        assert (tmp_path / "seed-report" / name).stat().st_size > 1000
    # --replot rebuilds from the stored series without running
    (tmp_path / "seed-report.md").unlink()
    r = feelflow("report", "seed", "--replot", "--out", str(tmp_path))
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "seed-report.md").read_text() == text


def test_report_errors_are_one_line_exit_2(tmp_path):
    for args, needle in ((("--only", "bogus"), "--only"), (("--replot",), "no stored experiment data"),
                         (("--phase-steps", "-3"), "--phase-steps"), (("--out", str(tmp_path / "nope")), "--out")):
        out = args if "--out" in args else (*args, "--out", str(tmp_path))
        r = feelflow("report", "seed", *out)
        assert r.returncode == 2, (args, r.stderr)
        assert needle in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
