"""The type stubs (python/tandem/_tandem.pyi) describe exactly what the extension exports."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import tandem
from tandem import _tandem

STUBS = Path(tandem.__file__).with_name("_tandem.pyi")


def stub_tree():
    return ast.parse(STUBS.read_text())


def public(names):
    return {n for n in names if not n.startswith("_") or n == "__version__"}


def test_stubs_name_every_export_and_nothing_else() -> None:
    tree = stub_tree()
    stubbed = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            stubbed.add(node.name)
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            stubbed.add(node.target.id)
    aliases = {"F64", "Bool", "I64", "ArrayLike", "Path", "Params", "Demo"}
    assert public(dir(_tandem)) == stubbed - aliases


def test_stub_classes_list_every_public_member() -> None:
    for node in stub_tree().body:
        if not isinstance(node, ast.ClassDef) or issubclass(getattr(_tandem, node.name), Exception):
            continue
        cls = getattr(_tandem, node.name)
        stubbed = {
            n.name
            for n in node.body
            if isinstance(n, ast.FunctionDef) and not n.name.startswith("__")
        }
        real = {n for n, _ in inspect.getmembers(cls) if not n.startswith("_")}
        assert real == stubbed, node.name


def test_package_exports_and_py_typed() -> None:
    assert Path(tandem.__file__).with_name("py.typed").exists()
    for name in tandem.__all__:
        assert hasattr(tandem, name), name
    for exc in ("InputError", "ParamError", "StateFileError", "ScheduleError", "InternalError"):
        assert issubclass(getattr(tandem, exc), tandem.TandemError)
    assert issubclass(tandem.TandemError, Exception)
