"""installer/install-desktop.sh as a teacher runs it: the real script through bash, into a
temporary HOME (per-user XDG folders) or --prefix, with --no-setup so that it never pips; the
launcher it writes execs this checkout's .venv/bin/feelflow (the shared venv here)."""
from __future__ import annotations

import configparser
import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "installer" / "install-desktop.sh"
VENV_FEELFLOW = ROOT / ".venv" / "bin" / "feelflow"
SUFFIX_TYPE = "application/x-feelflow-session"

needs_venv = pytest.mark.skipif(not os.access(VENV_FEELFLOW, os.X_OK),
                                reason="needs .venv/bin/feelflow (installer/setup.sh makes it)")


def run(home: Path, *args, data: Path | None = None):
    env = {k: v for k, v in os.environ.items() if not k.startswith("XDG_")}
    env["HOME"] = str(home)
    if data is not None:
        env["XDG_DATA_HOME"] = str(data)
    return subprocess.run(["bash", str(SCRIPT), *map(str, args)], env=env, capture_output=True, text=True,
                          timeout=60)


def snapshot(top: Path) -> dict[str, bytes | None]:
    """Every path under `top`: file contents (None for folders)."""
    return {str(p.relative_to(top)): (None if p.is_dir() else p.read_bytes()) for p in sorted(top.rglob("*"))}


def installed(home: Path):
    data = home / ".local" / "share"
    return {"desktop": data / "applications" / "feelflow.desktop",
            "icon": data / "icons" / "hicolor" / "scalable" / "apps" / "feelflow.svg",
            "mime": data / "mime" / "packages" / "feelflow.xml",
            "launcher": home / ".local" / "bin" / "feelflow"}


def desktop_entry(path: Path) -> configparser.SectionProxy:
    cp = configparser.ConfigParser(interpolation=None, strict=True)
    cp.optionxform = str   # keys are case-sensitive
    cp.read_string(path.read_text())
    return cp["Desktop Entry"]


@needs_venv
def test_install_writes_a_consistent_desktop_entry_and_a_working_launcher(tmp_path):
    home = tmp_path / "home"
    home.mkdir()
    r = run(home, "--no-setup")
    assert r.returncode == 0, r.stderr
    files = installed(home)
    for p in files.values():
        assert p.is_file(), p
    assert os.access(files["launcher"], os.X_OK)

    # the launcher runs this checkout's feelflow
    h = subprocess.run([str(files["launcher"]), "--help"], capture_output=True, text=True, timeout=60)
    assert h.returncode == 0 and h.stdout.startswith("usage: feelflow"), h.stderr
    assert f"exec '{VENV_FEELFLOW}' \"$@\"" in files["launcher"].read_text()

    e = desktop_entry(files["desktop"])
    assert e["Type"] == "Application" and e["Name"] == "FeelFlow" and e["GenericName"] == "Wind tunnel"
    assert e["Comment"] and e["Terminal"] == "false"
    assert e["Categories"] == "Education;Science;Physics;"
    # Exec: the installed launcher, replaying the double-clicked file (`feelflow gui SESSION`)
    assert e["Exec"].split() == [str(files["launcher"]), "gui", "%f"]
    assert e["TryExec"] == str(files["launcher"])
    # Icon: the installed icon's name, in the hicolor theme's scalable apps folder
    assert e["Icon"] == files["icon"].stem and files["icon"].parent.parts[-3:] == ("hicolor", "scalable", "apps")
    assert files["icon"].read_bytes() == (ROOT / "installer" / "feelflow.svg").read_bytes()
    # MimeType: the type the installed MIME package defines, for the suffix app/sessions/ writes
    from feelflow.app.sessions import SUFFIX

    assert e["MimeType"] == f"{SUFFIX_TYPE};"
    mime_xml = files["mime"].read_text()
    assert f'type="{SUFFIX_TYPE}"' in mime_xml and f'<glob pattern="*{SUFFIX}"/>' in mime_xml
    if shutil.which("update-mime-database"):   # the database now maps the suffix to the type
        globs2 = (home / ".local" / "share" / "mime" / "globs2").read_text()
        assert f"{SUFFIX_TYPE}:*{SUFFIX}" in globs2
    if shutil.which("desktop-file-validate"):
        v = subprocess.run(["desktop-file-validate", str(files["desktop"])], capture_output=True, text=True)
        assert v.returncode == 0, v.stdout + v.stderr


@needs_venv
def test_install_twice_then_uninstall_leaves_exactly_what_was_there(tmp_path):
    home = tmp_path / "home"
    data = home / ".local" / "share"
    unrelated = [data / "applications" / "other.desktop", data / "icons" / "hicolor" / "scalable" / "apps" / "other.svg",
                 data / "mime" / "packages" / "other.xml", home / ".local" / "bin" / "other-tool"]
    for p in unrelated:
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(f"not FeelFlow's: {p.name}\n")
    (data / "mime" / "packages" / "other.xml").write_text(
        '<?xml version="1.0"?>\n<mime-info xmlns="http://www.freedesktop.org/standards/shared-mime-info">'
        '<mime-type type="text/x-other"><glob pattern="*.oth"/></mime-type></mime-info>\n')
    before = snapshot(home)

    assert run(home, "--no-setup").returncode == 0
    first = snapshot(home)
    r = run(home, "--no-setup")
    assert r.returncode == 0, r.stderr
    assert snapshot(home) == first              # idempotent: the same files, the same contents
    assert not list(home.rglob(".feelflow-install.*"))   # no temp file left behind

    r = run(home, "--uninstall")
    assert r.returncode == 0, r.stderr
    after = snapshot(home)
    # the mime database (mime/ outside packages/) is regenerated by update-mime-database
    # from the packages left: only other.xml's type is in it now
    def ours(snap):
        return {k: v for k, v in snap.items() if not (k.startswith(".local/share/mime/") and
                                                      not k.startswith(".local/share/mime/packages"))}
    assert ours(after) == ours(before)
    globs2 = data / "mime" / "globs2"
    if globs2.exists():
        assert "ffsession" not in globs2.read_text() and "*.oth" in globs2.read_text()
    r = run(home, "--uninstall")                 # again: nothing to do
    assert r.returncode == 0 and "nothing to uninstall" in r.stdout


@needs_venv
def test_uninstall_from_an_empty_home_removes_the_folders_it_made_and_keeps_changed_files(tmp_path):
    home = tmp_path / "home"
    home.mkdir()
    assert run(home, "--no-setup").returncode == 0
    assert run(home, "--uninstall").returncode == 0
    assert list(home.iterdir()) == []            # folders, manifest and generated databases gone

    assert run(home, "--no-setup").returncode == 0
    launcher = installed(home)["launcher"]
    launcher.write_text("#!/bin/sh\necho the teacher's own\n")   # changed after install: kept
    r = run(home, "--uninstall")
    assert r.returncode == 0
    assert launcher.read_text() == "#!/bin/sh\necho the teacher's own\n"
    assert f"kept {launcher}" in r.stderr
    assert not installed(home)["desktop"].exists()


@needs_venv
def test_prefix_and_xdg_data_home(tmp_path):
    home, data, prefix = tmp_path / "home", tmp_path / "xdg-data", tmp_path / "usr-local"
    home.mkdir()
    r = run(home, "--no-setup", data=data)
    assert r.returncode == 0, r.stderr
    assert (data / "applications" / "feelflow.desktop").is_file()
    r = run(home, "--no-setup", "--prefix", prefix)
    assert r.returncode == 0, r.stderr
    entry = desktop_entry(prefix / "share" / "applications" / "feelflow.desktop")
    assert entry["Exec"] == f"{prefix / 'bin' / 'feelflow'} gui %f"
    assert run(home, "--uninstall", "--prefix", prefix).returncode == 0
    assert not prefix.exists()                   # it made the folder, so it took it away
    assert (data / "applications" / "feelflow.desktop").is_file()   # the other install untouched


@needs_venv
def test_an_unrelated_feelflow_in_the_way_is_not_overwritten(tmp_path):
    home = tmp_path / "home"
    theirs = home / ".local" / "bin" / "feelflow"
    theirs.parent.mkdir(parents=True)
    theirs.write_text("#!/bin/sh\n# pip install --user feelflow\n")
    r = run(home, "--no-setup")
    assert r.returncode == 1
    assert len(r.stderr.strip().splitlines()) == 1 and "not written by this installer" in r.stderr
    assert theirs.read_text() == "#!/bin/sh\n# pip install --user feelflow\n"


def test_a_conflict_on_any_file_writes_nothing(tmp_path):
    """The last file written (the menu entry) in the way: refused before the first write."""
    home = tmp_path / "home"
    theirs = home / ".local" / "share" / "applications" / "feelflow.desktop"
    theirs.parent.mkdir(parents=True)
    theirs.write_text("[Desktop Entry]\nName=Someone else's\n")
    r = run(home, "--no-setup")
    assert r.returncode == 1 and "not written by this installer" in r.stderr
    assert sorted(p for p in home.rglob("*") if p.is_file()) == [theirs]


def test_a_quote_in_the_home_folder_is_refused(tmp_path):
    """The launcher quotes its target with single quotes: a path holding one is refused, not broken."""
    home = tmp_path / "o'brien"
    home.mkdir()
    r = run(home, "--no-setup")
    assert r.returncode == 1 and len(r.stderr.strip().splitlines()) == 1 and "'" in r.stderr
    assert not any(home.rglob("*"))


@pytest.mark.parametrize("args", [["--bogus"], ["--prefix"], ["--uninstall", "extra"]])
def test_a_bad_option_is_one_line_and_exit_2(tmp_path, args):
    r = run(tmp_path, *args)
    assert r.returncode == 2
    assert len(r.stderr.strip().splitlines()) == 1 and r.stderr.startswith("install-desktop: ")
    assert r.stdout == "" and not (tmp_path / ".local").exists()


# --- a bundle (installer/build-bundle.sh) instead of a checkout ---------------------------------
def stand_in_bundle(folder: Path) -> Path:
    """A bundle folder as installer/feelflow.spec lays it out (`feelflow` beside installer/ with
    the desktop files), its program being installer/bundle_main.py on this checkout's Python:
    the frozen entry point, unfrozen (tests/test_bundle.py installs the real one)."""
    (folder / "installer").mkdir(parents=True)
    for name in ("install-desktop.sh", "feelflow.desktop.in", "feelflow.svg", "feelflow-mime.xml"):
        shutil.copy2(ROOT / "installer" / name, folder / "installer" / name)
    program = folder / "feelflow"
    program.write_text(f"#!/bin/sh\nexec '{ROOT / '.venv' / 'bin' / 'python'}' '{ROOT / 'installer' / 'bundle_main.py'}' \"$@\"\n")
    program.chmod(0o755)
    return program


def run_script(script: Path, home: Path, *args, **env_extra):
    env = {k: v for k, v in os.environ.items() if not k.startswith("XDG_")}
    env.update(HOME=str(home), **env_extra)
    return subprocess.run(["bash", str(script), *map(str, args)], env=env, capture_output=True, text=True, timeout=60)


@needs_venv
@pytest.mark.parametrize("how", ["script inside the bundle", "--bundle DIR from the checkout"])
def test_install_from_a_bundle_and_uninstall_leaves_nothing(tmp_path, how):
    home, bundle = tmp_path / "home", tmp_path / "FeelFlow"
    home.mkdir()
    program = stand_in_bundle(bundle)
    before = snapshot(bundle)
    if how == "script inside the bundle":
        r = run_script(bundle / "installer" / "install-desktop.sh", home)
    else:
        r = run(home, "--bundle", bundle)
    assert r.returncode == 0, r.stderr
    files = installed(home)
    assert all(p.is_file() for p in files.values())
    assert f"exec '{program}' \"$@\"" in files["launcher"].read_text()
    assert desktop_entry(files["desktop"])["Exec"].split() == [str(files["launcher"]), "gui", "%f"]
    h = subprocess.run([str(files["launcher"]), "--help"], capture_output=True, text=True, timeout=60)
    assert h.returncode == 0 and h.stdout.startswith("usage: feelflow"), h.stderr
    assert not (bundle / ".venv").exists()       # no setup.sh ran for a bundle
    r = run(home, "--uninstall")
    assert r.returncode == 0, r.stderr
    assert list(home.iterdir()) == []            # nothing left in the home folder
    assert snapshot(bundle) == before            # and the bundle folder as it was


def test_bundle_folder_without_a_program_is_one_line_and_exit_2(tmp_path):
    (tmp_path / "empty").mkdir()
    for args in (["--bundle", tmp_path / "empty"], ["--bundle", tmp_path / "missing"]):
        r = run(tmp_path, *args)
        assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
        assert not (tmp_path / ".local").exists()


@needs_venv
def test_udev_rule_install_and_uninstall(tmp_path):
    from feelflow.haptics.permissions import RULES_FILE
    from feelflow.haptics.udev import udev_rules

    rules_dir = tmp_path / "rules.d"
    rules_dir.mkdir()
    (rules_dir / "50-other.rules").write_text("# not FeelFlow's\n")
    before = snapshot(rules_dir)
    r = run_script(SCRIPT, tmp_path, "--udev", FEELFLOW_UDEV_DIR=str(rules_dir))
    assert r.returncode == 0, r.stderr
    assert (rules_dir / RULES_FILE).read_text() == udev_rules()
    assert not (tmp_path / ".local").exists()    # the rule only: no desktop entry for root
    r = run_script(SCRIPT, tmp_path, "--udev", "--uninstall", FEELFLOW_UDEV_DIR=str(rules_dir))
    assert r.returncode == 0, r.stderr
    assert snapshot(rules_dir) == before
    # a rule changed by hand is kept
    (rules_dir / RULES_FILE).write_text(udev_rules() + "# local change\n")
    r = run_script(SCRIPT, tmp_path, "--udev", "--uninstall", FEELFLOW_UDEV_DIR=str(rules_dir))
    assert r.returncode == 0 and "kept" in r.stderr and (rules_dir / RULES_FILE).exists()
    # from a bundle, the same rule (the program runs `feelflow -m feelflow.haptics.udev`)
    (rules_dir / RULES_FILE).unlink()
    stand_in_bundle(tmp_path / "bundle")
    r = run_script(tmp_path / "bundle" / "installer" / "install-desktop.sh", tmp_path, "--udev",
                   FEELFLOW_UDEV_DIR=str(rules_dir))
    assert r.returncode == 0, r.stderr
    assert (rules_dir / RULES_FILE).read_text() == udev_rules()


@needs_venv
def test_udev_rule_where_it_cannot_be_written_says_sudo(tmp_path):
    r = run_script(SCRIPT, tmp_path, "--udev", FEELFLOW_UDEV_DIR=str(tmp_path / "no-such-dir"))
    assert r.returncode == 1 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "(run it with sudo)" in r.stderr
