"""One loader per session format version (glue keeps one per version): each takes a file's
manifest and parameter changes as that version wrote them and gives them back in the current
version's form, so the rest of app/sessions/format.py reads one form only. A file from a newer
FeelFlow is refused with one line that says so.

The flow's configuration is stored with an explicit schema (`CONFIG_KEYS`), not as whatever the
solver's `FlowConfig` dataclass holds: a field added to FlowConfig changes the file format only
through a new version here (tests/test_session_versions.py fails until it is added).

- Version 1: every file FeelFlow wrote before the schema. `scene.config` (and a rebuild event's
  config) held the FlowConfig fields of the day: the keys of `V1_KEYS` always; the keys of
  `V1_ADDED` only in files written after they were added, absent before, when the flow ran as
  their value says (each one's "off"); `inlet_sponge_cells` only in files written while FeelFlow
  had an inlet velocity layer (removed since, replaced by the quiet inlet), 0 when it was off.
- Version 2: `scene.config` and every rebuild's config hold exactly `CONFIG_KEYS`.
- Version 3: `forces.npz` holds `torques` too (m, M): each model's mean torque on the body about
  its centre per force row (NaN: not computed). Versions 1 and 2 recorded none: their rows read
  as NaN torques.

Qt-free. docs/reference/session-format.md, "Versioning".
"""
from __future__ import annotations

import copy

import numpy as np

#: the current format version, written by this FeelFlow
VERSION = 3

#: version 2's flow configuration: exactly these keys (FlowConfig fields of the same names)
CONFIG_KEYS = ("nx", "ny", "nu", "collision", "trt_magic", "smagorinsky", "equilibrium", "dtype",
               "x_boundary", "y_boundary", "inflow_speed", "inflow_profile", "inflow_ramp_steps", "body_force",
               "sponge_cells", "sponge_strength", "sponge_absorb", "inlet_nonreflecting", "initial_velocity",
               "mach_limit", "extra")

#: version 1: the keys every version-1 configuration holds (the first session files' FlowConfig)
V1_KEYS = ("nx", "ny", "nu", "collision", "trt_magic", "dtype", "x_boundary", "y_boundary", "inflow_speed",
           "inflow_profile", "inflow_ramp_steps", "body_force", "sponge_cells", "sponge_strength",
           "initial_velocity", "mach_limit", "extra")
#: version 1: keys added to FlowConfig while version 1 was written, with the value a file
#: without the key ran with
V1_ADDED = {"sponge_absorb": 0.0, "equilibrium": "compressible", "smagorinsky": 0.0, "inlet_nonreflecting": 0.0}
#: version 1: keys FeelFlow no longer has, with the value that meant "off"
V1_RETIRED = {"inlet_sponge_cells": 0}


class SessionFormatError(ValueError):
    """A file's version or configuration cannot be read (format.py turns it into SessionError)."""


def config_to_dict(config) -> dict:
    """The flow configuration as the current version writes it: `CONFIG_KEYS`, tuples as lists."""
    out = {}
    for key in CONFIG_KEYS:
        v = getattr(config, key)
        out[key] = list(v) if isinstance(v, tuple) else v
    return out


class LoaderV1:
    """Files written before the explicit schema (module docstring)."""

    version = 1

    def config(self, d, where: str):
        if not isinstance(d, dict):
            return d                      # format.py names the malformed value
        d = dict(d)
        for key, off in V1_RETIRED.items():
            if key in d:
                value = d.pop(key)
                if value != off:
                    raise SessionFormatError(
                        f"{where}.{key} is {value!r}: the inlet's velocity layer it switches on is no longer "
                        f"part of FeelFlow (the quiet inlet replaced it), so this session cannot be replayed")
        for key in V1_KEYS:
            if key not in d:
                raise SessionFormatError(f"{where} lacks key {key!r} (a version-1 session holds it)")
        unknown = sorted(set(d) - set(V1_KEYS) - set(V1_ADDED))
        if unknown:
            raise SessionFormatError(f"{where} has unknown key {unknown[0]!r}")
        for key, value in V1_ADDED.items():
            d.setdefault(key, value)
        return {key: d[key] for key in CONFIG_KEYS}

    def upgrade(self, manifest: dict, parameters):
        """(manifest, parameters) in the current version's form (copies; the input is kept)."""
        manifest = copy.deepcopy(manifest)
        scene = manifest.get("scene")
        if isinstance(scene, dict) and "config" in scene:
            scene["config"] = self.config(scene["config"], "scene.config")
        if isinstance(parameters, list):
            parameters = copy.deepcopy(parameters)
            for k, p in enumerate(parameters):
                if isinstance(p, dict) and p.get("name") == "rebuild" and isinstance(p.get("value"), dict) \
                        and "config" in p["value"]:
                    p["value"]["config"] = self.config(p["value"]["config"], f"parameters.json: change {k}: rebuild config")
        manifest["version"] = VERSION
        return manifest, parameters

    def forces(self, forces: dict, models: int) -> dict:
        """forces.npz's arrays in the current form, for `models` force models: versions 1 and 2
        recorded no torque, so `torques` is NaN (a copy; any `torques` array there is not theirs)."""
        out = {k: v for k, v in forces.items() if k != "torques"}
        out["torques"] = np.full((len(forces["seq"]), models), np.nan)
        return out


class LoaderV2(LoaderV1):
    """The current version: the configuration holds exactly `CONFIG_KEYS`."""

    version = 2

    def config(self, d, where: str):
        if not isinstance(d, dict):
            return d
        missing = [key for key in CONFIG_KEYS if key not in d]
        if missing:
            raise SessionFormatError(f"{where} lacks key {missing[0]!r}")
        unknown = sorted(set(d) - set(CONFIG_KEYS))
        if unknown:
            raise SessionFormatError(f"{where} has unknown key {unknown[0]!r}")
        return dict(d)


class LoaderV3(LoaderV2):
    """The current version: forces.npz holds each model's torque (`torques`)."""

    version = 3

    def forces(self, forces: dict, models: int) -> dict:
        if "torques" not in forces:
            raise SessionFormatError("forces.npz has no array 'torques' (a version-3 session holds it)")
        return dict(forces)


LOADERS = {1: LoaderV1(), 2: LoaderV2(), 3: LoaderV3()}


def loader_for(version) -> LoaderV1:
    """The loader of format `version`; SessionFormatError for a newer or unknown one."""
    if isinstance(version, bool) or not isinstance(version, int):
        raise SessionFormatError(f"version must be an integer, got {version!r}")
    if version > VERSION:
        raise SessionFormatError(f"written by a newer FeelFlow (session format version {version}; this one "
                                 f"reads versions 1 to {VERSION}): update FeelFlow to open it")
    if version not in LOADERS:
        raise SessionFormatError(f"unknown session format version {version} (this FeelFlow reads 1 to {VERSION})")
    return LOADERS[version]
