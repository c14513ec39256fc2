"""The hand-written stubs (armsim/_armsim.pyi) against the extension module itself: every
public function, class, method, property and constant of ``armsim._armsim`` appears in
the stub with the same kind, the same parameter names, kinds and defaults, and the stub
declares nothing the module lacks. The runtime side is read with ``inspect.signature``
(PyO3's ``__text_signature__``); the stub side with ``ast``."""

from __future__ import annotations

import ast
import inspect
import pytest

from armsim import _armsim
from conftest import ROOT

STUB = ROOT / "python" / "armsim" / "_armsim.pyi"

# What a stub parameter says: (name, kind, default), default one of NO_DEFAULT, UNKNOWN
# (the stub writes `...`) or the literal value.
NO_DEFAULT, UNKNOWN = "<none>", "<...>"
KINDS = {
    "posonlyargs": inspect.Parameter.POSITIONAL_ONLY,
    "args": inspect.Parameter.POSITIONAL_OR_KEYWORD,
    "kwonlyargs": inspect.Parameter.KEYWORD_ONLY,
}


def stub_params(fn: ast.FunctionDef) -> list[tuple[str, object, object]]:
    a = fn.args
    positional = a.posonlyargs + a.args
    defaults = [NO_DEFAULT] * (len(positional) - len(a.defaults)) + list(a.defaults)
    out = []
    for arg, d in zip(positional, defaults):
        kind = KINDS["posonlyargs"] if arg in a.posonlyargs else KINDS["args"]
        out.append((arg.arg, kind, literal(d)))
    if a.vararg:
        out.append((a.vararg.arg, inspect.Parameter.VAR_POSITIONAL, NO_DEFAULT))
    for arg, d in zip(a.kwonlyargs, a.kw_defaults):
        out.append((arg.arg, KINDS["kwonlyargs"], literal(d)))
    if a.kwarg:
        out.append((a.kwarg.arg, inspect.Parameter.VAR_KEYWORD, NO_DEFAULT))
    return out


def literal(node):
    if node is NO_DEFAULT or node is None:
        return NO_DEFAULT
    if isinstance(node, ast.Constant) and node.value is Ellipsis:
        return UNKNOWN
    return ast.literal_eval(node)


def runtime_params(obj) -> list[tuple[str, object, object]]:
    sig = inspect.signature(obj)
    return [(p.name, p.kind, NO_DEFAULT if p.default is p.empty else p.default)
            for p in sig.parameters.values()]


def same_params(stub, runtime) -> bool:
    """Equal names, kinds and defaults; a stub default of `...` matches any default."""
    if len(stub) != len(runtime):
        return False
    for (sn, sk, sd), (rn, rk, rd) in zip(stub, runtime):
        if sn != rn or sk != rk:
            return False
        if sd is UNKNOWN:
            if rd is NO_DEFAULT:
                return False
        elif sd != rd or type(sd) is not type(rd):
            return False
    return True


def decorators(fn: ast.FunctionDef) -> set[str]:
    names = set()
    for d in fn.decorator_list:
        names.add(d.id if isinstance(d, ast.Name) else ast.unparse(d))
    return names


def stub_members(body) -> dict[str, tuple[str, object]]:
    """Public names of a stub body: `function`/`staticmethod` (with parameters),
    `attribute` (a property or an annotated name) and `class` (with its node)."""
    out: dict[str, tuple[str, object]] = {}
    for node in body:
        if isinstance(node, ast.FunctionDef):
            decos = decorators(node)
            if "property" in decos or any(d.endswith(".setter") for d in decos):
                out[node.name] = ("attribute", None)
            elif "staticmethod" in decos:
                out[node.name] = ("staticmethod", stub_params(node))
            else:
                out[node.name] = ("function", stub_params(node))
        elif isinstance(node, ast.ClassDef):
            out[node.name] = ("class", node)
        elif isinstance(node, ast.AnnAssign) and node.value is None:
            out[node.target.id] = ("attribute", None)
    return {k: v for k, v in out.items() if not k.startswith("_") or k == "__init__"}


def runtime_kind(owner, name: str) -> str:
    raw = inspect.getattr_static(owner, name)
    if isinstance(raw, staticmethod):
        return "staticmethod"
    if inspect.isclass(raw):
        return "class"
    if inspect.isroutine(raw):
        return "function"
    return "attribute"


def runtime_members(owner) -> dict[str, str]:
    names = vars(owner) if inspect.isclass(owner) else {n: None for n in dir(owner)}
    return {n: runtime_kind(owner, n) for n in names if not n.startswith("_")}


@pytest.fixture(scope="module")
def stub() -> dict[str, tuple[str, object]]:
    module = ast.parse(STUB.read_text(encoding="utf-8"), str(STUB))
    return stub_members(module.body)


def test_the_stub_and_the_module_name_the_same_public_things(stub):
    runtime = runtime_members(_armsim)
    assert sorted(runtime) == sorted(stub), (
        f"only in the module: {sorted(set(runtime) - set(stub))}; "
        f"only in the stub: {sorted(set(stub) - set(runtime))}")
    for name, kind in runtime.items():
        assert stub[name][0] == kind, f"{name}: a {kind} in the module, a {stub[name][0]} in the stub"


def test_module_functions_have_the_stubs_parameters(stub):
    functions = [n for n, (kind, _) in stub.items() if kind == "function"]
    assert len(functions) >= 15
    for name in functions:
        got, want = runtime_params(getattr(_armsim, name)), stub[name][1]
        assert same_params(want, got), f"{name}: stub {want} vs module {got}"


def test_classes_have_the_stubs_members_and_parameters(stub):
    classes = [n for n, (kind, _) in stub.items() if kind == "class"]
    assert {"Model", "Data", "Robot", "IkResult", "ArmsimError"} <= set(classes)
    for cname in classes:
        cls, node = getattr(_armsim, cname), stub[cname][1]
        assert [ast.unparse(b) for b in node.bases] == [b.__name__ for b in cls.__bases__
                                                       if b is not object], cname
        members = stub_members(node.body)
        init = members.pop("__init__", None)
        runtime = runtime_members(cls)
        assert sorted(runtime) == sorted(members), (
            f"{cname}: only in the module: {sorted(set(runtime) - set(members))}; "
            f"only in the stub: {sorted(set(members) - set(runtime))}")
        for name, kind in runtime.items():
            skind, want = members[name]
            assert skind == kind, f"{cname}.{name}: a {kind} in the module, a {skind} in the stub"
            if kind == "function" and want[:1] and want[0][0] == "self":
                # `self` is positional-only at run time (PyO3's `$self`).
                want = [("self", inspect.Parameter.POSITIONAL_ONLY, want[0][2])] + want[1:]
            if kind != "attribute":
                got = runtime_params(getattr(cls, name) if kind == "staticmethod"
                                     else inspect.getattr_static(cls, name))
                assert same_params(want, got), f"{cname}.{name}: stub {want} vs module {got}"
        # A constructor: the stub's __init__ without `self` is the class's signature.
        if init is not None:
            got = runtime_params(cls)
            assert same_params(init[1][1:], got), f"{cname}(): stub {init[1]} vs module {got}"
        elif not issubclass(cls, BaseException):
            with pytest.raises(TypeError):
                cls()


def test_the_checker_notices_a_renamed_parameter_and_a_changed_default():
    fn = ast.parse("def f(model, q, frame=None, *, seed: int = 0, **kwargs): ...").body[0]
    want = stub_params(fn)
    assert same_params(want, runtime_params(lambda model, q, frame=None, *, seed=0, **kwargs: 0))
    assert not same_params(want, runtime_params(lambda model, qs, frame=None, *, seed=0, **kwargs: 0))
    assert not same_params(want, runtime_params(lambda model, q, frame="x", *, seed=0, **kwargs: 0))
    assert not same_params(want, runtime_params(lambda model, q, frame=None, seed=0, **kwargs: 0))
    assert not same_params(want, runtime_params(lambda model, q, frame=None, *, seed=0.0, **kwargs: 0))
