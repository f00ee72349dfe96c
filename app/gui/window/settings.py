"""What the window remembers between runs (QSettings): the panel's parameters, the custom
polygon, the display mode and the window's geometry. Unreadable values fall back to the
defaults one by one."""
from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING

from PySide6.QtCore import QSettings

from feelflow.app.errors import UserError
from feelflow.app.inputs import MAX_NODES, loads_json
from feelflow.app.model.simulation import Params
from feelflow.shapes.polygon import MAX_VERTICES

if TYPE_CHECKING:
    from PySide6.QtWidgets import QMainWindow

PARAM_KEYS = ("shape", "size", "angle_deg", "wind", "nu", "wall", "force_model")


class WindowSettings:
    """Reads and writes the window's QSettings."""

    def __init__(self, settings: QSettings):
        self.qsettings = settings

    def params(self) -> Params:
        d = Params()
        s = self.qsettings

        def get(key, default, kind):   # a settings file is input too: bad values fall back
            try:
                value = kind(s.value(key, default))
            except (TypeError, ValueError, OverflowError):
                return default
            return value if kind is not float or math.isfinite(value) else default
        grid = str(s.value("grid", f"{d.grid[0]}x{d.grid[1]}"))[:32]
        try:
            grid = tuple(int(v) for v in grid.split("x"))
        except ValueError:
            grid = d.grid
        if len(grid) != 2 or not all(8 <= v <= 8192 for v in grid) or grid[0] * grid[1] > MAX_NODES:
            grid = d.grid
        return Params(grid=grid if len(grid) == 2 else d.grid, shape=get("shape", d.shape, str),
                      size=get("size", d.size, float), angle_deg=get("angle_deg", d.angle_deg, float),
                      wind=get("wind", d.wind, float), nu=get("nu", d.nu, float), wall=get("wall", d.wall, str),
                      force_model=get("force_model", d.force_model, str),
                      compare_all=str(s.value("compare_all", "false")).lower() == "true")

    def polygon(self):
        """The remembered polygon's vertices (body frame), or None."""
        try:   # bounded like every input (app/inputs.py); a bad value is forgotten
            verts = loads_json(str(self.qsettings.value("polygon", "null")).encode(), "settings")
            if not verts or len(verts) > MAX_VERTICES:
                return None
            pts = [(float(x), float(y)) for x, y in verts]
            return pts if all(map(math.isfinite, (c for v in pts for c in v))) else None
        except (TypeError, ValueError, OverflowError, UserError):
            return None

    def display_mode(self, modes) -> str:
        """The remembered display mode if it is one of `modes`, else "speed"."""
        mode = self.qsettings.value("display_mode", "speed")
        return mode if mode in modes else "speed"

    def restore_geometry(self, window: "QMainWindow"):
        geometry = self.qsettings.value("geometry")
        if geometry is not None:
            window.restoreGeometry(geometry)
        else:
            window.resize(1280, 820)

    def remember(self, params: Params, polygon, display_mode: str, geometry) -> None:
        """The panel's parameters, the custom polygon (body frame; None keeps the remembered
        one), the display mode and the window's geometry (QMainWindow.saveGeometry)."""
        s = self.qsettings
        s.setValue("grid", f"{params.grid[0]}x{params.grid[1]}")
        for key in PARAM_KEYS:
            s.setValue(key, getattr(params, key))
        s.setValue("compare_all", "true" if params.compare_all else "false")
        if polygon is not None:
            s.setValue("polygon", json.dumps([list(v) for v in polygon]))
        s.setValue("display_mode", display_mode)
        s.setValue("geometry", geometry)
        s.sync()
