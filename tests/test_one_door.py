"""Every file FeelFlow writes goes through one door (app/files.py), and the next feature cannot
skip it: this test enumerates every command-line option that names an output (by walking the
argparse parsers of app/cli) and checks, by running the command, that the output reaches the
door's checks (`check_output`, `check_output_folder`) before any work; and it scans the
production code (the window's writers included) for every call that writes a file and checks
each one writes through `atomic_path` (or is listed below with its reason). Each check is also
shown failing on a deliberately bypassing example."""
from __future__ import annotations

import argparse
import ast
import functools
import os
import pathlib
import re
import sys
import types

import pytest

from feelflow.app import files
from feelflow.app.cli import main as cli

ROOT = pathlib.Path(__file__).resolve().parents[1]
TINY = ROOT / "tests" / "data" / "exercises" / "tiny.toml"
SESSION = ROOT / "tests" / "data" / "sessions" / "v2-midflow.ffsession"

#: an option names a file when its metavar says so
FILE_METAVAR = re.compile(r"PATH|FILE|DIR|\.\w+$")
#: options that name a file the command READS; every other file option is an output
INPUT_OPTIONS = {"gui --exercise", "report --scenes", "report --scene"}
#: values for options a command requires
REQUIRED_VALUES = {"--angles": "0"}


# --- the command line: every output option reaches the door -----------------------------------
def file_options(parser, words=()):
    """("command words", option, action) for every option of `parser` and its sub-parsers whose
    metavar names a file."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from file_options(sub, words + (name,))
        elif action.option_strings and action.metavar and FILE_METAVAR.search(action.metavar):
            yield " ".join(words), action.option_strings[-1], action


def output_options(parser):
    return [(words, opt, act) for words, opt, act in file_options(parser)
            if f"{words} {opt}".strip() not in INPUT_OPTIONS]


def positional_arguments(parser, words, inputs) -> list[list[str]]:
    """Valid positional arguments of the sub-command `words`: one list per choice of a target."""
    for w in words.split():
        parser = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices[w]
    argvs = [[]]
    for action in parser._actions:
        if action.option_strings and action.required:
            argvs = [argv + [action.option_strings[-1], REQUIRED_VALUES[action.option_strings[-1]]] for argv in argvs]
        if action.option_strings or isinstance(action, argparse._SubParsersAction) or action.nargs == "?":
            continue
        if action.choices:
            argvs = [argv + [choice] for argv in argvs for choice in sorted(action.choices)]
        else:
            argvs = [argv + [str(inputs[action.metavar])] for argv in argvs]
    return argvs


class Reached(Exception):
    """The output under test reached the door."""


class Worked(Exception):
    """A command started its work (built a solver) before its output reached the door."""


def unguarded_outputs(folder: pathlib.Path, monkeypatch) -> tuple[list[str], list[str]]:
    """(every output option of `feelflow`, those whose path never reaches the door's checks)."""
    scene = folder / "scene.toml"
    from test_file_policy import SCENE

    scene.write_text(SCENE)
    inputs = {"SCENE.toml": scene, "FILE": SESSION, "EXERCISE.toml": TINY, "SHAPES": TINY.parent / "shapes"}
    sentinel = folder / "sentinel-output"
    checks = {"check_output": files.check_output, "check_output_folder": files.check_output_folder}

    def spy(real):
        def check(path, *args, **kwargs):
            if os.path.abspath(path) == os.path.abspath(sentinel):
                raise Reached()
            return real(path, *args, **kwargs)
        return check
    parser = cli.build_parser()   # imports every command module before their names are patched
    from feelflow.solver import backend

    def no_work(*args, **kwargs):
        raise Worked()
    patches = {**{name: (real, spy(real)) for name, real in checks.items()},
               "create_solver": (backend.create_solver, no_work)}
    for module in list(sys.modules.values()):   # also the names imported at a module's top
        if isinstance(module, types.ModuleType) and module.__name__.startswith("feelflow"):
            for name, (real, patched) in patches.items():
                if getattr(module, name, None) is real:
                    monkeypatch.setattr(module, name, patched)
    try:
        return _run_outputs(parser, folder, inputs, sentinel, monkeypatch)
    finally:   # a module first imported during the runs bound a patched name: give it the real one
        for module in list(sys.modules.values()):
            if isinstance(module, types.ModuleType) and module.__name__.startswith("feelflow"):
                for name, (real, patched) in patches.items():
                    if getattr(module, name, None) is patched:
                        setattr(module, name, real)


def _run_outputs(parser, folder, inputs, sentinel, monkeypatch):
    monkeypatch.chdir(folder)
    names, missed = [], []
    for words, opt, action in output_options(parser):
        label = f"{words} {opt}".strip()
        names.append(label)
        reached = False
        # a sub-command with targets (`report seed|lessons|...`): the option must reach the door
        # for at least one of them (the others may not use it)
        for positionals in positional_arguments(parser, words, inputs) if words else [["--selftest"]]:
            try:
                cli.main([*words.split(), *positionals, opt, str(sentinel)])
            except Reached:
                reached = True
                break
            except (SystemExit, Worked):
                pass
        if not reached:
            missed.append(label)
    return names, missed


def test_every_output_option_goes_through_the_door(tmp_path, monkeypatch, capsys):
    names, missed = unguarded_outputs(tmp_path, monkeypatch)
    # the enumeration finds the outputs we know of (and any new one)
    for known in ("--screenshot", "run --out", "run --record", "session replay --out", "session export --csv",
                  "session export --manifest", "exercise score --out", "validate --json", "bench --json",
                  "report --json", "report --out"):
        assert known in names, names
    assert missed == [], f"these outputs skip app/files.py's checks: {missed}"


def bypassing_command() -> types.ModuleType:
    """A deliberately bypassing sub-command: it writes its --out with a plain open()."""
    module = types.ModuleType("feelflow.app.cli.commands.bypass")

    def add_arguments(parser):
        parser.add_argument("--out", default="bypass.txt", metavar="PATH", help="written without the door")

    def main(args):
        with open(args.out, "w") as fh:
            fh.write("written without the checks\n")
        return 0
    module.add_arguments, module.main = add_arguments, main
    return module


def test_every_option_that_writes_names_a_file():
    """An output must be found by the enumeration above: an option whose help says it writes or
    saves something has a file metavar (PATH, FILE, DIR or a suffix)."""
    found = {(words, opt) for words, opt, _ in file_options(cli.build_parser())}

    def writing(parser, words=()):
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    yield from writing(sub, words + (name,))
            elif action.option_strings and re.search(r"\b(write|writes|save|saves|record)\b", action.help or "", re.I) \
                    and action.nargs != 0:
                yield " ".join(words), action.option_strings[-1]
    hidden = [f"{w} {o}".strip() for w, o in writing(cli.build_parser()) if (w, o) not in found]
    assert hidden == [], f"options that write but have no file metavar: {hidden}"


def test_the_enumeration_catches_a_bypassing_output(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "feelflow.app.cli.commands.bypass", bypassing_command())
    monkeypatch.setitem(cli.COMMANDS, "bypass", "a command that skips the door (test only)")
    names, missed = unguarded_outputs(tmp_path, monkeypatch)
    assert "bypass --out" in names and missed == ["bypass --out"]


# --- the code: every writer writes through atomic_path ------------------------------------------
#: calls that write a file, by name (a function or a method)
WRITERS = {"write_text", "write_bytes", "savez", "savez_compressed", "tofile", "savefig", "export", "mkstemp",
           "NamedTemporaryFile", "copyfile", "copy2", "get_writer", "imwrite", "mimwrite", "to_csv"}
#: writers that are not a user's file, with the reason (file, writer) -> why
ALLOWED = {
    ("app/sessions/format.py", "savez"): "into an in-memory buffer (io.BytesIO), then the atomic writer",
    ("haptics/process_loop.py", "fdopen"): "the force loop's own standard output (a pipe to its parent)",
    ("haptics/process_loop.py", "open"): "the force loop's shared-memory block, not a user's file",
    ("haptics/process_loop.py", "mkstemp"): "the force loop's shared-memory block, not a user's file",
}
PRODUCTION = ("app", "solver", "shapes", "haptics")


def _writes_mode(call: ast.Call) -> bool:
    mode = call.args[1] if len(call.args) >= 2 else next((k.value for k in call.keywords if k.arg == "mode"), None)
    if mode is None:
        return False
    return not (isinstance(mode, ast.Constant) and isinstance(mode.value, str)) or any(c in mode.value for c in "wax+")


def writer_name(call: ast.Call) -> str | None:
    """The name of the write this call makes, or None when it writes no file."""
    f = call.func
    if isinstance(f, ast.Name):
        if f.id == "open":
            return "open" if _writes_mode(call) else None
        return f.id if f.id in WRITERS else None
    if not isinstance(f, ast.Attribute):
        return None
    receiver = ast.unparse(f.value)
    if f.attr == "open" and receiver == "os":
        flags = ast.unparse(call.args[1]) if len(call.args) > 1 else ""
        return "os.open" if re.search(r"O_WRONLY|O_RDWR|O_CREAT", flags) else None
    if f.attr == "open":   # path.open("w"), av.open(path, "w"): a literal write mode (zf.open(name) reads)
        modes = list(call.args[:2]) + [k.value for k in call.keywords if k.arg == "mode"]
        writes = any(isinstance(m, ast.Constant) and isinstance(m.value, str) and re.fullmatch(r"[rwaxbt+]{1,3}", m.value)
                     and any(c in m.value for c in "wax+") for m in modes)
        return "open" if writes else None
    if f.attr == "fdopen":
        return "fdopen" if _writes_mode(call) else None
    if f.attr == "save":   # numpy's np.save, and QImage/QPixmap.save(path, format)
        return "save" if receiver in ("np", "numpy") or len(call.args) >= 2 else None
    if f.attr in ("replace", "rename"):
        return f.attr if receiver == "os" else None
    if f.attr in ("copy", "move", "copyfile", "copy2"):
        return f.attr if receiver == "shutil" else None
    return f.attr if f.attr in WRITERS else None


@functools.lru_cache(maxsize=None)
def parsed(path: pathlib.Path) -> ast.Module:
    return ast.parse(path.read_text(encoding="utf-8"))


def unguarded_writers(source, name: str) -> list[str]:
    """`name:line writer` for every call in `source` (text or a parsed module) that writes a file
    outside a `with atomic_path(...) as tmp:` block writing to `tmp`."""
    tree = ast.parse(source) if isinstance(source, str) else source
    found = []

    def is_door(expr) -> bool:
        return any(isinstance(n, ast.Call) and ast.unparse(n.func).split(".")[-1] == "atomic_path"
                   for n in ast.walk(expr))
    # a temporary kept for later (`self._tmp = stack.enter_context(atomic_path(path))`)
    kept = frozenset(ast.unparse(t) for n in ast.walk(tree) if isinstance(n, ast.Assign) and is_door(n.value)
                     for t in n.targets)

    def visit(node, temporaries):
        if isinstance(node, (ast.With, ast.AsyncWith)):
            temporaries = temporaries | {ast.unparse(item.optional_vars) for item in node.items
                                         if item.optional_vars is not None and is_door(item.context_expr)}
        if isinstance(node, ast.Call):
            writer = writer_name(node)
            if writer is not None:
                target = node.args[0] if node.args else node.func
                if isinstance(node.func, ast.Attribute) and writer in ("write_text", "write_bytes", "tofile"):
                    target = node.func.value
                elif isinstance(node.func, ast.Attribute) and writer == "open" and not (
                        node.args and isinstance(node.args[0], ast.Constant)) and node.args:
                    target = node.args[0]                      # av.open(path, "w")
                elif isinstance(node.func, ast.Attribute) and writer == "open":
                    target = node.func.value                   # path.open("w")
                text = ast.unparse(target)
                if not any(re.search(rf"(?<![\w.]){re.escape(t)}(?![\w])", text) for t in temporaries):
                    found.append(f"{name}:{node.lineno} {writer}")
        for child in ast.iter_child_nodes(node):
            visit(child, temporaries)
    visit(tree, kept)
    return found


#: text every writer call contains: a file without any is not parsed (it cannot write)
MAY_WRITE = re.compile(r"open\(|write_text|write_bytes|\.save|savez|savefig|\.export\(|mkstemp|Temporary|"
                       r"replace\(|rename\(|shutil|tofile|imwrite|get_writer|to_csv|copyfile|copy2")


def production_writers() -> list[str]:
    out = []
    for top in PRODUCTION:
        for path in sorted((ROOT / top).rglob("*.py")):
            rel = path.relative_to(ROOT).as_posix()
            if rel == "app/files.py" or not MAY_WRITE.search(path.read_text(encoding="utf-8")):
                continue   # the door itself, and modules that cannot write
            for hit in unguarded_writers(parsed(path), rel):
                if (rel, hit.split()[-1]) not in ALLOWED:
                    out.append(hit)
    return out


def test_every_writer_in_the_code_and_the_window_goes_through_the_door():
    gui = sorted((ROOT / "app" / "gui").rglob("*.py"))
    assert len(gui) > 10   # the window's modules are scanned (with the rest of the production code)
    assert production_writers() == []


BYPASSING_WINDOW_CODE = '''
from feelflow.app.files import atomic_path

def save_screenshot(image, path):
    with atomic_path(path, suffix=".png") as tmp:
        image.save(str(tmp), "PNG")            # through the door

def export_notes(path, text):
    with open(path, "w") as fh:                # a deliberate bypass
        fh.write(text)

def export_pixels(image, path):
    image.save(path, "PNG")                    # another one

def export_array(a, path):
    np.save(path, a)                           # and another

def export_log(path, text):
    with path.open("a") as fh:                 # and one through pathlib
        fh.write(text)

class Clip:
    def __init__(self, path, stack):
        self._tmp = stack.enter_context(atomic_path(path))
        self._container = av.open(str(self._tmp), "w")   # through the door (kept temporary)
        self._log = av.open(str(path), "w")                # a bypass
'''


def test_the_writer_scan_catches_bypassing_writers():
    assert unguarded_writers(BYPASSING_WINDOW_CODE, "bypass.py") == [
        "bypass.py:9 open", "bypass.py:13 save", "bypass.py:16 save", "bypass.py:19 open", "bypass.py:26 open"]


def test_no_core_package_writes_files_at_all():
    """The Qt-free core (solver, shapes) never writes a file: writing is the app's door."""
    for top in ("solver", "shapes"):
        for path in sorted((ROOT / top).rglob("*.py")):
            if not MAY_WRITE.search(path.read_text(encoding="utf-8")):
                continue
            calls = [n for n in ast.walk(parsed(path)) if isinstance(n, ast.Call) and writer_name(n)]
            assert calls == [], (path, [ast.unparse(c)[:60] for c in calls])


def test_a_bypassed_output_really_loses_a_file(tmp_path, capsys):
    """Why the door matters: the bypassing command replaces a file the door would have kept."""
    kept = tmp_path / "results.csv"
    kept.write_text("a teacher's results\n")
    module = bypassing_command()
    parser = argparse.ArgumentParser()
    module.add_arguments(parser)
    module.main(parser.parse_args(["--out", str(kept)]))
    assert kept.read_text() != "a teacher's results\n"
    kept.write_text("a teacher's results\n")
    with pytest.raises(files.OutputError, match="already exists"):
        files.check_output(kept, "--out")
