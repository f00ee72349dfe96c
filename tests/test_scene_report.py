"""The example scenes' tunnels are calm (app/scene_report.py, docs/science/validation.md 'Calm tunnels'): their outlet
sponge has the window's absorbing layer, which lets the tunnel's sound out after the inflow ramp.
numpy backend, the scenes as `feelflow run` runs them."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from feelflow.app.model.scene import load_scene
from feelflow.app.reports.scenes import SCENES, run_scene_calm
from feelflow.app.model.simulation import default_base_config

ROOT = Path(__file__).resolve().parents[1]


def test_every_example_scene_with_a_sponge_has_the_windows_absorbing_layer():
    window = default_base_config((256, 128)).sponge_absorb
    for name in SCENES:
        cfg = load_scene(ROOT / "scenes" / f"{name}.toml").config
        assert cfg.sponge_cells > 0 and cfg.sponge_absorb == window, name


def test_the_layer_calms_the_classroom_scene_after_its_ramp():
    """The default scene's 1000-step ramp rings the tunnel's quarter-wave mode (period 4 nx / c_s
    = 2771 steps at 400 columns); without the layer the mean velocity near the inlet keeps
    swinging, with it the swing is at least halved (measured over steps 1500 - 3000)."""
    path = ROOT / "scenes" / "default.toml"
    swing = {}
    for without in (False, True):
        r = run_scene_calm(path, without_layer=without, steps=3000)
        assert r["from_step"] == 1550
        swing[without] = r["mean_u_max"] - r["mean_u_min"]
    assert swing[False] < 0.5 * swing[True], swing


def test_report_scenes_refuses_an_unknown_scene_in_one_line():
    r = subprocess.run([sys.executable, "-m", "feelflow.app", "report", "scenes", "--only", "tidal"],
                       capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 2 and "tidal" in r.stderr and len(r.stderr.strip().splitlines()) == 1
