"""The field display: which quantity the viewport shows (speed, vorticity, pressure, tracers)
and the shown model's field into the viewport each frame, as the flow's own texture (gl
backend) or as an (ny, nx, 4) array; the pressure view's reference density
(app/model/readouts.py) follows the field.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from feelflow.app.model import readouts

if TYPE_CHECKING:
    from collections.abc import Callable

    from feelflow.app.gui.side_panel import SidePanel
    from feelflow.app.gui.viewport import Viewport
    from feelflow.app.model.simulation import Params
    from feelflow.app.model.tunnel import TunnelModel


class FieldDisplay:
    """Holds the display mode and puts the shown model's field into the viewport."""

    def __init__(self, viewport: "Viewport", panel: "SidePanel", params_now: "Callable[[], Params]",
                 make_current: "Callable[[], None]"):
        """`params_now`: the parameters the panel shows; `make_current`: the viewport's GL
        context current where the solver draws on it."""
        self.viewport, self.panel, self.params_now, self.make_current = viewport, panel, params_now, make_current
        self.mode = "speed"
        self.shown: "TunnelModel | None" = None   # the model whose field is drawn

    def show(self, model: "TunnelModel"):
        """Draw `model`'s field from now on (the frame loop uploads it)."""
        self.shown = model

    def set_mode(self, mode: str):
        """Show `mode` (a key of the display modes): the viewport, the panel and the field again."""
        self.mode = mode
        self.viewport.mode = mode
        if mode != "tracers":
            self.viewport.tracers = None
        self.panel.show_params(self.params_now(), mode)
        if self.shown is not None:   # the field again (a gl texture computes the vorticity only where shown)
            self.make_current()
            self.upload_field()
        self.viewport.update()

    def upload_field(self):
        """The shown model's field into the viewport: the flow's own texture where it has one
        (the gl backend, on the viewport's context; the vorticity, five nodes a texel, only where
        it is shown), else its (ny, nx, 4) array, which it returns."""
        model = self.shown
        if model is None:
            return None
        texture = model.field_texture(vorticity=self.mode == "vorticity")
        if texture is not None:
            self.viewport.use_texture(texture)
            return None
        rgba = model.field_rgba()
        self.viewport.makeCurrent()
        self.viewport.upload_field(rgba)
        return rgba

    def field_array(self) -> np.ndarray:
        """gl backend: the field texture `upload_field` computed this frame, read back (ny, nx,
        4) float32, instead of running the field pass again."""
        tex = self.viewport.field_texture
        return np.frombuffer(tex.read(), np.float32).reshape(tex.height, tex.width, 4)

    def follow_field(self, rgba):
        """After a frame: the pressure view's reference density, every fifth frame drawn
        (`rgba`: this frame's field array, or None where it stayed in a texture)."""
        if self.mode == "pressure" and self.viewport.frames % 5 == 0:
            self.viewport.rho_ref = readouts.free_stream_density(self.field_array() if rgba is None else rgba)
