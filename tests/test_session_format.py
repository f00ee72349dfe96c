"""The session file: round trip, and every kind of bad file refused with one line."""
from __future__ import annotations

import io
import json
import os
import zipfile

import numpy as np
import pytest

import feelflow.app.sessions as session_mod
from feelflow.app.sessions.format import VERSION
from feelflow.app.sessions import (FORCES, INPUTS, MANIFEST, PARAMETERS, SessionError, SessionRecorder, SessionSolver,
                         load_session)
from session_scenes import MODELS, drive_moving_cylinder, small_config, start_body
from feelflow.solver.backend import create_solver


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    cfg = small_config()
    rec = SessionRecorder(cfg, start_body(), MODELS, scene_toml="[grid]\nnx = 64\n", scene_source="s.toml",
                          scene_dict={"grid": {"nx": 64, "ny": 32}})
    drive_moving_cylinder(SessionSolver(create_solver("numpy", cfg), rec), steps=12)
    path = tmp_path_factory.mktemp("good") / "good.ffsession"
    rec.save(path)
    return path, rec


def members(path) -> dict:
    with zipfile.ZipFile(path) as zf:
        return {n: zf.read(n) for n in zf.namelist()}


def write_members(path, data: dict):
    with zipfile.ZipFile(path, "w") as zf:
        for n, b in data.items():
            zf.writestr(n, b)


def npz(arrays, **kw) -> bytes:
    buf = io.BytesIO()
    np.savez(buf, **arrays, **kw)
    return buf.getvalue()


def arrays(raw) -> dict:
    with np.load(io.BytesIO(raw)) as z:
        return {k: z[k] for k in z.files}


def refused(path, *words):
    with pytest.raises(SessionError) as info:
        load_session(path)
    msg = str(info.value)
    assert "\n" not in msg and msg.startswith(str(path) + ": ")
    for w in words:
        assert w in msg, msg
    return msg


def test_round_trip(good, tmp_path):
    path, rec = good
    s = load_session(path)
    mem = rec.session()
    assert s.manifest == json.loads(json.dumps(mem.manifest))
    for group in ("inputs", "forces"):
        for k, a in getattr(mem, group).items():
            np.testing.assert_array_equal(getattr(s, group)[k], a)
    assert s.parameters == mem.parameters
    assert s.config == rec.config and s.body == rec.body
    m = s.manifest
    assert (m["format"], m["version"], m["backend"]) == ("feelflow-session", VERSION, "numpy")
    assert m["counts"] == {"inputs": 12, "parameters": len(s.parameters), "forces": 12, "steps": s.steps}
    assert m["scene"]["toml"] == "[grid]\nnx = 64\n" and m["scene"]["dict"]["grid"]["nx"] == 64
    # saving the loaded session again gives the same content
    again = tmp_path / "again.ffsession"
    session_mod.save_session(s, again)
    assert members(again) == members(path)


def test_not_a_zip_truncated_and_missing(good, tmp_path):
    path, _ = good
    raw = path.read_bytes()
    (tmp_path / "text.ffsession").write_text("hello\n")
    refused(tmp_path / "text.ffsession", "not a zip")
    (tmp_path / "cut.ffsession").write_bytes(raw[: len(raw) // 2])
    refused(tmp_path / "cut.ffsession")
    refused(tmp_path / "absent.ffsession", "no such")
    refused(tmp_path, "directory")
    data = members(path)
    del data[FORCES]
    write_members(tmp_path / "missing.ffsession", data)
    refused(tmp_path / "missing.ffsession", FORCES, "missing")


def test_damaged_member(good, tmp_path):
    path, _ = good
    raw = bytearray(path.read_bytes())
    with zipfile.ZipFile(path) as zf:
        info = zf.getinfo(INPUTS)
    # flip bytes inside the compressed data of inputs.npz (after its 30-byte local header + name)
    start = info.header_offset + 30 + len(INPUTS) + len(info.extra) + 5
    for k in range(start, start + 8):
        raw[k] ^= 0xFF
    (tmp_path / "flip.ffsession").write_bytes(bytes(raw))
    refused(tmp_path / "flip.ffsession", INPUTS)


@pytest.mark.parametrize("version, words", [(VERSION + 1, ("written by a newer FeelFlow", f"version {VERSION + 1}")),
                                            (0, ("unknown session format version",)), ("1", ("integer",))])
def test_wrong_version(good, tmp_path, version, words):
    path, _ = good
    data = members(path)
    m = json.loads(data[MANIFEST])
    m["version"] = version
    data[MANIFEST] = json.dumps(m).encode()
    write_members(tmp_path / "v.ffsession", data)
    refused(tmp_path / "v.ffsession", *words)


def test_wrong_format_and_bad_json(good, tmp_path):
    path, _ = good
    data = members(path)
    m = json.loads(data[MANIFEST])
    m["format"] = "something-else"
    write_members(tmp_path / "f.ffsession", {**data, MANIFEST: json.dumps(m).encode()})
    refused(tmp_path / "f.ffsession", "format")
    write_members(tmp_path / "j.ffsession", {**data, MANIFEST: b"{not json"})
    refused(tmp_path / "j.ffsession", MANIFEST, "JSON")
    write_members(tmp_path / "n.ffsession", {**data, PARAMETERS: b"[NaN]"})
    refused(tmp_path / "n.ffsession", PARAMETERS)


def test_pickle_is_refused(good, tmp_path):
    path, _ = good
    data = members(path)
    a = arrays(data[INPUTS])
    a["pose"] = np.array([object()] * len(a["pose"]), dtype=object)
    write_members(tmp_path / "p.ffsession", {**data, INPUTS: npz(a)})
    refused(tmp_path / "p.ffsession", INPUTS, "pickle")


@pytest.mark.parametrize("change, words", [
    (lambda a: a["pose"].__setitem__((3, 0), np.nan), ("non-finite", "pose")),
    (lambda a: a["velocity"].__setitem__((2, 1), np.inf), ("non-finite", "velocity")),
    (lambda a: a["pose"].__setitem__((1, 1), 1e6), ("outside",)),
    (lambda a: a["velocity"].__setitem__((1, 0), 3.0), ("speed",)),
])
def test_bad_inputs(good, tmp_path, change, words):
    path, _ = good
    data = members(path)
    a = arrays(data[INPUTS])
    change(a)
    write_members(tmp_path / "i.ffsession", {**data, INPUTS: npz(a)})
    refused(tmp_path / "i.ffsession", INPUTS, *words)


@pytest.mark.parametrize("edit, words", [
    (lambda a: a.update(step=a["step"].astype(np.float64)), ("'step'", "int64")),
    (lambda a: a.update(body=a["body"][:, :3]), ("'body'", "shape")),
    (lambda a: a.update(n=a["n"][:-1]), ("'n'", "rows")),
    (lambda a: a.pop("values"), ("'values'",)),
    (lambda a: a["n"].__setitem__(2, a["n"][2] + 1), ("row 2",)),
    (lambda a: a["values"].__setitem__((0, 0), np.inf), ("values",)),
])
def test_malformed_force_arrays(good, tmp_path, edit, words):
    path, _ = good
    data = members(path)
    a = arrays(data[FORCES])
    edit(a)
    write_members(tmp_path / "fa.ffsession", {**data, FORCES: npz(a)})
    refused(tmp_path / "fa.ffsession", *words)


@pytest.mark.parametrize("edit, words", [
    (lambda p, m: p[1].update(name="warp"), ("unknown parameter",)),
    (lambda p, m: p[1].update(value=5.0), ("inflow_speed", "-1..1")),
    (lambda p, m: p[0].update(value=["no_such_model"]), ("force_models",)),
    (lambda p, m: m["counts"].update(inputs=3), ("counts.inputs",)),
    (lambda p, m: m["scene"]["config"].update(nu=-1), ("scene.config.nu",)),
    (lambda p, m: m["scene"]["body"].update(diameter=-2), ("scene.body",)),
    (lambda p, m: p[0].update(seq=p[1]["seq"]), ("sequence",)),
])
def test_bad_manifest_or_parameters(good, tmp_path, edit, words):
    path, _ = good
    data = members(path)
    p, m = json.loads(data[PARAMETERS]), json.loads(data[MANIFEST])
    assert p[0]["name"] == "force_models"
    edit(p, m)
    write_members(tmp_path / "pm.ffsession",
                  {**data, PARAMETERS: json.dumps(p).encode(), MANIFEST: json.dumps(m).encode()})
    refused(tmp_path / "pm.ffsession", *words)


def test_atomic_write_keeps_the_old_file_when_writing_fails(good, tmp_path, monkeypatch):
    import tempfile

    path, rec = good
    rescue = tmp_path / "rescue"   # the temp folder the rescue copies go to
    rescue.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(rescue))
    target = tmp_path / "keep.ffsession"
    target.write_bytes(path.read_bytes())
    before = target.read_bytes()

    def disk_full(*_a, **_k):
        raise OSError(28, "No space left on device")

    import feelflow.app.files
    real_fsync = os.fsync
    monkeypatch.setattr(feelflow.app.files.os, "fsync", disk_full)  # the fsync of every atomic write
    with pytest.raises(SessionError, match="No space left on device") as info:
        rec.save(target)
    assert "\n" not in str(info.value)
    monkeypatch.setattr(feelflow.app.files.os, "fsync", real_fsync)
    assert target.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["keep.ffsession", "rescue"]  # no temp file left behind
    assert os.listdir(rescue) == []   # nor an empty rescue copy: that write failed too
    load_session(target)
    with pytest.raises(SessionError, match="cannot write") as info:
        rec.save(tmp_path / "no" / "such" / "dir.ffsession")
    (saved,) = rescue.iterdir()   # the work went to the rescue copy the line names
    assert str(saved) in str(info.value)
    load_session(saved)


def test_an_impossible_event_is_refused_at_replay(good, tmp_path):
    """An input that puts the body across the domain edge loads (it is on the grid) but cannot
    be replayed: one line naming the event."""
    from feelflow.app.sessions import replay

    path, _ = good
    data = members(path)
    a = arrays(data[INPUTS])
    a["pose"][4, 0] = 1.0  # the cylinder's centre one cell from the inlet
    write_members(tmp_path / "edge.ffsession", {**data, INPUTS: npz(a)})
    s = load_session(tmp_path / "edge.ffsession")
    with pytest.raises(SessionError, match=r"event \d+ \(input at step \d+\) cannot be replayed") as info:
        replay(s)
    assert "\n" not in str(info.value)


def test_saved_file_gets_the_usual_permissions(good, tmp_path):
    path, rec = good
    umask = os.umask(0o022)
    os.umask(umask)
    fresh = tmp_path / "fresh.ffsession"
    rec.save(fresh)
    assert fresh.stat().st_mode & 0o777 == 0o666 & ~umask
    fresh.chmod(0o640)
    rec.save(fresh)  # overwriting keeps the file's mode
    assert fresh.stat().st_mode & 0o777 == 0o640
