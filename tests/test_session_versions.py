"""Versioned session loaders (app/sessions/versions.py): a session written by each earlier
format in the repository's history opens and replays (the files in tests/data/sessions, written
by those commits' own recorders: tests/data/sessions/make_session.py), a file from a newer
FeelFlow is refused with one line that says so, and the stored configuration follows the
explicit schema, not the solver's dataclass."""
from __future__ import annotations

import dataclasses
import io
import json
import pathlib
import zipfile

import numpy as np
import pytest

from feelflow.app.sessions import SessionError, load_session, replay
from feelflow.app.sessions import versions
from feelflow.app.sessions.format import config_to_dict
from feelflow.solver.config import FlowConfig

DATA = pathlib.Path(__file__).resolve().parent / "data" / "sessions"
#: file -> the commit whose recorder wrote it, and what that format held
HISTORY = {
    "v1-2f57f13-start.ffsession": "the first session files (no sponge_absorb, equilibrium, smagorinsky, quiet inlet)",
    "v1-263f505-midflow.ffsession": "recorded on a running flow (state.npz) with a rebuild event",
    "v1-1543f8d-start.ffsession": "the config's retired inlet_sponge_cells key",
    "v1-1543f8d-midflow.ffsession": "inlet_sponge_cells, a quiet inlet without its stored reference",
    "v1-d9a539c-midflow.ffsession": "the quiet inlet's reference in state.npz",
    "v2-midflow.ffsession": "the explicit schema",
    "v3-midflow.ffsession": "each model's torque (forces.npz torques)",
}


@pytest.mark.parametrize("name", sorted(HISTORY))
def test_every_earlier_format_opens_and_replays(name):
    session = load_session(DATA / name)
    assert session.manifest["version"] == versions.VERSION          # read into the current form
    assert set(config_to_dict(session.config)) == set(versions.CONFIG_KEYS)
    result = replay(session, "numpy")
    assert result.diverged_at is None
    assert result.values.shape == session.forces["values"].shape and np.isfinite(result.values).all()
    # the physics moved on since these were written (the moving body's terms, the quiet inlet's
    # stored reference): the replay is the same run, not bit for bit (1.6 % of the largest force
    # for the oldest file's moving cylinder when this was written); a misread file is far off
    assert result.relative_deviation < 0.2


def test_every_file_of_the_history_is_tested():
    assert sorted(p.name for p in DATA.glob("*.ffsession")) == sorted(HISTORY)


def rewrite(src, dst, edit):
    """Copy a session file with its manifest edited."""
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item)
            if item.filename == "manifest.json":
                manifest = json.loads(data)
                edit(manifest)
                data = json.dumps(manifest).encode()
            zout.writestr(item, data)
    return dst


def test_a_newer_file_says_it_was_written_by_a_newer_feelflow(tmp_path):
    path = rewrite(DATA / "v2-midflow.ffsession", tmp_path / "new.ffsession",
                   lambda m: m.update(version=versions.VERSION + 1))
    with pytest.raises(SessionError, match=f"written by a newer FeelFlow \\(session format version "
                                           f"{versions.VERSION + 1}"):
        load_session(path)


def test_a_retired_setting_that_was_on_is_one_line(tmp_path):
    path = rewrite(DATA / "v1-1543f8d-start.ffsession", tmp_path / "layer.ffsession",
                   lambda m: m["scene"]["config"].update(inlet_sponge_cells=8))
    with pytest.raises(SessionError, match="inlet_sponge_cells is 8: the inlet's velocity layer"):
        load_session(path)


def test_version_2_holds_exactly_the_schema(tmp_path):
    unknown = rewrite(DATA / "v2-midflow.ffsession", tmp_path / "u.ffsession",
                      lambda m: m["scene"]["config"].update(future_setting=1))
    with pytest.raises(SessionError, match="unknown key 'future_setting'"):
        load_session(unknown)
    missing = rewrite(DATA / "v2-midflow.ffsession", tmp_path / "m.ffsession",
                      lambda m: m["scene"]["config"].pop("sponge_absorb"))
    with pytest.raises(SessionError, match="lacks key 'sponge_absorb'"):
        load_session(missing)


def test_the_schema_is_every_flow_setting():
    """A setting added to FlowConfig changes what a session must store: add it to a new format
    version (app/sessions/versions.py: VERSION, CONFIG_KEYS and a loader for the old version)."""
    assert set(versions.CONFIG_KEYS) == {f.name for f in dataclasses.fields(FlowConfig)}


def test_torques_are_recorded_from_version_3_and_read_as_missing_before():
    """A version-3 file holds each row's torque as the solver gave it, and its replay gives the
    same; files of versions 1 and 2 recorded none: NaN, and nothing of theirs reads as a torque."""
    v3 = load_session(DATA / "v3-midflow.ffsession")
    torques = v3.forces["torques"]
    assert torques.shape == (len(v3.forces["seq"]), len(v3.models)) and np.isfinite(torques).all()
    assert np.abs(torques).max() > 0
    assert v3.torques(0) == {"momentum_exchange": float(torques[0, 0])}
    replayed = replay(v3, "numpy").session.forces["torques"]
    assert np.allclose(replayed, torques, rtol=1e-9, atol=1e-15)
    for name in ("v2-midflow.ffsession", "v1-2f57f13-start.ffsession"):
        old = load_session(DATA / name)
        assert np.isnan(old.forces["torques"]).all() and old.torques(0) == {}


def test_a_version_3_file_without_torques_is_one_line(tmp_path):
    src, dst = DATA / "v3-midflow.ffsession", tmp_path / "no-torques.ffsession"
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item)
            if item.filename == "forces.npz":
                with np.load(io.BytesIO(data)) as npz:
                    arrays = {k: npz[k] for k in npz.files if k != "torques"}
                buf = io.BytesIO()
                np.savez(buf, **arrays)
                data = buf.getvalue()
            zout.writestr(item, data)
    with pytest.raises(SessionError, match="forces.npz has no array 'torques'"):
        load_session(dst)
