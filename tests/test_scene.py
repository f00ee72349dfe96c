"""Scene files: the examples load, keys mean what docs/reference/scenes.md says, bad values name their key."""
import math
import pathlib

import pytest

from feelflow.app.errors import UserError
from feelflow.app.model.scene import load_scene, scene_from_dict
from feelflow.solver.motion import MotionScript, Phase

ROOT = pathlib.Path(__file__).resolve().parents[1]
SCENES = sorted((ROOT / "scenes").rglob("*.toml"))


def minimal(**sections):
    d = {"grid": {"nx": 200, "ny": 80},
         "flow": {"nu": 0.02, "inflow_speed": 0.05},
         "body": {"kind": "cylinder", "diameter": 10, "x": 50, "y": 40},
         "run": {"steps": 100}}
    for k, v in sections.items():
        if v is None:
            d.pop(k)
        else:
            d[k] = v
    return d


@pytest.mark.parametrize("path", SCENES, ids=[str(p.relative_to(ROOT / "scenes")) for p in SCENES])
def test_example_scenes_load(path):
    scene = load_scene(path)
    assert scene.steps >= 1 and scene.config.nu > 0


def test_examples_cover_every_shape_kind():
    from feelflow.shapes.io import KINDS

    kinds = {load_scene(p).body.kind for p in SCENES}
    assert kinds == set(KINDS)


def test_reynolds_sets_viscosity_from_frontal_size_and_inflow_speed():
    flow = {"reynolds": 100, "inflow_speed": 0.05}
    scene = scene_from_dict(minimal(flow=flow))
    assert scene.reference_length == pytest.approx(10)
    assert scene.config.nu == pytest.approx(0.05 * 10 / 100)
    assert scene.reynolds == pytest.approx(100)


def test_reynolds_without_inflow_uses_the_motion_speed():
    d = minimal(flow={"reynolds": 50, "inflow_speed": 0.0}, motion=[{"steps": 100, "velocity": [0.04, 0]}])
    assert scene_from_dict(d).config.nu == pytest.approx(0.04 * 10 / 50)


def test_angles_are_degrees():
    body = {"kind": "wedge", "length": 20, "apex_angle": 60, "x": 50, "y": 40, "angle": 90}
    shape = scene_from_dict(minimal(body=body)).body
    assert shape.apex_angle == pytest.approx(math.pi / 3)
    assert shape.angle == pytest.approx(math.pi / 2)


def test_motion_phases_stop_with_against_and_defaults():
    d = minimal(motion=[{"steps": 10, "move": "stop"}, {"steps": 20, "move": "with"},
                        {"steps": 5, "move": "against", "speed": 0.02}], run=None)
    scene = scene_from_dict(d)
    assert scene.steps == 35
    assert [p.velocity for p in scene.motion.phases] == [(0.0, 0.0), (0.05, 0.0), (-0.02, 0.0)]


def test_motion_script_velocity_and_displacement():
    s = MotionScript([Phase(10, (0.0, 0.0)), Phase(20, (0.05, 0.0)), Phase(5, (-0.02, 0.01))])
    assert s.velocity_at(9) == (0.0, 0.0) and s.velocity_at(10) == (0.05, 0.0)
    assert s.velocity_at(35) == (0.0, 0.0)  # after the script: at rest
    assert s.displacement(30) == pytest.approx((1.0, 0.0))
    assert s.displacement(100) == pytest.approx((0.9, 0.05))
    assert s.steps_left_in_phase(12) == 18 and s.steps_left_in_phase(40) is None


BAD = [
    ({"body": {"kind": "cylinder", "diameter": -3, "x": 50, "y": 40}}, "body.diameter: must be a positive number, got -3"),
    ({"body": {"kind": "cylinder", "diameter": 10, "x": 50, "y": 40, "colour": 1}}, "body.colour: unknown key"),
    ({"body": {"kind": "circle", "diameter": 10, "x": 50, "y": 40}}, "body.kind: must be one of"),
    ({"body": {"kind": "cylinder", "x": 50, "y": 40}}, "body.diameter: missing"),
    ({"body": {"kind": "cylinder", "diameter": 10, "x": 500, "y": 40}}, "body"),
    ({"body": {"kind": "polygon", "vertices": [[0, 0], [1, 1]], "x": 50, "y": 40}}, "body.vertices"),
    ({"body": {"kind": "polygon", "vertices": [[0, 0], [10, 10], [10, 0], [0, 10]], "x": 50, "y": 40}},
     "body.vertices"),
    ({"grid": {"nx": 4, "ny": 80}}, "grid.nx: must be an integer in 8..8192, got 4"),
    ({"grid": {"nx": 200.5, "ny": 80}}, "grid.nx: must be an integer"),
    ({"grid": {"nx": 200, "ny": 80, "nz": 3}}, "grid.nz: unknown key"),
    ({"flow": {"nu": 0.02, "reynolds": 100}}, "flow.reynolds: give either flow.nu or flow.reynolds"),
    ({"flow": {"nu": -1}}, "flow.nu: must be a positive number"),
    ({"flow": {"nu": 1e-9}}, "flow.nu: too small"),
    ({"flow": {"reynolds": 1e9}}, "flow.reynolds: gives nu"),
    ({"flow": {"inflow_speed": 0.5}}, "flow.inflow_speed: 0.5 exceeds the Mach limit"),
    ({"flow": {"walls": "sticky"}}, "flow.walls: must be one of no_slip, free_slip, periodic"),
    ({"flow": {"collision": "mrt"}}, "flow.collision: must be one of bgk, trt"),
    ({"flow": {"equilibrium": "ideal_gas"}}, "flow.equilibrium: must be one of compressible, incompressible"),
    ({"flow": {"inflow_profile": "plug"}}, "flow.inflow_profile"),
    ({"flow": {"sponge_cells": 150}}, "flow.sponge_cells"),
    ({"flow": {"sponge_cells": 20, "sponge_absorb": 0.9}}, "flow.sponge_absorb: must be in 0..0.5, got 0.9"),
    ({"flow": {"viscosity": 0.1}}, "flow.viscosity: unknown key"),
    ({"output": {"forces": ["telepathy"]}}, "output.forces: unknown force model 'telepathy'"),
    ({"output": {"interval": 0}}, "output.interval: must be an integer >= 1, got 0"),
    ({"run": {"steps": "many"}}, "run.steps: must be an integer"),
    ({"run": {"steps": 100, "backend": "cuda"}}, "run.backend: must be one of cpu, gl, numpy"),
    ({"run": None}, "run.steps: missing (required)"),
    ({"grid": None}, "grid: missing (required)"),
    ({"extras": {"a": 1}}, "extras: unknown key"),
    ({"motion": [{"steps": 10, "move": "sideways"}]}, "motion[0].move: must be one of stop, with, against"),
    ({"motion": [{"steps": 0, "move": "stop"}]}, "motion[0].steps: must be an integer >= 1, got 0"),
    ({"motion": [{"steps": 10, "velocity": [1.0, 0]}]}, "motion[0]: body speed 1 exceeds the Mach limit"),
    ({"motion": [{"steps": 10, "velocity": [0.05]}]}, "motion[0].velocity: must be two finite numbers"),
    ({"motion": [{"steps": 5000, "move": "with"}], "run": None}, "motion: the body leaves the domain"),
    ({"motion": {"steps": 10}}, "motion: must be a list of phases"),
]


@pytest.mark.parametrize("change,message", BAD, ids=[m.split(":")[0] for _, m in BAD])
def test_bad_values_name_their_key_in_one_line(change, message):
    with pytest.raises(UserError) as info:
        scene_from_dict(minimal(**change), "scene.toml")
    text = str(info.value)
    assert "\n" not in text
    assert text.startswith("scene.toml: " + message.split(":")[0])
    assert message in text, text


def test_missing_and_malformed_files(tmp_path):
    with pytest.raises(UserError, match="no such scene file"):
        load_scene(tmp_path / "nope.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[grid\nnx = 3\n")
    with pytest.raises(UserError, match="bad.toml: not valid TOML"):
        load_scene(bad)


def test_equilibrium_key_reaches_the_solver_config():
    scene = scene_from_dict(minimal(flow={"equilibrium": "incompressible"}), "scene.toml")
    assert scene.config.equilibrium == "incompressible"
    assert scene_from_dict(minimal(), "scene.toml").config.equilibrium == "compressible"


def test_an_oscillating_phase_is_duetschs_motion():
    """`amplitude` and `period` add A sin(2 pi k / T) to a phase (docs/reference/scenes.md): the
    positions follow it exactly, each step's velocity is what the pose moves in that step, the
    reference speed for `reynolds` is the peak speed 2 pi |A| / T, and the path check sees the
    turning points."""
    A, T = 3.0, 400
    scene = scene_from_dict(minimal(flow={"inflow_speed": 0.0, "reynolds": 100},
                                    motion=[{"steps": 800, "amplitude": [-A, 0.0], "period": T}]))
    script = scene.motion
    for k in (0, 37, 100, 250, 799):
        assert script.displacement(k)[0] == pytest.approx(-A * math.sin(2 * math.pi * k / T), abs=1e-12)
        v = script.velocity_at(k)[0]
        assert v == pytest.approx(script.displacement(k + 1)[0] - script.displacement(k)[0], abs=1e-15)
    assert scene.reference_speed == pytest.approx(2 * math.pi * A / T)
    assert scene.config.nu == pytest.approx(2 * math.pi * A / T * 10 / 100)
    assert min(dx for _, (dx, _) in script.extreme_displacements(800)) == pytest.approx(-A, abs=1e-3)
    with pytest.raises(UserError, match="leaves the domain"):
        scene_from_dict(minimal(run=None, motion=[{"steps": 4000, "amplitude": [-45.0, 0.0], "period": 4000}]))
    with pytest.raises(UserError, match=r"motion\[0\].period.*both amplitude"):
        scene_from_dict(minimal(motion=[{"steps": 400, "amplitude": [-3.0, 0.0]}]))
    with pytest.raises(UserError, match="Mach limit"):
        scene_from_dict(minimal(motion=[{"steps": 400, "amplitude": [-30.0, 0.0], "period": 100}]))


def test_a_tunnel_scene_without_boundary_keys_gets_the_quiet_tunnel():
    """docs/reference/scenes.md 'Quiet by default': the window's sponge, absorbing layer and quiet
    inlet; the quiet inlet only where the ramp allows it (at least 2 nx / c_s steps, or none);
    naming any boundary key gives exactly what the scene says."""
    quiet = scene_from_dict(minimal()).config
    assert (quiet.sponge_cells, quiet.sponge_absorb, quiet.inlet_nonreflecting) == (32, 0.1, 0.001)
    long_tunnel = scene_from_dict(minimal(grid={"nx": 600, "ny": 80})).config   # 1000-step ramp < 2078
    assert (long_tunnel.sponge_cells, long_tunnel.inlet_nonreflecting) == (32, 0.0)
    windy = scene_from_dict(minimal(grid={"nx": 600, "ny": 80},
                                    flow={"nu": 0.02, "inflow_speed": 0.05, "inflow_ramp_steps": 0})).config
    assert windy.inlet_nonreflecting == 0.001
    bare = scene_from_dict(minimal(flow={"nu": 0.02, "inflow_speed": 0.05, "sponge_cells": 0})).config
    assert (bare.sponge_cells, bare.sponge_absorb, bare.inlet_nonreflecting) == (0, 0.0, 0.0)
    periodic = scene_from_dict(minimal(flow={"nu": 0.02, "x_boundary": "periodic"})).config
    assert periodic.sponge_cells == 0 and periodic.inlet_nonreflecting == 0.0
