"""Loading the GLSL programs in `shaders/`: lattice constants injected, driver lines kept true.

Every file in `shaders/` is one shader stage whose line 1 is the `#version` directive for GLSL
330 core (GL 3.3 core, which macOS's 4.1 core also runs). A line `// @LATTICE` is replaced by the D2Q9 constants of
`feelflow.solver.lattice.glsl_constants()` (the one lattice definition: docs/developer/architecture.md, rule 3) and by any
compile-time `#define`s a variant asks for; a `#line` directive after the injected block puts
the driver's line numbers back on the file's own lines, so a compile error reported by the
driver as "0:57(3)" is line 57 of the file. `ShaderError` names the file and that line.

A line `// @INCLUDE name.glsl` is replaced by that file of `shaders/` (its `#version` line
dropped): GLSL code two programs share, e.g. the texture layout of the populations
(`paired_layout.glsl`). The k-th included file's lines are numbered from k * INCLUDE_LINES
by `#line` (Mesa attributes some errors to the wrong source-string number, never to the wrong
line), which `ShaderError` turns back into the included file's name and line.

Also the few things every pass does: `begin_pass` sets the whole GL state a pass needs (a host
such as Qt may have left blending, a scissor box or its own framebuffer), `set_uniforms` skips
uniforms the compiler dropped, `triangles` turns rectangles into vertices.
"""
from __future__ import annotations

import re
from pathlib import Path

import moderngl
import numpy as np

from feelflow import SHADER_DIR
from feelflow.solver.lattice import glsl_constants

MARKER = "// @LATTICE"
INCLUDE = "// @INCLUDE "
#: line-number offset of each included file (file k starts at k * INCLUDE_LINES + 1)
INCLUDE_LINES = 100000
#: what line 1 of every shader must declare after `#version`
GLSL_VERSION = "330 core"
_DRIVER_LINE = re.compile(r"^\s*(\d+):(\d+)\((\d+)\):\s*(.*)$")


class ShaderError(RuntimeError):
    """A shader failed to load or compile; the message starts with `file:line:`."""


def _read_lines(path: Path) -> list[str]:
    try:
        text = path.read_text()
    except OSError as exc:
        raise ShaderError(f"{path}: cannot read shader: {exc.strerror}") from None
    lines = text.splitlines()
    if not lines or lines[0].split(None, 1) != ["#version", GLSL_VERSION]:
        raise ShaderError(f"{path}:1: the first line must be the #version directive for GLSL {GLSL_VERSION}")
    return lines


def shader_source(name: str, defines: dict | None = None, directory: Path = SHADER_DIR,
                  sources: list | None = None) -> str:
    """The text of `shaders/<name>` with constants and defines injected at the marker and
    included files in place; `sources`, when given, receives the files: index k is the file
    whose lines are numbered from k * INCLUDE_LINES (0: `name` itself)."""
    path = Path(directory) / name
    files = [path] if sources is None else sources
    files[:] = [path]
    out = []
    for number, line in enumerate(_read_lines(path), start=1):
        if line.strip() == MARKER:
            out.extend(f"#define {k} {int(v) if isinstance(v, bool) else v}" for k, v in (defines or {}).items())
            out.append(glsl_constants())
            out.append(f"#line {number + 1}")
        elif line.startswith(INCLUDE):
            included = Path(directory) / line[len(INCLUDE):].strip()
            files.append(included)
            out.append(f"#line {(len(files) - 1) * INCLUDE_LINES + 2}")
            out.extend(_read_lines(included)[1:])
            out.append(f"#line {number + 1}")
        else:
            out.append(line)
    return "\n".join(out) + "\n"


def _explain(files: list, log: str) -> str:
    """Turn the driver's log into 'file:line:col: message' lines (files: see shader_source)."""
    messages = []
    for raw in log.splitlines():
        m = _DRIVER_LINE.match(raw)
        if m:
            k, line = divmod(int(m.group(2)), INCLUDE_LINES)
            where = files[k] if k < len(files) else files[0]
            messages.append(f"{where}:{line}:{m.group(3)}: {m.group(4)}")
    return "\n".join(messages) if messages else f"{files[0]}: {log.strip()}"


def create_program(ctx, vertex: str, fragment: str, defines: dict | None = None,
                   directory: Path = SHADER_DIR):
    """Compile `shaders/<vertex>` + `shaders/<fragment>` into a moderngl Program.

    Raises ShaderError whose first line is `<file>:<line>:<col>: <driver message>`.
    """
    vs_files, fs_files = [], []
    vs = shader_source(vertex, defines, directory, vs_files)
    fs = shader_source(fragment, defines, directory, fs_files)
    try:
        return ctx.program(vertex_shader=vs, fragment_shader=fs)
    except Exception as exc:  # moderngl raises a plain Error with the driver's log
        log = str(exc)
        files = fs_files
        if "vertex_shader\n" in log and "fragment_shader\n" not in log:
            files = vs_files
        body = log.split("===============", 1)[-1]
        raise ShaderError(_explain(files, body)) from None


def set_uniforms(prog, **values) -> None:
    """Set the uniforms of `prog` that it has (the compiler drops unused ones)."""
    for name, value in values.items():
        if name in prog:
            prog[name].value = value


def begin_pass(ctx, fbo, size) -> None:
    """The state every pass needs, whatever the host left: no blending, depth test or other
    capability (Qt enters paintGL with blending on), no scissor box, `fbo` bound with a
    viewport of `size`."""
    ctx.enable_only(moderngl.NOTHING)
    ctx.scissor = None
    fbo.use()
    ctx.viewport = (0, 0, *size)


def triangles(rects) -> np.ndarray:
    """Two triangles per rectangle (x0, y0, x1, y1), texel-edge coordinates, float32 (k*6, 2)."""
    out = []
    for x0, y0, x1, y1 in rects:
        out += [(x0, y0), (x1, y0), (x1, y1), (x0, y0), (x1, y1), (x0, y1)]
    return np.asarray(out, dtype="f4").reshape(-1, 2)
