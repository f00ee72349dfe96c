"""The window's model interface (app/model/tunnel.py): the live `Simulation` and a replay's
`ReplaySimulation` both carry every `TunnelModel` member with the Protocol's call signatures,
and body input reaches the model only through `drive(BodyInput)` (app/model/body_input.py)."""
from __future__ import annotations

import ast
import inspect
import math
import pathlib

import pytest

from feelflow.app.model.body_input import BodyInput
from feelflow.app.model.replay_simulation import ReplaySimulation
from feelflow.app.model.simulation import Params, Simulation
from feelflow.app.model.tunnel import TunnelModel
from feelflow.app.sessions import SessionRecorder, SessionSolver, load_session
from feelflow.solver.backend import create_solver
from session_scenes import MODELS, drive_moving_cylinder, small_config, start_body

ROOT = pathlib.Path(__file__).resolve().parents[1]


def protocol_methods() -> dict[str, inspect.Signature]:
    return {name: inspect.signature(value) for name, value in vars(TunnelModel).items()
            if callable(value) and not name.startswith("_")}


def protocol_attributes() -> list[str]:
    return [name for name in TunnelModel.__annotations__ if not name.startswith("_")]


def mismatches(obj) -> list[str]:
    """What `obj` lacks of TunnelModel, or has with another call signature than the Protocol's
    (parameter names, kinds and defaults, self left out)."""
    out = [f"{name}: missing" for name in protocol_attributes() if not hasattr(obj, name)]
    for name, want in protocol_methods().items():
        member = getattr(type(obj), name, None)
        if member is None or not callable(member):
            out.append(f"{name}(): missing")
            continue
        want_params = [(p.name, p.kind, p.default) for p in list(want.parameters.values())[1:]]
        have_params = [(p.name, p.kind, p.default) for p in list(inspect.signature(member).parameters.values())[1:]]
        if want_params != have_params:
            out.append(f"{name}(): {inspect.signature(member)} is not the Protocol's {want}")
    return out


@pytest.fixture(scope="module")
def live():
    sim = Simulation(Params(grid=(96, 48), size=8.0))
    sim.advance(2)
    return sim


@pytest.fixture(scope="module")
def replayed(tmp_path_factory):
    cfg = small_config()
    rec = SessionRecorder(cfg, start_body(), MODELS, scene_toml="# test scene\n")
    drive_moving_cylinder(SessionSolver(create_solver("numpy", cfg), rec), steps=12, extras=False)
    path = tmp_path_factory.mktemp("tunnel") / "run.ffsession"
    rec.save(path)
    sim = ReplaySimulation(load_session(path))
    sim.advance(4)
    yield sim
    sim.close()


def test_the_protocol_declares_what_the_window_reads():
    members = set(protocol_methods()) | set(protocol_attributes())
    for name in ("advance", "drive", "hit", "target_degrees", "relative_wind", "field_rgba", "config", "params",
                 "history", "shape", "pos", "angle", "target"):
        assert name in members


@pytest.mark.parametrize("model", ["live", "replayed"])
def test_both_models_implement_every_member(model, request):
    obj = request.getfixturevalue(model)
    assert mismatches(obj) == []
    assert isinstance(obj, TunnelModel)


def test_the_check_finds_a_missing_member_and_a_changed_signature(live):
    class Lacking:
        def __init__(self, base):
            self.__dict__.update({k: getattr(base, k) for k in protocol_attributes() if k != "history"})

        def advance(self, n: int, extra: int = 0):
            return {}

    found = mismatches(Lacking(live))
    assert "history: missing" in found and "drive(): missing" in found
    assert any(line.startswith("advance(): ") for line in found)


def test_drive_pulls_turns_and_lets_go_of_the_live_body():
    sim = Simulation(Params(grid=(96, 48), size=8.0))
    x0, y0 = sim.pos
    assert sim.drive(BodyInput.pull(x0 + 12.0, y0, source="mouse"))
    assert sim.target == (x0 + 12.0, y0)
    for _ in range(20):
        sim.advance(20)
    assert sim.pos[0] > x0 + 6.0 and abs(sim.pos[1] - y0) < 0.5   # the spring pulled it downstream
    assert sim.drive(BodyInput.turn(200.0, source="device"))
    assert sim.target_degrees() == 200.0 and sim.params.angle_deg == pytest.approx(-160.0)
    assert sim.target == (x0 + 12.0, y0)                          # a turn leaves the pull as it was
    assert sim.drive(BodyInput.release("mouse")) and sim.target is None
    with pytest.raises(AttributeError):
        sim.target = (1.0, 1.0)                                   # no way in but drive


def test_a_replay_refuses_body_input(replayed):
    pose = (replayed.pos, replayed.angle)
    assert not replayed.drive(BodyInput.pull(10.0, 10.0, source="mouse"))
    assert not replayed.drive(BodyInput.turn(90.0))
    assert replayed.target is None and (replayed.pos, replayed.angle) == pose
    assert replayed.target_degrees() == pytest.approx(math.degrees(replayed.angle))
    assert replayed.hit(*replayed.pos) and not replayed.hit(1.0, 1.0, tolerance=0.0)


@pytest.mark.parametrize("kwargs, words", [
    ({"source": "keyboard"}, "source must be one of"),
    ({"target": (1.0, 2.0), "let_go": True}, "both pull"),
    ({"target": (math.nan, 2.0)}, "must be finite"),
    ({"angle_deg": math.inf}, "must be finite"),
])
def test_bad_body_input_is_one_line(kwargs, words):
    with pytest.raises(ValueError, match=words) as err:
        BodyInput(**kwargs)
    assert "\n" not in str(err.value)


def test_the_viewport_writes_nothing_into_the_model():
    """The mouse's requests leave the viewport as signals: no assignment to `sim.<anything>`."""
    tree = ast.parse((ROOT / "app" / "gui" / "viewport.py").read_text())
    writes = []
    for node in ast.walk(tree):
        targets = node.targets if isinstance(node, ast.Assign) else \
            [node.target] if isinstance(node, (ast.AugAssign, ast.AnnAssign)) else []
        for t in targets:
            base = t.value if isinstance(t, ast.Attribute) else None
            if (isinstance(base, ast.Attribute) and base.attr == "sim") or (isinstance(base, ast.Name) and base.id == "sim"):
                writes.append(f"line {t.lineno}: {ast.unparse(t)}")
    assert writes == []
