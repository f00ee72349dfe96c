"""FeelFlow: a desktop wind tunnel you can touch.

The repository root is the `feelflow` package (pyproject.toml maps it), so that one namespace
holds every part while the repository keeps one top-level folder per part:

- `feelflow.solver`   the lattice Boltzmann physics (numpy reference, OpenGL fragment shaders)
- `feelflow.shapes`   bodies and their rasterisation onto the lattice
- `feelflow.haptics`  devices and the 1 kHz force loop
- `feelflow.app`      the tunnel model, sessions, window, command line, reports, benchmarks
- `shaders/`, `scenes/`, `exercises/`  package data: GLSL programs, scene files and lessons,
  exercise files with their shapes
"""
from pathlib import Path

__version__ = "0.1.0"

#: where the package's data folders live (the repository root in a checkout, the installed
#: package elsewhere)
PACKAGE_DIR = Path(__file__).resolve().parent
SHADER_DIR = PACKAGE_DIR / "shaders"
SCENE_DIR = PACKAGE_DIR / "scenes"
EXERCISE_DIR = PACKAGE_DIR / "exercises"
