"""Rules of the house the code is held to (docs/developer/architecture.md): no production module
reads another object's private attribute, and the model's and the sessions' classes set up every
attribute they hold in their constructor (a reader finds it there)."""
from __future__ import annotations

import ast
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[1]
PRODUCTION = ("app", "solver", "shapes", "haptics")


def modules(*packages):
    for pkg in packages:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            yield path, ast.parse(path.read_text())


def private_reads(tree):
    """`x._name` where x is not self, cls or super(); an explicit base-class call
    (`Base._method(self, ...)`) is the object's own method."""
    own_calls = {id(node.func) for node in ast.walk(tree) if isinstance(node, ast.Call)
                 and isinstance(node.func, ast.Attribute) and node.args
                 and isinstance(node.args[0], ast.Name) and node.args[0].id == "self"}
    for node in ast.walk(tree):
        if not (isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__")):
            continue
        v = node.value
        if isinstance(v, ast.Name) and v.id in ("self", "cls"):
            continue
        if isinstance(v, ast.Call) and isinstance(v.func, ast.Name) and v.func.id == "super":
            continue
        if id(node) in own_calls:
            continue
        yield node


def test_no_module_reads_another_objects_private_names():
    found = [f"{path.relative_to(ROOT)}:{node.lineno}: {ast.unparse(node)}"
             for path, tree in modules(*PRODUCTION) for node in private_reads(tree)]
    assert found == []


def attributes_first_set_outside_init(cls: ast.ClassDef):
    declared = {t.target.id for t in cls.body if isinstance(t, ast.AnnAssign) and isinstance(t.target, ast.Name)}
    declared |= {t.id for a in cls.body if isinstance(a, ast.Assign) for t in a.targets if isinstance(t, ast.Name)}
    declared |= {f.name for f in cls.body if isinstance(f, ast.FunctionDef)}
    constructed, elsewhere = set(), {}
    for f in cls.body:
        if not isinstance(f, ast.FunctionDef):
            continue
        for node in ast.walk(f):
            targets = node.targets if isinstance(node, ast.Assign) else \
                [node.target] if isinstance(node, (ast.AugAssign, ast.AnnAssign)) else []
            for t in targets:
                for e in ast.walk(t):
                    if isinstance(e, ast.Attribute) and isinstance(e.value, ast.Name) and e.value.id == "self":
                        if f.name in ("__init__", "__post_init__"):
                            constructed.add(e.attr)
                        else:
                            elsewhere.setdefault(e.attr, f.name)
    return {a: f for a, f in elsewhere.items() if a not in constructed and a not in declared}


def test_model_and_session_classes_set_up_what_they_hold_in_their_constructor():
    found = [f"{path.relative_to(ROOT)}: {cls.name}.{attr} first set in {where}()"
             for path, tree in modules("app/model", "app/sessions")
             for cls in ast.walk(tree) if isinstance(cls, ast.ClassDef)
             for attr, where in attributes_first_set_outside_init(cls).items()]
    assert found == []
