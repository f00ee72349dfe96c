"""What the viewport can colour the field by (the menu's View entries, the panel's Display box):
each mode's colormap (pyqtgraph's), its number in shaders/display.glsl, the colour bar's range
and unit."""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class DisplayMode:
    label: str
    colormap: str
    shader_mode: int
    range: tuple[float, float]
    unit: str           # what the colour bar's numbers mean


DISPLAY_MODES = {
    "speed": DisplayMode("Speed", "viridis", 0, (0.0, 1.6), "speed\n\u00f7 wind speed"),
    "vorticity": DisplayMode("Vorticity", "CET-D1", 1, (-4.0, 4.0), "vorticity\n\u00d7 D \u00f7 U"),
    "pressure": DisplayMode("Pressure", "CET-D1", 2, (-1.5, 1.5), "pressure\ncoefficient Cp"),
    "tracers": DisplayMode("Tracers", "viridis", 3, (0.0, 1.6), "speed\n\u00f7 wind speed"),
}

COLOUR_BAR_MARGIN = 132  # pixels on the right of the viewport kept for the colour bar
