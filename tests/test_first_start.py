"""A calm first start without a screen, provoked for real: `feelflow gui` in a child process with
no display variables, or with DISPLAY naming a server that is not there, gives one line and exit
2 (not Qt's abort). And the CPU fallback's colouring (app/gui/cpu_field.py, used where OpenGL 3.3
is missing) against the shader it stands in for, shaders/display.glsl, on the EGL context."""
from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

NO_DISPLAY = ("DISPLAY", "WAYLAND_DISPLAY", "QT_QPA_PLATFORM")


def feelflow_gui(**env_changes) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in NO_DISPLAY}
    env.update(env_changes)
    return subprocess.run([sys.executable, "-m", "feelflow.app", "gui"], env=env, capture_output=True,
                          text=True, timeout=120)


def one_line(r: subprocess.CompletedProcess) -> str:
    assert r.returncode == 2, r.stdout + r.stderr
    assert r.stdout == "" and r.stderr.count("\n") == 1, r.stderr
    assert "Traceback" not in r.stderr and "qt.qpa" not in r.stderr
    return r.stderr.strip()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="X11 displays")
def test_no_display_variables_give_one_line():
    assert one_line(feelflow_gui()) == ("feelflow: no display to open the window on (DISPLAY is not set); "
                                        "use 'feelflow run' for a headless run, or run under xvfb-run")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="X11 displays")
def test_a_display_nobody_serves_gives_one_line_not_a_qt_abort():
    display = next(f":{n}" for n in range(4711, 4800) if not os.path.exists(f"/tmp/.X11-unix/X{n}"))
    assert one_line(feelflow_gui(DISPLAY=display)) == (
        f"feelflow: no X server answers on DISPLAY={display}; use 'feelflow run' for a headless run, "
        "or run under xvfb-run")


def test_offscreen_platform_gives_one_line():
    assert one_line(feelflow_gui(QT_QPA_PLATFORM="offscreen")).startswith(
        "feelflow: QT_QPA_PLATFORM=offscreen has no screen with OpenGL")


@pytest.mark.gl
@pytest.mark.parametrize("mode", ["speed", "vorticity", "pressure", "tracers"])
def test_cpu_colouring_matches_the_display_shader(gl_context, mode):
    """The same field through display.glsl (EGL, nearest sampling at texel centres) and through
    cpu_field.field_colours: the same colours to within one step of the 256-entry colormap."""
    import moderngl

    from feelflow.app.gui import cpu_field
    from feelflow.app.gui.field_colours import display_program
    from feelflow.app.gui.viewport import DISPLAY_MODES

    ctx = gl_context
    nx, ny = 64, 32
    rng = np.random.default_rng(3)
    field = np.empty((ny, nx, 4), np.float32)
    field[..., 0] = 1.0 + rng.normal(0, 0.02, (ny, nx))
    field[..., 1:3] = rng.normal(0, 0.06, (ny, nx, 2))
    field[..., 3] = rng.normal(0, 0.05, (ny, nx))
    field[0, 0] = np.nan                         # grey, both ways
    m = DISPLAY_MODES[mode]
    scale, rho_ref = 1 / 0.05, 1.01
    colours = cpu_field.lut(m.colormap)

    prog = display_program(ctx)
    tex = ctx.texture((nx, ny), 4, field.tobytes(), dtype="f4")
    tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
    lut_tex = ctx.texture((256, 1), 4, np.concatenate([colours, np.full((256, 1), 255, np.uint8)], 1).tobytes())
    lut_tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
    lut_tex.repeat_x = lut_tex.repeat_y = False
    out = ctx.texture((nx, ny), 4, dtype="f1")
    fbo = ctx.framebuffer(color_attachments=[out])
    fbo.use()
    ctx.viewport = (0, 0, nx, ny)
    tex.use(0)
    lut_tex.use(1)
    prog["field"], prog["lut"], prog["mode"] = 0, 1, m.shader_mode
    prog["scale"], prog["range"], prog["rho_ref"] = scale, m.range, rho_ref
    ctx.vertex_array(prog, []).render(moderngl.TRIANGLE_STRIP, vertices=4)
    gpu = np.frombuffer(out.read(), np.uint8).reshape(ny, nx, 4)[..., :3].astype(int)
    cpu = cpu_field.field_colours(field, m.shader_mode, scale, m.range, rho_ref, colours).astype(int)
    for t in (tex, lut_tex, out, fbo, prog):
        t.release()
    assert tuple(cpu[0, 0]) == tuple(gpu[0, 0]) == (128, 128, 128)
    # the shader looks the colour up at texture coordinate s (texel floor(256 s) here; the window
    # filters linearly), the CPU at entry round(255 s): at most one colormap step apart
    step = np.abs(np.diff(colours.astype(int), axis=0)).max() + 1
    assert np.abs(cpu - gpu).max() <= step, np.abs(cpu - gpu).max()
    assert cpu.std() > 5                         # a field, not one flat colour
