"""Shader loading: version line, lattice injection, driver line numbers that match the file."""
from __future__ import annotations

import re

import pytest

from feelflow.solver.gl_programs import SHADER_DIR, ShaderError, create_program, shader_source
from feelflow.solver.lattice import glsl_constants

pytestmark = pytest.mark.gl


def test_every_shader_starts_with_version_330_core():
    files = sorted(SHADER_DIR.glob("*.glsl"))
    assert files
    for path in files:
        assert path.read_text().splitlines()[0] == "#version 330 core", path.name


def test_lattice_constants_injected_and_line_numbering_restored():
    src = shader_source("lbm_step.glsl", {"BODY": 1})
    assert glsl_constants() in src and "#define BODY 1" in src
    file_lines = (SHADER_DIR / "lbm_step.glsl").read_text().splitlines()
    marker = file_lines.index("// @LATTICE") + 1
    assert f"#line {marker + 1}" in src


def _broken(tmp_path, error_line):
    lines = ["#version 330 core", "// a test shader", "// @LATTICE", "out vec4 colour;", "void main() {"]
    while len(lines) < error_line - 1:
        lines.append("    colour = vec4(W[0]);")
    lines.append("    colour = vec4(undeclared_thing);")
    lines.append("}")
    (tmp_path / "broken.glsl").write_text("\n".join(lines) + "\n")
    (tmp_path / "rect_vertex.glsl").write_text((SHADER_DIR / "rect_vertex.glsl").read_text())


@pytest.mark.parametrize("error_line", [6, 17])
def test_compile_error_names_file_and_line(gl_context, tmp_path, error_line):
    _broken(tmp_path, error_line)
    with pytest.raises(ShaderError) as err:
        create_program(gl_context, "rect_vertex.glsl", "broken.glsl", directory=tmp_path)
    first = str(err.value).splitlines()[0]
    m = re.match(r"^(.*broken\.glsl):(\d+):(\d+): (.*)$", first)
    assert m, first
    assert int(m.group(2)) == error_line
    assert "undeclared_thing" in m.group(4)


def test_every_step_variant_compiles(gl_context):
    for body in (0, 1):
        for edges in (0, 1):
            for y_mode in (0, 1, 2):
                for odd in (0, 1):
                    defines = dict(BODY=body, EDGES=edges, TRT=1, GUO_FORCE=1, SPONGE=1, X_PERIODIC=y_mode == 2,
                                   Y_MODE=y_mode, NX_ODD=odd)
                    create_program(gl_context, "rect_vertex.glsl", "lbm_step.glsl", defines).release()


def test_compile_error_in_an_included_file_names_that_file(gl_context, tmp_path):
    """`// @INCLUDE name.glsl` (solver/gl_programs.py): a driver error inside the included file
    is reported with that file's name and its own line number."""
    (tmp_path / "rect_vertex.glsl").write_text((SHADER_DIR / "rect_vertex.glsl").read_text())
    (tmp_path / "part.glsl").write_text("#version 330 core\n// shared part\nfloat helper() {\n"
                                        "    return undeclared_in_part;\n}\n")
    (tmp_path / "main.glsl").write_text("#version 330 core\n// @LATTICE\n// @INCLUDE part.glsl\n"
                                        "out vec4 colour;\nvoid main() { colour = vec4(helper()); }\n")
    with pytest.raises(ShaderError) as err:
        create_program(gl_context, "rect_vertex.glsl", "main.glsl", directory=tmp_path)
    first = str(err.value).splitlines()[0]
    m = re.match(r"^(.*part\.glsl):(\d+):(\d+): (.*)$", first)
    assert m, first
    assert int(m.group(2)) == 4 and "undeclared_in_part" in m.group(4)
