"""The PyInstaller bundle, built and run as a classroom PC would (opt-in: `pytest -m bundle`,
under xvfb-run for the window's self-test; minutes and several hundred MB).

The module's fixture runs installer/build-bundle.sh once into FEELFLOW_BUNDLE_WORK (default
/tmp/bundle-build; its build venv is kept between runs) and then only the built folder is used:
its program runs from a temporary folder with no Python of ours on the PATH or PYTHONPATH."""
from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
pytestmark = [pytest.mark.bundle, pytest.mark.timeout(2400)]


@pytest.fixture(scope="module")
def bundle() -> Path:
    work = Path(os.environ.get("FEELFLOW_BUNDLE_WORK", "/tmp/bundle-build"))
    r = subprocess.run(["bash", str(ROOT / "installer" / "build-bundle.sh"), str(work)], capture_output=True,
                       text=True, timeout=2400)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    folder = work / "dist" / "feelflow"
    assert (folder / "feelflow").is_file()
    return folder


def clean_env(tmp: Path) -> dict:
    """No virtual environment, no PYTHONPATH: what the bundle finds must be its own."""
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV") and not k.startswith("XDG_")}
    env["PATH"] = "/usr/bin:/bin"
    env["HOME"] = str(tmp / "home")
    env["MESA_SHADER_CACHE_DIR"] = env["XDG_CACHE_HOME"] = str(tmp / "cache")
    return env


def feelflow(bundle: Path, tmp: Path, *args, timeout=300) -> subprocess.CompletedProcess:
    (tmp / "home").mkdir(exist_ok=True)
    return subprocess.run([str(bundle / "feelflow"), *map(str, args)], cwd=tmp, env=clean_env(tmp),
                          capture_output=True, text=True, timeout=timeout)


def test_bundle_holds_every_package_data_file(bundle):
    """Every file the installed package carries besides code (shaders, scenes, presets, any
    later data folder) is in the bundle: the build venv's installed copy against the bundle's."""
    installed = next((bundle.parents[1] / "venv" / "lib").glob("python3*/site-packages/feelflow"))
    data = sorted(p.relative_to(installed) for p in installed.rglob("*")
                  if p.is_file() and p.suffix not in (".py", ".pyc") and "__pycache__" not in p.parts)
    assert {p.parts[0] for p in data} >= {"shaders", "scenes"}
    assert any(p.parts[:2] == ("scenes", "presets") for p in data)
    internal = bundle / "_internal" / "feelflow"
    missing = [str(p) for p in data if not (internal / p).is_file()]
    assert not missing


def test_run_record_and_open_the_session(bundle, tmp_path):
    scene = tmp_path / "tunnel.toml"
    shutil.copy(ROOT / "scenes" / "cylinder_tunnel.toml", scene)
    r = feelflow(bundle, tmp_path, "run", scene, "--steps", "300", "--out", "forces.csv", "--record", "s.ffsession",
                 "--backend", "numpy")
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "forces.csv").read_text().startswith("step,")
    info = feelflow(bundle, tmp_path, "session", "info", "s.ffsession")
    assert info.returncode == 0, info.stderr
    assert "recorded  300 steps" in info.stdout
    replay = feelflow(bundle, tmp_path, "session", "replay", "s.ffsession")
    assert replay.returncode == 0, replay.stderr
    assert "largest force deviation 0 " in replay.stdout   # numpy re-simulates bit for bit
    gl = feelflow(bundle, tmp_path, "run", scene, "--steps", "100", "--backend", "gl", "--out", "gl.csv")
    assert gl.returncode == 0, gl.stderr                    # the shaders and EGL from inside the bundle
    assert "100 steps on gl" in gl.stdout


def test_the_compiled_cpu_backend_runs_frozen_and_keeps_its_compiled_kernels(bundle, tmp_path):
    """numba inside the bundle: the kernels compile on the first run into the user's cache (the
    bundle's own folder may be read-only) and the second run loads them: it writes nothing new."""
    scene = tmp_path / "tunnel.toml"
    shutil.copy(ROOT / "scenes" / "cylinder_tunnel.toml", scene)
    compiled = []
    for k in range(2):
        r = feelflow(bundle, tmp_path, "run", scene, "--steps", "100", "--backend", "cpu", "--out", f"cpu{k}.csv")
        assert r.returncode == 0, r.stdout + r.stderr
        assert "100 steps on cpu" in r.stdout
        compiled.append({(p.name, p.stat().st_mtime_ns) for p in tmp_path.rglob("*.nbc")})
    assert compiled[0] and compiled[1] == compiled[0]
    assert (tmp_path / "cpu0.csv").read_text() == (tmp_path / "cpu1.csv").read_text()


def test_child_processes_run_from_the_bundle(bundle, tmp_path):
    """`feelflow -m MODULE`: the haptic loop's process and the serial simulator behind a pty
    both start as [sys.executable, "-m", ...], sys.executable being the bundle's program."""
    from feelflow.haptics.udev import udev_rules

    r = feelflow(bundle, tmp_path, "-m", "feelflow.haptics.udev")
    assert r.returncode == 0 and r.stdout == udev_rules(), r.stderr
    r = feelflow(bundle, tmp_path, "-m", "json.tool")
    assert r.returncode == 2 and "FeelFlow's own modules only" in r.stderr
    r = feelflow(bundle, tmp_path, "bench", "haptics", "--seconds", "1.5")
    assert r.returncode == 0, r.stdout + r.stderr
    assert "haptic loop on sim://haply2diy" in r.stdout and "as a child process" in r.stdout


@pytest.mark.skipif(not os.environ.get("DISPLAY"), reason="the window needs a display: run under xvfb-run -a")
def test_selftest_and_a_session_in_the_window(bundle, tmp_path):
    r = feelflow(bundle, tmp_path, "--selftest", "--seconds", "5")
    assert r.returncode == 0, r.stdout + r.stderr
    assert r.stdout.rstrip().endswith("selftest: ok")
    # Qt without OpenGL (X forwarding, a remote desktop): the window runs on the CPU
    env = {**clean_env(tmp_path), "QT_XCB_GL_INTEGRATION": "none"}
    r = subprocess.run([str(bundle / "feelflow"), "--selftest", "--seconds", "4"], cwd=tmp_path, env=env,
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "renderer no GL, solver backend numpy" in r.stdout and r.stdout.rstrip().endswith("selftest: ok")
    rec = feelflow(bundle, tmp_path, "run", ROOT / "scenes" / "default.toml", "--steps", "600", "--backend", "numpy", "--out", "f.csv",
                   "--record", "lesson.ffsession")
    assert rec.returncode == 0, rec.stderr
    r = feelflow(bundle, tmp_path, "--selftest", "--seconds", "4", "gui", "lesson.ffsession")
    assert r.returncode == 0, r.stdout + r.stderr
    assert r.stdout.rstrip().endswith("selftest: ok")


def test_desktop_install_from_the_bundle_and_uninstall(bundle, tmp_path):
    home = tmp_path / "home"
    home.mkdir()
    env = clean_env(tmp_path)
    script = bundle / "installer" / "install-desktop.sh"
    r = subprocess.run(["bash", str(script)], env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    launcher = home / ".local" / "bin" / "feelflow"
    assert f"exec '{bundle / 'feelflow'}' \"$@\"" in launcher.read_text()
    h = subprocess.run([str(launcher), "--help"], env=env, capture_output=True, text=True, timeout=120)
    assert h.returncode == 0 and h.stdout.startswith("usage: feelflow"), h.stderr
    r = subprocess.run(["bash", str(script), "--uninstall"], env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert list(home.iterdir()) == []
    # the udev rule, written by the bundle's own program
    from feelflow.haptics.permissions import RULES_FILE
    from feelflow.haptics.udev import udev_rules

    rules = tmp_path / "rules.d"
    rules.mkdir()
    env["FEELFLOW_UDEV_DIR"] = str(rules)
    for args, present in ((["--udev"], True), (["--udev", "--uninstall"], False)):
        r = subprocess.run(["bash", str(script), *args], env=env, capture_output=True, text=True, timeout=120)
        assert r.returncode == 0, r.stderr
        assert (rules / RULES_FILE).exists() == present
        if present:
            assert (rules / RULES_FILE).read_text() == udev_rules()
