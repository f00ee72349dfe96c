"""FeelFlow as an installed package: the wheel holds one `feelflow` namespace with its shaders
and scenes, and a `feelflow` command that works outside the checkout.

The wheel test builds from a copy of the tracked files (what a clean clone holds), installs it
into a fresh virtual environment in a temporary folder with `--no-deps`, and lets that
environment see the test environment's dependencies through a plain path entry (so the test
needs no download of PySide6 and friends; a path entry does not run the test environment's
editable-install hook, so `feelflow` itself can only come from the wheel).
"""
import os
import pathlib
import shutil
import subprocess
import sys
import sysconfig
import tomllib
import zipfile

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]


def _listed_packages() -> set[str]:
    return set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])


def test_pyproject_lists_every_package_folder():
    """Every folder holding an __init__.py is in pyproject's package list, and the data
    folders are too (a forgotten one would be missing from the wheel)."""
    found = {"feelflow"}
    for init in ROOT.rglob("__init__.py"):
        rel = init.parent.relative_to(ROOT)
        if rel.parts and rel.parts[0] in {".venv", "tests", "build", "docs"}:
            continue
        if rel.parts:
            found.add(".".join(("feelflow",) + rel.parts))
    data = {"feelflow.shaders", "feelflow.scenes", "feelflow.scenes.presets", "feelflow.exercises"}
    assert _listed_packages() == found | data


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> pathlib.Path:
    src = tmp_path_factory.mktemp("src")
    tracked = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"], cwd=ROOT,
                             capture_output=True, check=True).stdout.decode().split("\0")
    for name in filter(None, tracked):
        if not (ROOT / name).is_file():
            continue  # deleted in the working tree
        (src / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / name, src / name)
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(out), str(src)],
                   check=True, capture_output=True)
    (whl,) = out.glob("feelflow-*.whl")
    return whl


def test_wheel_holds_one_namespace_with_its_data(wheel):
    names = zipfile.ZipFile(wheel).namelist()
    tops = {n.split("/")[0] for n in names if not n.startswith("feelflow-")}
    assert tops == {"feelflow"}
    for data in ("feelflow/shaders/lbm_step.glsl", "feelflow/scenes/default.toml",
                 "feelflow/scenes/presets/vortex_street.toml", "feelflow/exercises/least_drag.toml"):
        assert data in names
    shaders = {p.name for p in (ROOT / "shaders").glob("*.glsl")}
    assert {n.split("/")[-1] for n in names if n.startswith("feelflow/shaders/")} == shaders


@pytest.fixture(scope="module")
def installed(wheel, tmp_path_factory) -> pathlib.Path:
    venv = tmp_path_factory.mktemp("venv") / "env"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    new_site = pathlib.Path(sysconfig.get_path("purelib", vars={"base": str(venv), "platbase": str(venv)}))
    deps = sysconfig.get_path("purelib")
    (new_site / "test-dependencies.pth").write_text(deps + "\n")
    subprocess.run([sys.executable, "-m", "pip", "--python", str(venv / "bin" / "python"), "install", "--no-deps", "-q",
                    str(wheel)], check=True, capture_output=True)
    return venv


def _run(venv, *args, cwd, timeout=300):
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH",)}
    return subprocess.run([str(venv / "bin" / "feelflow"), *args], cwd=cwd, capture_output=True, text=True,
                          timeout=timeout, env=env)


def test_installed_package_comes_from_the_wheel(installed, tmp_path):
    code = ("import feelflow, importlib.util as u; print(feelflow.__file__); "
            "print([n for n in ('app', 'solver', 'shapes', 'haptics') if u.find_spec(n)])")
    out = subprocess.run([str(installed / "bin" / "python"), "-c", code], cwd=tmp_path, capture_output=True,
                         text=True, check=True).stdout.splitlines()
    assert str(installed) in out[0]
    assert out[1] == "[]"  # no generic top-level names


def test_installed_feelflow_runs_its_shipped_scene(installed, tmp_path):
    """`feelflow run` on the default scene as the wheel ships it (package data)."""
    scene = subprocess.run([str(installed / "bin" / "python"), "-c",
                            "import feelflow; print(feelflow.SCENE_DIR / 'default.toml')"],
                           cwd=tmp_path, capture_output=True, text=True, check=True).stdout.strip()
    assert scene.startswith(str(installed))
    result = _run(installed, "run", scene, "--steps", "200", "--out", str(tmp_path / "forces.csv"), cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    rows = (tmp_path / "forces.csv").read_text().splitlines()
    assert rows[0].startswith("step,") and len(rows) == 1 + 200 // 50


def test_installed_feelflow_finds_its_shaders(installed, tmp_path):
    """The gl backend loads its programs from the installed package (EGL, llvmpipe here)."""
    code = ("import moderngl; from feelflow.solver.gl_programs import shader_source; "
            "print(len(shader_source('lbm_step.glsl')))")
    result = subprocess.run([str(installed / "bin" / "python"), "-c", code], cwd=tmp_path, capture_output=True,
                            text=True)
    assert result.returncode == 0, result.stderr
    assert int(result.stdout) > 1000


@pytest.mark.gui
def test_installed_feelflow_passes_its_selftest(installed, tmp_path):
    if not os.environ.get("DISPLAY"):
        pytest.skip("needs an X display (installer/run-tests.sh runs the tests under Xvfb)")
    result = _run(installed, "--selftest", cwd=tmp_path, timeout=600)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
