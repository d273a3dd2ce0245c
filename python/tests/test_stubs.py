"""The hand-written stubs name everything the native module defines, with the same signatures
where Python can read them."""

import ast
import inspect
from pathlib import Path

import pytest

import fuzzyvox
from fuzzyvox import _native

STUB = Path(fuzzyvox.__file__).with_name("_native.pyi")


def stub_tree():
    assert STUB.is_file(), "the stubs ship with the package"
    assert STUB.with_name("py.typed").is_file()
    return ast.parse(STUB.read_text())


def public(obj):
    return {n for n in dir(obj) if not n.startswith("_")}


def test_stubs_name_every_module_level_name():
    tree = stub_tree()
    names = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            names.add(node.target.id)
        elif isinstance(node, ast.Assign):
            names.update(t.id for t in node.targets)
    assert public(_native) <= names, public(_native) - names


def stub_members(tree, name, seen=None):
    classes = {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}
    node = classes[name]
    members = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
    for base in node.bases:
        if isinstance(base, ast.Name) and base.id in classes:
            members |= stub_members(tree, base.id)
    return members


@pytest.mark.parametrize(
    "cls",
    [c for c in vars(_native).values() if isinstance(c, type) and not issubclass(c, Exception)],
    ids=lambda c: c.__name__,
)
def test_stubs_name_every_method(cls):
    members = stub_members(stub_tree(), cls.__name__)
    assert public(cls) <= members, public(cls) - members
    assert cls.__doc__, f"{cls.__name__} has a docstring"


def test_every_function_has_a_docstring_and_its_stub_signature():
    tree = stub_tree()
    stubs = {n.name: n for n in tree.body if isinstance(n, ast.FunctionDef)}
    for name in public(_native):
        obj = getattr(_native, name)
        if not callable(obj) or isinstance(obj, type):
            continue
        assert obj.__doc__, name
        params = list(inspect.signature(obj).parameters)
        stub = stubs[name].args
        keywords = [stub.kwarg.arg] if stub.kwarg else []
        assert params == [a.arg for a in stub.args] + keywords, name
