"""Safe evaluation of xacro expressions (``${...}`` and ``$(eval ...)``).

xacro evaluates expressions with Python ``eval``; forbidding ``__`` names, as xacro does, is not
enough (a generator's ``gi_frame.f_back.f_globals`` reaches ``os``; ``$(eval ...)`` sees every
builtin; ``str.format`` walks ``__globals__`` inside a string). Here every expression is

1. validated with ``ast`` (``check_expression``): literals, names, operators, conditional
   expressions, subscripts, comprehensions, calls and attribute access; no lambdas, no ``:=``,
   no dunder names, no attributes of frames, code objects, generators or tracebacks; then
2. compiled with guards around every attribute access, call and size-sensitive operator, so that
   at run time attributes are an allow-list per type (properties and YAML keys of namespaces and
   dictionaries, the methods of ``str``/``list``/``dict``/numbers) and only the functions xacro
   documents (math, ``python.*`` less ``type``/``vars``, ``xacro.*``) and those methods can be
   called, also indirectly through ``map``/``sorted(key=...)``.

What the allow-list admits evaluates exactly as in plain xacro (same operations, same objects);
anything else raises ``UnsafeExpression`` (reported as ``xacro.unsafe-expression``). Huge numbers
and sequences, and running past the deadline, raise ``LimitExceeded`` (``xacro.limit-exceeded``).
"""

from __future__ import annotations

import ast
import math
import operator
import re
import time
import types

# Attributes of interpreter internals: never legitimate in a robot description.
FRAME_ATTRS = frozenset({
    "gi_frame", "gi_code", "gi_yieldfrom", "gi_running", "gi_suspended",
    "cr_frame", "cr_code", "cr_await", "cr_origin", "cr_running", "cr_suspended",
    "ag_frame", "ag_code", "ag_await", "ag_running",
    "f_back", "f_builtins", "f_code", "f_globals", "f_locals", "f_trace", "f_trace_lines",
    "f_trace_opcodes", "f_lasti", "f_lineno",
    "tb_frame", "tb_next", "tb_lasti", "tb_lineno",
    "co_code", "co_consts", "co_names", "co_varnames", "co_freevars", "co_cellvars",
    "co_filename", "co_name", "co_qualname", "co_firstlineno", "co_lnotab", "co_linetable",
    "co_exceptiontable", "co_flags", "co_argcount", "co_kwonlyargcount", "co_posonlyargcount",
    "co_nlocals", "co_stacksize", "co_positions", "co_lines",
    "func_globals", "func_code", "func_closure", "func_defaults", "func_dict",
    "im_func", "im_self", "im_class", "mro", "format_map",
})

_ALLOWED_NODES = (
    ast.Expression, ast.Constant, ast.Name, ast.Load, ast.Store, ast.BinOp, ast.UnaryOp,
    ast.BoolOp, ast.Compare, ast.IfExp, ast.Subscript, ast.Slice, ast.Tuple, ast.List, ast.Dict,
    ast.Set, ast.Call, ast.keyword, ast.Attribute, ast.Starred, ast.JoinedStr,
    ast.FormattedValue, ast.ListComp, ast.SetComp, ast.DictComp, ast.GeneratorExp,
    ast.comprehension, ast.operator, ast.unaryop, ast.boolop, ast.cmpop, ast.expr_context,
)
_NODE_WORDS = {ast.Lambda: "a lambda", ast.NamedExpr: "an assignment expression (:=)",
               ast.Await: "await", ast.Yield: "yield", ast.YieldFrom: "yield from"}

MAX_INT_BITS = 1 << 20  # ~315 000 decimal digits
MAX_ITEMS = 10_000_000  # characters or items of one sequence made by * or range()

_G_ATTR, _G_CALL, _G_BINOP = "__urdftool_attr", "__urdftool_call", "__urdftool_binop"
_G_ITER = "__urdftool_iter"


class UnsafeExpression(Exception):
    """An expression urdftool refuses to evaluate."""

    def __init__(self, expression: str, reason: str, partial: bool = False):
        super().__init__(f"unsafe expression '{expression}': {reason}")
        self.expression, self.reason = expression, reason
        self.partial = partial  # raised by a guard: ``expression`` is only the offending part


class LimitExceeded(Exception):
    """Expansion went past a time, size or recursion limit."""


# -- static validation ----------------------------------------------------------------------


def check_expression(expression: str) -> ast.Expression:
    """Parse ``expression`` and validate it against the allow-list. Raises SyntaxError as
    ``eval`` would, or UnsafeExpression; returns the tree."""
    text = expression.strip()
    try:
        tree = ast.parse(text, "<expression>", "eval")
    except (RecursionError, MemoryError):
        raise UnsafeExpression(text, "nested too deeply") from None
    for node in ast.walk(tree):
        if not isinstance(node, _ALLOWED_NODES):
            word = _NODE_WORDS.get(type(node), f"'{type(node).__name__}'")
            raise UnsafeExpression(text, f"{word} is not allowed in a xacro expression")
        if isinstance(node, ast.Name) and node.id.startswith("__"):
            raise UnsafeExpression(text, f"name '{node.id}': names starting with __ are not allowed")
        if isinstance(node, ast.Attribute):
            if node.attr.startswith("__"):
                raise UnsafeExpression(text, f"attribute '{node.attr}': dunder attributes are not "
                                             "allowed")
            if node.attr in FRAME_ATTRS:
                raise UnsafeExpression(text, f"attribute '{node.attr}' reaches interpreter "
                                             "internals (frames, code, generators)")
            if not isinstance(node.ctx, ast.Load):
                raise UnsafeExpression(text, "assigning to an attribute is not allowed")
        if isinstance(node, ast.comprehension):
            for target in ast.walk(node.target):
                if isinstance(target, (ast.Attribute, ast.Subscript)):
                    raise UnsafeExpression(text, "a comprehension may only assign to names")
        if isinstance(node, ast.Subscript) and not isinstance(node.ctx, ast.Load):
            raise UnsafeExpression(text, "assigning to an item is not allowed")
    return tree


def scan(value: str) -> list[UnsafeExpression]:
    """Statically validate every literal ``${...}`` and ``$(eval ...)`` in an attribute value or
    text (as xacro's lexer splits it). Expressions built from other expressions are checked when
    they are evaluated."""
    import xacro

    found = []
    if "$" not in value:
        return found
    lexer = xacro.QuickLexer(xacro.LEXER)
    try:
        lexer.lex(value)
        while lexer.peek():
            kind, token = lexer.next()
            body = None
            if kind == lexer.EXPR:
                body = token[2:-1]
            elif kind == lexer.EXTENSION and token[2:].lstrip().startswith("eval "):
                body = token[2:-1].lstrip()[len("eval "):]
            if body is None or "$" in body:
                continue
            try:
                check_expression(body)
            except UnsafeExpression as exc:
                found.append(exc)
            except SyntaxError:
                pass  # xacro reports it when (if) it evaluates it
    except Exception:  # noqa: BLE001, S110 - xacro's lexer rejects it; xacro will say so
        pass
    return found


# -- guarded compilation ----------------------------------------------------------------------


class _Guard(ast.NodeTransformer):
    def visit_Attribute(self, node):
        self.generic_visit(node)
        return ast.copy_location(ast.Call(ast.Name(_G_ATTR, ast.Load()),
                                          [node.value, ast.Constant(node.attr)], []), node)

    def visit_Call(self, node):
        self.generic_visit(node)
        return ast.copy_location(ast.Call(ast.Name(_G_CALL, ast.Load()),
                                          [node.func, *node.args], node.keywords), node)

    def visit_comprehension(self, node):
        self.generic_visit(node)
        node.iter = ast.copy_location(ast.Call(ast.Name(_G_ITER, ast.Load()), [node.iter], []),
                                      node.iter)
        return node

    def visit_BinOp(self, node):
        self.generic_visit(node)
        if isinstance(node.op, (ast.Pow, ast.LShift, ast.Mult, ast.Mod)):
            name = type(node.op).__name__
            return ast.copy_location(ast.Call(ast.Name(_G_BINOP, ast.Load()),
                                              [ast.Constant(name), node.left, node.right], []),
                                     node)
        return node


_CODE_CACHE: dict[str, types.CodeType] = {}


def compile_guarded(expression: str) -> types.CodeType:
    """Validated, guarded code for an expression (cached)."""
    code = _CODE_CACHE.get(expression)
    if code is None:
        tree = _Guard().visit(check_expression(expression))
        code = compile(ast.fix_missing_locations(tree), "<expression>", "eval")
        if len(_CODE_CACHE) > 20000:
            _CODE_CACHE.clear()
        _CODE_CACHE[expression] = code
    return code


# -- run-time allow-lists ---------------------------------------------------------------------

_STR_METHODS = frozenset([
    "capitalize", "casefold", "center", "count", "encode", "endswith", "expandtabs", "find",
    "format", "index", "isalnum", "isalpha", "isascii", "isdecimal", "isdigit", "isidentifier",
    "islower", "isnumeric", "isprintable", "isspace", "istitle", "isupper", "join", "ljust",
    "lower", "lstrip", "maketrans", "partition", "removeprefix", "removesuffix", "replace",
    "rfind", "rindex", "rjust", "rpartition", "rsplit", "rstrip", "split", "splitlines",
    "startswith", "strip", "swapcase", "title", "translate", "upper", "zfill"
])
_BYTES_METHODS = frozenset([
    "decode", "hex", "count", "endswith", "startswith", "find", "index", "split", "strip",
    "lower", "upper", "replace", "join"
])
_LIST_METHODS = frozenset([
    "append", "clear", "copy", "count", "extend", "index", "insert", "pop", "remove", "reverse",
    "sort"
])
_TUPLE_METHODS = frozenset({"count", "index"})
_DICT_METHODS = frozenset([
    "clear", "copy", "fromkeys", "get", "items", "keys", "pop", "popitem", "setdefault",
    "update", "values"
])
_SET_METHODS = frozenset([
    "add", "clear", "copy", "difference", "difference_update", "discard", "intersection",
    "intersection_update", "isdisjoint", "issubset", "issuperset", "pop", "remove",
    "symmetric_difference", "symmetric_difference_update", "union", "update"
])
_NUMBER_METHODS = frozenset([
    "real", "imag", "conjugate", "is_integer", "as_integer_ratio", "bit_length", "bit_count",
    "hex", "fromhex", "from_bytes", "to_bytes", "numerator", "denominator"
])
_RANGE_METHODS = frozenset({"start", "stop", "step", "count", "index"})
_SLICE_METHODS = frozenset({"start", "stop", "step", "indices"})

_METHODS: dict[type, frozenset] = {
    str: _STR_METHODS, bytes: _BYTES_METHODS, list: _LIST_METHODS, tuple: _TUPLE_METHODS,
    dict: _DICT_METHODS, set: _SET_METHODS, frozenset: _SET_METHODS - {
        "add", "clear", "difference_update", "discard", "intersection_update", "pop", "remove",
        "symmetric_difference_update", "update"},
    int: _NUMBER_METHODS, float: _NUMBER_METHODS, complex: _NUMBER_METHODS,
    bool: _NUMBER_METHODS, range: _RANGE_METHODS, slice: _SLICE_METHODS,
}

# Builtins visible to $(eval ...): what roslaunch-style expressions use, nothing that reaches
# files, code, attributes by name or interpreter internals.
SAFE_BUILTIN_NAMES = [
    "abs", "all", "any", "ascii", "bin", "bool", "bytes", "callable", "chr", "complex", "dict",
    "divmod", "enumerate", "filter", "float", "format", "frozenset", "hash", "hex", "int",
    "isinstance", "issubclass", "len", "list", "map", "max", "min", "oct", "ord", "pow",
    "range", "repr", "reversed", "round", "set", "slice", "sorted", "str", "sum", "tuple", "zip"
]


UNSAFE_BUILTIN_NAMES = frozenset([
    "breakpoint", "compile", "delattr", "dir", "eval", "exec", "exit", "getattr", "globals",
    "hasattr", "help", "id", "input", "iter", "locals", "memoryview", "next", "object", "open",
    "print", "property", "quit", "setattr", "super", "type", "vars"
])


def _methods_for(kind: type) -> frozenset | None:
    for base in kind.__mro__:
        if base in _METHODS:
            return _METHODS[base]
    return None


class _SafeFormat:
    """``str.format`` that refuses attribute lookups in replacement fields ('{0.attr}')."""

    __slots__ = ("template", "unbound")

    def __init__(self, template=None, unbound=False):
        self.template, self.unbound = template, unbound

    def __call__(self, *args, **kwargs):
        if self.unbound:
            template, *args = args
        else:
            template = self.template
        if isinstance(template, str):
            _check_format(template, template)
            _check_widths(template, (*args, *kwargs.values()))
        return template.format(*args, **kwargs)


def _check_format(template: str, whole: str, depth: int = 0) -> None:
    import _string

    if depth > 2:
        return
    try:
        parts = list(_string.formatter_parser(template))
    except ValueError:
        return  # str.format raises the same error
    for _, field, spec, _ in parts:
        if field:
            try:
                _, rest = _string.formatter_field_name_split(field)
                rest = list(rest)
            except ValueError:
                continue
            if any(is_attribute for is_attribute, _ in rest):
                raise UnsafeExpression(whole, f"format field '{{{field}}}' looks up an attribute",
                                   partial=True)
        if spec:
            _check_format(spec, whole, depth + 1)


_WIDTH_RE = re.compile(r"\d{8,}")
_PERCENT_RE = re.compile(r"%(?:\([^)]*\))?[-+ #0]*(?:\*|\d+)?(?:\.(?:\*|\d+))?")
_PADDING = frozenset({"center", "ljust", "rjust", "zfill"})
_BIG_MATH = frozenset({"factorial", "comb", "perm"})


def _check_widths(template: str, values, percent: bool = False) -> None:
    """'%100000000d', '{:>100000000}' or a width given as an argument ('%*d', '{:{}}') would
    build a string of that size."""
    import _string

    if percent:
        specs = _PERCENT_RE.findall(template)
        nested = any("*" in spec for spec in specs)
    else:
        try:
            specs = [spec or "" for _, _, spec, _ in _string.formatter_parser(template)]
        except ValueError:
            return  # str.format raises the same error
        nested = any("{" in spec for spec in specs)
    if any(_WIDTH_RE.search(spec) for spec in specs) or (nested and any(
            isinstance(v, int) and v > MAX_ITEMS for v in values)):
        raise LimitExceeded("a format width makes too long a string")


def _check_size(function, args, kwargs) -> None:
    """Calls whose result size the arguments decide: refuse the gigantic ones up front."""
    name = getattr(function, "__name__", "")
    owner = getattr(function, "__self__", None)
    if function is pow and len(args) == 2 and all(isinstance(a, int) for a in args):
        base, exponent = args
        if exponent > 0 and abs(base) > 1 and exponent * math.log2(abs(base)) > MAX_INT_BITS:
            raise LimitExceeded(f"{base} ** {exponent} is too large a number")
    elif name in _BIG_MATH and getattr(function, "__module__", None) == "math":
        if any(isinstance(a, int) and a > 100_000 for a in args):
            raise LimitExceeded(f"math.{name} of a number that large takes too long")
    elif isinstance(owner, str) and args:
        if name in _PADDING and isinstance(args[0], int) and args[0] > MAX_ITEMS:
            raise LimitExceeded(f"str.{name}({args[0]}) makes too long a string")
        if name == "expandtabs" and isinstance(args[0], int) \
                and args[0] * owner.count("\t") > MAX_ITEMS:
            raise LimitExceeded("str.expandtabs makes too long a string")
        if name == "replace" and len(args) >= 2 and isinstance(args[0], str) \
                and isinstance(args[1], str):
            count = (owner.count(args[0]) if args[0] else len(owner) + 1)
            if len(args) > 2 and isinstance(args[2], int) and args[2] >= 0:
                count = min(count, args[2])
            if len(owner) + count * (len(args[1]) - len(args[0])) > MAX_ITEMS:
                raise LimitExceeded("str.replace makes too long a string")


class Evaluator:
    """Guarded ``eval`` for one expansion: what may be called, the deadline."""

    def __init__(self, deadline: float | None = None):
        import xacro

        self.deadline = deadline
        self.forbidden = {id(type), id(vars)}
        self._keep: list = []  # keeps the allowed objects alive (their ids are the allow-list)
        allowed: list = [_SafeFormat]
        self._namespace_types = (xacro.NameSpace,)
        self._yaml_types = (xacro.YamlDictWrapper, xacro.YamlListWrapper)
        for value in xacro._global_symbols.values():
            if isinstance(value, xacro.NameSpace):
                allowed.extend(v for v in dict.values(value) if callable(v))
            elif callable(value):
                allowed.append(value)
        builtins = __builtins__ if isinstance(__builtins__, dict) else vars(__builtins__)
        self.safe_builtins = {name: builtins[name] for name in SAFE_BUILTIN_NAMES}
        allowed.extend(self.safe_builtins.values())
        allowed.extend(v for k, v in vars(math).items() if not k.startswith("_") and callable(v))
        allowed.extend([xacro.YamlDictWrapper, xacro.YamlListWrapper])
        self.allowed = {id(v) for v in allowed if id(v) not in self.forbidden}
        self._keep.extend(allowed)
        self.range_functions = {id(range)} | {
            id(v) for v in allowed if getattr(v, "__name__", "") == "wrapper"
            and getattr(v, "__closure__", None)
            and any(getattr(c, "cell_contents", None) is range for c in v.__closure__)}
        self.guards = {_G_ATTR: self._attr, _G_CALL: self._call, _G_BINOP: self._binop,
                       _G_ITER: self._iter}

    def allow(self, *functions) -> None:
        """Also allow calling these (functions made per evaluation, like $(eval)'s arg())."""
        self._keep.extend(functions)
        self.allowed.update(id(f) for f in functions)

    # -- guards --

    def _tick(self):
        if self.deadline is not None and time.monotonic() > self.deadline:
            raise LimitExceeded("xacro expansion took longer than the time limit")

    def _attr(self, obj, name):
        kind = type(obj)
        if isinstance(obj, self._namespace_types):
            if name in obj:
                value = getattr(obj, name)
                if id(value) in self.forbidden:
                    raise UnsafeExpression(name, f"'{name}' is not allowed in expressions",
                                           partial=True)
                return value
            if _real_attribute(obj, name):
                raise UnsafeExpression(name, f"'{name}' is not a property of this namespace",
                                       partial=True)
            return getattr(obj, name)  # raises NameError, as xacro does
        if isinstance(obj, self._yaml_types):
            if _real_attribute(obj, name) and name not in _methods_for(kind):
                raise UnsafeExpression(name, f"attribute '{name}' of YAML data is not "
                                                 "allowed", partial=True)
            value = getattr(obj, name)
            if id(value) in self.forbidden:
                raise UnsafeExpression(name, f"'{name}' is not allowed in expressions",
                                       partial=True)
            return value
        if kind in _METHODS:
            if name not in _METHODS[kind]:
                raise UnsafeExpression(name, f"attribute '{name}' of a {kind.__name__} is not "
                                             "allowed", partial=True)
            if name == "format" and kind is str:
                return _SafeFormat(obj)
            return getattr(obj, name)
        if isinstance(obj, type) and obj in _METHODS:
            if name not in _METHODS[obj] or name in ("real", "imag"):
                raise UnsafeExpression(name, f"'{obj.__name__}.{name}' is not allowed",
                                       partial=True)
            if name == "format" and obj is str:
                return _SafeFormat(unbound=True)
            return getattr(obj, name)
        raise UnsafeExpression(name, f"attribute '{name}' of a {kind.__name__} object is not "
                                     "allowed", partial=True)

    def _callable_ok(self, function) -> bool:
        if id(function) in self.allowed or isinstance(function, _SafeFormat):
            return True
        if function is str.maketrans or function is bytes.maketrans:
            return True
        if isinstance(function, types.BuiltinMethodType):
            owner = function.__self__
            kind = owner if isinstance(owner, type) else type(owner)
            methods = _methods_for(kind) if kind is not type else None
            if owner is None:
                return False
            if isinstance(owner, self._namespace_types):
                return False
            return methods is not None and function.__name__ in methods
        if isinstance(function, (types.MethodDescriptorType, types.ClassMethodDescriptorType,
                                 types.WrapperDescriptorType)):
            methods = _METHODS.get(function.__objclass__)
            return methods is not None and function.__name__ in methods
        return False

    def _call(self, function, /, *args, **kwargs):
        self._tick()
        if not self._callable_ok(function):
            name = getattr(function, "__name__", type(function).__name__)
            raise UnsafeExpression(f"{name}(...)", f"calling '{name}' is not allowed",
                                   partial=True)
        for value in (*args, *kwargs.values()):
            if callable(value) and not self._callable_ok(value):
                name = getattr(value, "__name__", type(value).__name__)
                raise UnsafeExpression(name, f"passing '{name}' to a function is not allowed",
                                       partial=True)
        _check_size(function, args, kwargs)
        if id(function) in self.range_functions:
            result = function(*args, **kwargs)
            if isinstance(result, range) and len(result) > MAX_ITEMS:
                raise LimitExceeded(f"range of {len(result)} items is too long")
            return result
        return function(*args, **kwargs)

    def _iter(self, iterable):
        """A comprehension's iterable, with the deadline checked as it runs."""
        for item in iterable:
            self._tick()
            yield item

    def _binop(self, name, left, right):
        if name == "Pow":
            if isinstance(left, int) and isinstance(right, int) and right > 0 \
                    and abs(left) > 1 and right * math.log2(abs(left)) > MAX_INT_BITS:
                raise LimitExceeded(f"{left} ** {right} is too large a number")
            return operator.pow(left, right)
        if name == "Mod":
            if isinstance(left, str):
                _check_widths(left, right if isinstance(right, tuple) else (right,), True)
            return operator.mod(left, right)
        if name == "LShift":
            if isinstance(left, int) and isinstance(right, int) and right > MAX_INT_BITS:
                raise LimitExceeded(f"{left} << {right} is too large a number")
            return operator.lshift(left, right)
        for sequence, count in ((left, right), (right, left)):
            if isinstance(sequence, (str, bytes, list, tuple)) and isinstance(count, int) \
                    and count > 0 and len(sequence) * count > MAX_ITEMS:
                raise LimitExceeded(f"a sequence of {len(sequence) * count} items is too long")
        return operator.mul(left, right)

    # -- entry points --

    def eval_expression(self, expression: str, symbols):
        """``xacro.safe_eval``: evaluate ``${expression}`` with the xacro symbol table."""
        text = expression.strip()
        try:
            return eval(compile_guarded(text), _Scope(symbols, self.guards))
        except UnsafeExpression as exc:
            if exc.partial:
                raise UnsafeExpression(text, exc.reason) from None
            raise

    def eval_substitution(self, expression: str, names):
        """``$(eval expression)``: ``names`` is xacro's mapping of args and functions."""
        scope = {"__builtins__": self.safe_builtins, **self.guards}
        try:
            return eval(compile_guarded(expression), scope, names)
        except UnsafeExpression as exc:
            if exc.partial:
                raise UnsafeExpression(expression, exc.reason) from None
            raise
        except NameError as exc:
            if getattr(exc, "name", None) in UNSAFE_BUILTIN_NAMES:
                raise UnsafeExpression(expression, f"'{exc.name}' is not available in "
                                                   "expressions") from None
            raise


def _real_attribute(obj, name: str) -> bool:
    try:
        object.__getattribute__(obj, name)
    except AttributeError:
        return False
    return True


class _Scope(dict):
    """Globals for a guarded ``${}`` evaluation: the guards, empty builtins, then xacro's
    symbol table (looked up through its own ``__getitem__``, as plain xacro does)."""

    def __init__(self, symbols, guards):
        super().__init__(guards)
        dict.__setitem__(self, "__builtins__", {})
        self.symbols = symbols

    def __getitem__(self, key):
        if dict.__contains__(self, key):
            return dict.__getitem__(self, key)
        return self.symbols[key]

    def __setitem__(self, key, value):  # never reached: no assignment survives validation
        raise UnsafeExpression(key, "assignment is not allowed")
