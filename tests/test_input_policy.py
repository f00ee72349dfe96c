"""The input policy (app/inputs.py, shapes/io.py, app/sessions/format.py) and the physical
bounds: each class of bad input a hostile or careless user tried is one line, fast, no
traceback; a flow that leaves the physical range ends the run with exit 1 and only physical rows.
"""
from __future__ import annotations

import csv
import io
import json
import math
import time
import zipfile
import zlib

import numpy as np
import pytest

from feelflow.app.cli.main import main as cli_main
from feelflow.app.errors import UserError
from feelflow.app.model.scene import load_scene, scene_from_dict
from feelflow.app.sessions import SessionError, load_session
from feelflow.shapes.base import ShapeError
from feelflow.shapes.io import from_dict
from feelflow.app.shape_files import load_shape

from test_file_policy import SCENE, one_error_line

BLOWS_UP = """
[grid]
nx = 64
ny = 32

[flow]
nu = 0.0004
collision = "bgk"
inflow_speed = 0.09
inflow_ramp_steps = 0

[body]
kind = "plate"
length = 12
thickness = 2
angle = 90
x = 20
y = 16

[output]
interval = 10

[run]
steps = 600
"""


def shape_file(tmp_path, text, name="s.json"):
    p = tmp_path / name
    p.write_text(text)
    return p


def wrap(shape) -> str:
    return json.dumps({"format": "feelflow-shape", "version": 1, "shape": shape})


# --- text documents: depth, integers, types -------------------------------------------------------

def test_deep_nesting_and_huge_integers_are_one_line(tmp_path):
    deep = "[" * 100000 + "]" * 100000
    cases = [
        (tmp_path / "a.toml", f"x = {deep}\n", load_scene, UserError, "nested"),
        (tmp_path / "b.toml", "[grid]\nnx = " + "9" * 5000 + "\n", load_scene, UserError, "too large"),
        (tmp_path / "c.json", '{"a": ' + deep + "}", load_shape, ShapeError, "deep"),
        (tmp_path / "d.json", wrap({"kind": "cylinder", "diameter": int("9" * 20)}), load_shape, ShapeError, "large"),
    ]
    for path, text, load, error, words in cases:
        path.write_text(text)
        t0 = time.perf_counter()
        with pytest.raises(error) as info:
            load(path)
        assert time.perf_counter() - t0 < 5
        assert words in str(info.value) and "\n" not in str(info.value), str(info.value)[:200]


@pytest.mark.parametrize("shape,words", [
    ({"kind": ["cylinder"], "diameter": 10}, "kind must be one of"),
    ({"kind": "cylinder", "diameter": "32"}, "must be a number, got text"),
    ({"kind": "cylinder", "diameter": True}, "true/false"),
    ({"kind": "cylinder", "diameter": 10, "x": False}, "true/false"),
    ({"kind": "polygon", "vertices": [[0, 0], [True, 0], [0, 5]]}, "number pairs"),
    ({"kind": "polygon", "vertices": [["1", 0], [5, 0], [0, 5]]}, "number pairs"),
    ({"kind": "polygon", "vertices": [[k % 50, k // 50] for k in range(2000)]}, "at most"),
])
def test_shapes_have_strict_types_and_bounded_vertices(tmp_path, shape, words):
    t0 = time.perf_counter()
    with pytest.raises(ShapeError) as info:
        load_shape(shape_file(tmp_path, wrap(shape)))
    assert time.perf_counter() - t0 < 5
    assert words in str(info.value) and "\n" not in str(info.value), info.value
    with pytest.raises(ShapeError):
        from_dict(shape)


def test_a_polygon_of_100000_vertices_is_refused_at_once(tmp_path):
    vertices = [[50 + 20 * math.cos(t * 2 * math.pi / 1e5), 50 + 20 * math.sin(t * 2 * math.pi / 1e5)]
                for t in range(100000)]
    t0 = time.perf_counter()
    with pytest.raises(ShapeError, match="at most"):
        from_dict({"kind": "polygon", "vertices": vertices})
    with pytest.raises(ShapeError, match="more than a shape file can be"):
        load_shape(shape_file(tmp_path, wrap({"kind": "polygon", "vertices": vertices})))
    assert time.perf_counter() - t0 < 5


def test_scene_bounds_and_ignored_settings(tmp_path):
    base = {"grid": {"nx": 64, "ny": 32}, "body": {"kind": "cylinder", "diameter": 6, "x": 20, "y": 16},
            "run": {"steps": 10}}
    bad = [
        ({"flow": {"body_force": [0.5, 0.0]}}, "flow.body_force"),
        ({"flow": {"x_boundary": "periodic", "inflow_speed": 0.05}}, "flow.inflow_speed: has no effect"),
        ({"flow": {"x_boundary": "periodic", "sponge_cells": 4}}, "flow.sponge_cells: has no effect"),
        ({"flow": {"sponge_absorb": 0.1}}, "flow.sponge_absorb: has no effect without an absorbing layer"),
        ({"flow": {"collision": "bgk", "trt_magic": 0.25}}, "flow.trt_magic: has no effect"),
        ({"run": {"steps": 10 ** 9}}, "run.steps"),
        ({"grid": {"nx": 8192, "ny": 8192}}, "nodes"),
        ({"body": {"kind": "cylinder", "diameter": "6", "x": 20, "y": 16}}, "body.diameter"),
        ({"body": {"kind": ["cylinder"], "diameter": 6, "x": 20, "y": 16}}, "body.kind"),
        ({"body": {"kind": "cylinder", "diameter": 6, "x": True, "y": 16}}, "body.x"),
    ]
    for change, words in bad:
        with pytest.raises(UserError) as info:
            scene_from_dict({**base, **change}, "s.toml")
        assert words in str(info.value) and "\n" not in str(info.value), (change, info.value)
    scene_from_dict({**base, "flow": {"x_boundary": "periodic", "body_force": [1e-5, 0.0]}}, "s.toml")


def test_steps_beyond_the_motion_script_are_refused_before_the_run(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text(SCENE.replace("[run]", "[[motion]]\nsteps = 5000\nvelocity = [0.05, 0.0]\n\n[run]"))
    assert cli_main(["run", str(scene), "--out", str(tmp_path / "f.csv"), "--steps", "2000"]) == 2
    assert "leaves the domain" in one_error_line(capsys.readouterr().err)
    assert not (tmp_path / "f.csv").exists()


def test_validate_impossible_resolution_is_one_line(capsys):
    for res in ("1", "100000"):
        assert cli_main(["validate", "--case", "poiseuille", "--quick", "--resolution", res]) == 2
        one_error_line(capsys.readouterr().err)


# --- sessions -------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def good(tmp_path_factory):
    folder = tmp_path_factory.mktemp("good")
    scene = folder / "s.toml"
    scene.write_text(SCENE)
    assert cli_main(["run", str(scene), "--out", str(folder / "f.csv"), "--record", str(folder / "g.ffsession")]) == 0
    with zipfile.ZipFile(folder / "g.ffsession") as zf:
        return {n: zf.read(n) for n in zf.namelist()}


def write_session(path, members, compress=zipfile.ZIP_STORED):
    with zipfile.ZipFile(path, "w", compression=compress) as zf:
        for n, b in members.items():
            zf.writestr(n, b)
    return path


def npy(array) -> bytes:
    buf = io.BytesIO()
    np.save(buf, array)
    return buf.getvalue()


def crafted_npz(name: str, header_shape) -> bytes:
    """An .npz whose one entry's .npy header claims `header_shape` float64 but holds 8 bytes."""
    head = np.lib.format.header_data_from_array_1_0(np.zeros(1))
    head["shape"] = header_shape
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, head)
    buf.write(b"\0" * 8)
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w") as zf:
        zf.writestr(name + ".npy", buf.getvalue())
    return out.getvalue()


def test_bad_sessions_are_refused_fast_in_one_line(good, tmp_path):
    manifest = json.loads(good["manifest.json"])
    many_steps = json.loads(good["manifest.json"])
    many_steps["counts"]["steps"] = 10 ** 9
    many_rows = json.loads(good["manifest.json"])
    many_rows["counts"]["forces"] = 10 ** 8
    deep = b'{"a": ' + b"[" * 100000 + b"]" * 100000 + b"}"
    cases = {
        "plain_npy": ({**good, "forces.npz": npy(np.zeros(3))}, "not an .npz"),
        "terabytes": ({**good, "forces.npz": crafted_npz("values", (10 ** 7, 10 ** 6))}, "declares shape"),
        "steps_1e9": ({**good, "manifest.json": json.dumps(many_steps).encode()}, "counts.steps"),
        "rows_1e8": ({**good, "manifest.json": json.dumps(many_rows).encode()}, "counts.forces"),
        "deep_json": ({**good, "parameters.json": deep}, "nested"),
        "huge_int": ({**good, "manifest.json": json.dumps({**manifest, "version": 10 ** 30}).encode()}, "too large"),
    }
    for name, (members, words) in cases.items():
        path = write_session(tmp_path / f"{name}.ffsession", members)
        t0 = time.perf_counter()
        with pytest.raises(SessionError) as info:
            load_session(path)
        assert time.perf_counter() - t0 < 5, name
        assert words in str(info.value) and "\n" not in str(info.value), (name, info.value)


def malformed_header_npz(name: str) -> bytes:
    """An .npz whose entry's .npy header is cut off inside a bracket (numpy's header parser
    raises tokenize.TokenError on it)."""
    head = b"{'descr': '<f8', 'fortran_order': False, 'shape': (3,"
    head += b" " * (64 - 10 - len(head) - 1) + b"\n"
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w") as zf:
        zf.writestr(name + ".npy", b"\x93NUMPY\x01\x00" + len(head).to_bytes(2, "little") + head + bytes(24))
    return out.getvalue()


def test_session_leftovers_are_one_line(good, tmp_path, capsys):
    """A malformed .npy header (`session info`), a recorded rebuild to 8192 x 8192 (`session
    replay`) and `run /proc/self/mem`: one line and exit 2 each."""
    bad_header = write_session(tmp_path / "header.ffsession", {**good, "forces.npz": malformed_header_npz("values")})
    params = json.loads(good["parameters.json"])
    manifest = json.loads(good["manifest.json"])
    config = dict(manifest["scene"]["config"], nx=8192, ny=8192)
    params.append({"seq": 10 ** 6, "step": 0, "name": "rebuild", "value": {"config": config, "keep_flow": False}})
    manifest["counts"]["parameters"] = len(params)
    rebuild = write_session(tmp_path / "rebuild.ffsession", {**good, "parameters.json": json.dumps(params).encode(),
                                                             "manifest.json": json.dumps(manifest).encode()})
    for argv, words in [(["session", "info", str(bad_header)], "not a readable .npz"),
                        (["session", "replay", str(rebuild)], "more than 4194304"),
                        (["run", "/proc/self/mem", "--out", str(tmp_path / "f.csv")], "cannot be read")]:
        t0 = time.perf_counter()
        assert cli_main(argv) == 2, argv
        err = capsys.readouterr().err
        assert time.perf_counter() - t0 < 10
        assert err.count("\n") == 1 and words in err and "Traceback" not in err, (argv, err)


def test_a_zip_bomb_is_refused_before_it_inflates(good, tmp_path):
    """64 MB of zeros deflate to about 64 KB; the forces member may hold a few KB here."""
    path = write_session(tmp_path / "bomb.ffsession", {**good, "forces.npz": bytes(64 << 20)},
                         compress=zipfile.ZIP_DEFLATED)
    assert path.stat().st_size < 1 << 20
    with pytest.raises(SessionError, match="bytes uncompressed"):
        load_session(path)
    # a member whose header lies about its size is cut off at the bound while inflating
    raw = bytearray(path.read_bytes())
    with zipfile.ZipFile(path) as zf:
        info = zf.getinfo("forces.npz")
    lie = (1000).to_bytes(4, "little")
    start = raw.find(b"forces.npz")                      # local header: sizes at offsets 18..25 before the name
    raw[start - 30 + 22:start - 30 + 26] = lie
    central = raw.rfind(b"forces.npz")                   # central directory entry: sizes at 20..27
    raw[central - 46 + 24:central - 46 + 28] = lie
    liar = tmp_path / "liar.ffsession"
    liar.write_bytes(bytes(raw))
    with pytest.raises(SessionError) as exc:
        load_session(liar)
    assert "\n" not in str(exc.value)
    assert info.file_size == 64 << 20


# --- divergence: the physical range ---------------------------------------------------------------

def physical_rows(path):
    with open(path) as fh:
        rows = list(csv.DictReader(fh))
    for row in rows:
        for k, v in row.items():
            assert math.isfinite(float(v)) and (k in ("step", "x", "y") or abs(float(v)) < 10), (k, v)
    return rows


@pytest.mark.parametrize("backend", ["numpy", pytest.param("gl", marks=pytest.mark.gl)])
def test_a_run_that_leaves_the_physical_range_exits_1_with_physical_rows_only(backend, tmp_path, capsys, request):
    if backend == "gl":
        request.getfixturevalue("gl_context")
    scene = tmp_path / "blow.toml"
    scene.write_text(BLOWS_UP)
    out, session = tmp_path / "f.csv", tmp_path / "s.ffsession"
    assert cli_main(["run", str(scene), "--backend", backend, "--out", str(out), "--record", str(session)]) == 1
    err = capsys.readouterr().err
    last = err.strip().splitlines()[-1]
    assert "diverged" in last and "far" in last and "Traceback" not in err, err   # caught before NaN
    rows = physical_rows(out)
    assert 0 < len(rows) < 60
    # the replay diverges too: exit 1, and its CSV keeps only the physical rows
    replayed = tmp_path / "r.csv"
    assert cli_main(["session", "replay", str(session), "--backend", backend, "--out", str(replayed)]) == 1
    assert "diverged" in one_error_line(capsys.readouterr().err)
    assert len(physical_rows(replayed)) == len(rows)


def test_check_physical_flags_speed_and_density_on_a_finite_field():
    from feelflow.solver.backend import SolverDiverged, create_solver
    from feelflow.solver.config import FlowConfig
    from feelflow.solver.lattice import C, W

    cfg = FlowConfig(nx=16, ny=8, x_boundary="periodic", y_boundary="periodic", inflow_speed=0.0)
    s = create_solver("numpy", cfg)
    s.check_physical()   # fluid at rest: fine
    for rho, u in ((1.0, 0.6), (2.0, 0.0)):
        cu = 3 * (C[:, 0] * u)
        feq = (W * rho * (1 + cu + 0.5 * cu ** 2 - 1.5 * u * u))[:, None, None] * np.ones((9, 8, 16))
        s.set_distributions(feq)
        s.time += 1
        with pytest.raises(SolverDiverged, match="far"):
            s.check_physical()


def test_a_session_solver_checking_every_n_steps_still_catches_a_flow_out_of_range():
    """The window checks the range once every PHYSICAL_CHECK_STEPS steps (SessionSolver.check_every);
    the default checks after every step call."""
    from feelflow.app.sessions import SessionSolver
    from feelflow.solver.backend import SolverDiverged, create_solver
    from feelflow.solver.config import FlowConfig
    from feelflow.solver.lattice import C, W

    backend = create_solver("numpy", FlowConfig(nx=16, ny=8, x_boundary="periodic", y_boundary="periodic",
                                                inflow_speed=0.0))
    checked, check = [], backend.check_physical
    backend.check_physical = lambda: (checked.append(backend.time), check())[1]
    ss = SessionSolver(backend)
    ss.step(1)
    ss.step(2)
    ss.check_physical()   # nothing new since the last check
    assert checked == [1, 3]
    ss.check_every = 8
    for _ in range(20):
        ss.step(1)
    assert checked == [1, 3, 11, 19]
    u = 0.6   # a uniform stream far above the Mach limit: finite, it stays so in a periodic box
    cu = 3 * (C[:, 0] * u)
    backend.set_distributions((W * (1 + cu + 0.5 * cu ** 2 - 1.5 * u * u))[:, None, None] * np.ones((9, 8, 16)))
    with pytest.raises(SolverDiverged, match="far"):
        for _ in range(8):
            ss.step(1)
    assert backend.time == 27 and checked[-1] == 27
