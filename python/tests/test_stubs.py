"""The type stubs of the extension (``macrotree/_native.pyi``) hold to the extension itself:
the same names at module level, the same classes with the same methods and attributes, and every
function's and method's parameters — names, order, keyword-only or not, with a default or not —
as the compiled extension declares them (PyO3's text signatures). A change on the Rust side that
the stub does not follow fails here."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path
from typing import Any

import macrotree._native as native

STUB = Path(native.__file__).with_name("_native.pyi")
if not STUB.exists():  # an editable checkout: the stub beside the sources
    STUB = Path(__file__).resolve().parents[1] / "macrotree" / "_native.pyi"

Parameter = tuple[str, str, bool]


def _stub_parameters(f: ast.FunctionDef, method: bool) -> list[Parameter]:
    """(name, kind, has a default) of each parameter of a stub function, ``self`` left out."""
    a = f.args
    positional = [*a.posonlyargs, *a.args]
    if method:
        positional = positional[1:]
    defaults = [False] * (len(positional) - len(a.defaults)) + [True] * len(a.defaults)
    out: list[Parameter] = [
        (p.arg, "positional", d) for p, d in zip(positional, defaults, strict=True)
    ]
    out += [
        (p.arg, "keyword", d is not None) for p, d in zip(a.kwonlyargs, a.kw_defaults, strict=True)
    ]
    return out


def _runtime_parameters(f: Any) -> list[Parameter]:
    """The same of a compiled function, method or constructor (``self`` left out)."""
    kinds = {
        inspect.Parameter.POSITIONAL_ONLY: "positional",
        inspect.Parameter.POSITIONAL_OR_KEYWORD: "positional",
        inspect.Parameter.KEYWORD_ONLY: "keyword",
    }
    out: list[Parameter] = []
    for p in inspect.signature(f).parameters.values():
        if p.name == "self":
            continue
        assert p.kind in kinds, f"{f}: parameter {p.name} is {p.kind}"
        out.append((p.name, kinds[p.kind], p.default is not inspect.Parameter.empty))
    return out


def _stub() -> ast.Module:
    return ast.parse(STUB.read_text(encoding="utf-8"))


def _public(names: list[str]) -> set[str]:
    return {n for n in names if not n.startswith("_")}


def test_the_stub_names_what_the_extension_has_at_module_level() -> None:
    stub = set()
    for node in _stub().body:
        if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            stub.add(node.target.id)
        elif isinstance(node, ast.FunctionDef | ast.ClassDef):
            stub.add(node.name)
    runtime = _public(dir(native)) | {"__version__"}
    assert _public(sorted(stub)) | {"__version__"} == runtime


def test_every_function_of_the_stub_has_the_extensions_parameters() -> None:
    for node in _stub().body:
        if isinstance(node, ast.FunctionDef):
            runtime = _runtime_parameters(getattr(native, node.name))
            assert _stub_parameters(node, method=False) == runtime, node.name


def test_every_class_of_the_stub_has_the_extensions_methods_attributes_and_parameters() -> None:
    for node in _stub().body:
        if not isinstance(node, ast.ClassDef):
            continue
        cls = getattr(native, node.name)
        own = vars(cls)
        methods = {
            n: v for n, v in own.items() if not n.startswith("_") and inspect.ismethoddescriptor(v)
        }
        attributes = {n for n, v in own.items() if inspect.isgetsetdescriptor(v) and n[0] != "_"}
        stub_methods = {
            f.name: f for f in node.body if isinstance(f, ast.FunctionDef) and f.name != "__init__"
        }
        stub_attributes = {
            a.target.id
            for a in node.body
            if isinstance(a, ast.AnnAssign) and isinstance(a.target, ast.Name)
        }
        assert set(stub_methods) == set(methods), node.name
        assert stub_attributes == attributes, node.name
        for name, f in stub_methods.items():
            assert _stub_parameters(f, method=True) == _runtime_parameters(methods[name]), (
                f"{node.name}.{name}"
            )
        init = [f for f in node.body if isinstance(f, ast.FunctionDef) and f.name == "__init__"]
        if init:
            assert _stub_parameters(init[0], method=True) == _runtime_parameters(cls), (
                f"{node.name}()"
            )
