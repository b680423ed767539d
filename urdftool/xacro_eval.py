"""The xacro expression interpreter: ``${...}``, ``$(eval ...)`` and YAML ``!degrees``-style units.

Python's ``eval`` is never called on file content. ``Interpreter`` walks the parsed ``ast`` itself
over a closed set of values: numbers (complex too), booleans, strings, None, lists, tuples, dicts
and their keys/values/items views, sets, frozensets, ranges, slices, YAML data (xacro's dotted
``YamlDictWrapper``/``YamlListWrapper``), and urdftool's own ``Function``/``Method``/``Namespace``/
``Lazy``/``Closure`` (a ``lambda``) objects. Functions are a fixed table urdftool implements or
wraps with checked arguments: xacro's documented symbols (math, ``python.*`` less ``vars`` and
three-argument ``type``, ``xacro.*``) and a fixed list of str/list/dict/set methods. An
attribute is looked up in that table, never on a Python object, so no other object (types,
modules, frames, functions' attributes, descriptors) ever becomes a value; whatever else an
expression asks for raises ``UnsafeExpression`` (``xacro.unsafe-expression``).

Sizes are checked before every operation that can grow (repetition, concatenation, powers,
shifts, ranges, joins, replace, padding, format widths and precisions, str/repr of nested data,
int/str conversions, sums and products); nested data is measured (shared parts counted each
time, so YAML alias bombs are too) before C code walks it (compare, hash, sort, repr); every
loop checks the deadline; no regex is built from expression data (``xacro.tokenize`` splits by
hand). Exceeding a limit raises ``LimitExceeded`` (``xacro.limit-exceeded``). Within these
limits a valid expression gives what plain xacro gives (``tests/test_xacro_eval_fuzz.py``
compares them), except that ``map``/``filter``/``zip``/lambdas print without an address, a
recursion past Python's limit is ``LimitExceeded``, and ``str.encode`` (bytes) is refused.
"""

from __future__ import annotations

import ast
import math
import operator
import re
import string
import time

MAX_ITEMS = 1_000_000  # characters or items of one value an expression builds
MAX_TREE = 4_000_000  # expanded size (shared parts counted each time) of data C code walks
MAX_RESULT = 16_000_000  # expanded size of a value handed back to xacro (which str()s it)
MAX_BUDGET = 8_000_000  # characters and items built by all expressions of one expansion
MAX_TEXT = 1 << 18  # characters of one string handed back to xacro (an attribute, a property)
MAX_INT_BITS = 1 << 16  # ~19 700 decimal digits
MAX_STR_BITS = 14_000  # int -> decimal str (Python's own default limit is 4300 digits)
MAX_WIDTH = 10_000  # format widths and precisions
MAX_DEPTH = 100  # nesting of data
MAX_NODES = 20_000  # nodes of one expression
MAX_YAML_CHARS = 2 << 20  # a YAML file read by xacro.load_yaml


class UnsafeExpression(Exception):
    """An expression urdftool refuses to evaluate."""

    def __init__(self, expression: str, reason: str, partial: bool = False):
        super().__init__(f"unsafe expression '{expression}': {reason}")
        self.expression, self.reason = expression, reason
        self.partial = partial  # raised deep inside: ``expression`` is only the offending part


class LimitExceeded(Exception):
    """Expansion went past a time, size or recursion limit."""


class Deadline(LimitExceeded):
    """Expansion ran out of time: nothing after it can be evaluated."""


REFUSED_TEXT = "urdftool-refused-expression"


class Refused(str):
    """The value of an expression urdftool refused (unsafe, or past a size limit): the
    placeholder text, so that expansion goes on; an expression that reads it is refused too,
    silently (``DependsOnRefused``): its cause is reported once, where it was written."""

    __slots__ = ()

    def __new__(cls):
        return super().__new__(cls, REFUSED_TEXT)


class DependsOnRefused(Exception):
    """An expression read the value of a refused one."""


def _unsafe(reason: str) -> UnsafeExpression:
    return UnsafeExpression("", reason, partial=True)


# -- urdftool's own values ------------------------------------------------------------------


class Function:
    """A function of the fixed table: ``impl(interpreter, args, kwargs)``. ``pytype`` is set for
    the type-like functions (``str``, ``float``...) that ``isinstance`` and ``str.upper`` use."""

    __slots__ = ("impl", "name", "pytype")

    def __init__(self, name, impl, pytype=None):
        self.name, self.impl, self.pytype = name, impl, pytype

    def __repr__(self):
        if self.pytype is not None and self.name in (self.pytype.__name__,
                                                     self.pytype.__qualname__):
            return f"<class '{self.pytype.__name__}'>"
        if self.pytype is not None and self.name.endswith(self.pytype.__qualname__):
            return f"<class '{self.name}'>"
        return f"<built-in function {self.name}>"


class Method:
    """A method of the fixed table bound to a value (``'a,b'.split``)."""

    __slots__ = ("name", "receiver")

    def __init__(self, receiver, name):
        self.receiver, self.name = receiver, name

    def __repr__(self):
        return f"<built-in method {self.name}>"


class Namespace:
    """``python``, ``math``, ``xacro``: urdftool's tables (entries are Functions or constants)."""

    __slots__ = ("entries", "name")

    def __init__(self, name, entries):
        self.name, self.entries = name, entries

    def __repr__(self):
        return f"<namespace {self.name}>"


class UserNamespace:
    """A namespace of the file (``<xacro:include ns="...">``): xacro's table, read by key."""

    __slots__ = ("table",)

    def __init__(self, table):
        self.table = table

    def __repr__(self):
        return "<namespace>"


class Lazy:
    """An iterator made by ``map``/``filter``/``zip``/``enumerate``/``reversed`` or a generator
    expression; consumed only by the interpreter."""

    __slots__ = ("iterator", "kind")

    def __init__(self, iterator, kind):
        self.iterator, self.kind = iterator, kind

    def __repr__(self):
        return f"<{self.kind} object>"


class Closure:
    """A ``lambda`` of the expression: its parameters (defaults evaluated when it was made),
    its body, the scope and the symbol table it was made in (as Python's: its globals are the
    table xacro evaluated it with); called by the interpreter, never by Python."""

    __slots__ = ("defaults", "kw_defaults", "lookup", "node", "scope")

    def __init__(self, node, scope, lookup, defaults, kw_defaults):
        self.node, self.scope, self.lookup = node, scope, lookup
        self.defaults, self.kw_defaults = defaults, kw_defaults

    def __repr__(self):
        return "<function <lambda>>"


_REQUIRED = object()  # a keyword-only parameter of a lambda without a default


class _Refused:
    __slots__ = ("reason",)

    def __init__(self, reason):
        self.reason = reason


_SCALARS = (int, float, bool, str, type(None), complex)
_NUMBERS = (int, float, bool, complex)
_SEQUENCES = (str, list, tuple)
_OWN = (Function, Method, Namespace, UserNamespace, Lazy, Closure)
# a dict's keys()/values()/items(): Python's own views (set operators on keys and items), whose
# attributes are never looked up (``getattr`` reads the method table)
_VIEWS = (type({}.keys()), type({}.values()), type({}.items()))
_ITERABLE = (list, tuple, str, range, set, frozenset, dict, *_VIEWS)


def _typename(value) -> str:
    kind = type(value)
    if kind in (Function, Method):
        return "builtin_function_or_method"
    if kind in (Namespace, UserNamespace):
        return "namespace"
    if kind is Lazy:
        return value.kind
    if kind is Closure:
        return "function"
    return kind.__name__


# -- static validation ----------------------------------------------------------------------

_ALLOWED_NODES = (
    ast.Expression, ast.Constant, ast.Name, ast.Load, ast.Store, ast.BinOp, ast.UnaryOp,
    ast.BoolOp, ast.Compare, ast.IfExp, ast.Subscript, ast.Slice, ast.Tuple, ast.List, ast.Dict,
    ast.Set, ast.Call, ast.keyword, ast.Attribute, ast.Starred, ast.JoinedStr,
    ast.FormattedValue, ast.ListComp, ast.SetComp, ast.DictComp, ast.GeneratorExp,
    ast.comprehension, ast.operator, ast.unaryop, ast.boolop, ast.cmpop, ast.expr_context,
    ast.Lambda, ast.arguments, ast.arg,
)
_NODE_WORDS = {ast.NamedExpr: "an assignment expression (:=)",
               ast.Await: "await", ast.Yield: "yield", ast.YieldFrom: "yield from"}
_PARSED: dict[str, ast.Expression] = {}
_YAML_DATA: dict[str, object] = {}  # YAML text (without expressions) -> its data, checked
# a unit tag on a number literal (``!degrees 180.0``): its value depends on the text alone
_LITERAL_UNIT = (r"!(?:radians|degrees|meters|millimeters|foot|inches)[ \t]+"
                 r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?=[\s,\]}]|$)")


def check_expression(expression: str) -> ast.Expression:
    """Parse and validate ``expression`` (cached). Raises SyntaxError as ``eval`` would,
    UnsafeExpression for what the interpreter does not do, LimitExceeded when too big."""
    text = expression.strip()
    tree = _PARSED.get(text)
    if tree is not None:
        return tree
    try:
        tree = ast.parse(text, "<expression>", "eval")
    except (RecursionError, MemoryError):
        raise LimitExceeded("expression nested too deeply") from None
    except ValueError as exc:  # e.g. an integer literal with too many digits
        raise LimitExceeded(f"expression: {exc}") from None
    for count, node in enumerate(ast.walk(tree)):
        if count >= MAX_NODES:
            raise LimitExceeded(f"expression of more than {MAX_NODES} parts")
        if not isinstance(node, _ALLOWED_NODES):
            word = _NODE_WORDS.get(type(node), f"'{type(node).__name__}'")
            raise UnsafeExpression(text, f"{word} is not allowed in a xacro expression")
        if isinstance(node, ast.Name) and node.id.startswith("__"):
            raise UnsafeExpression(text, f"name '{node.id}': names starting with __ are not "
                                         "allowed")
        if isinstance(node, ast.Attribute):
            if node.attr.startswith("__"):
                raise UnsafeExpression(text, f"attribute '{node.attr}': dunder attributes are "
                                             "not allowed")
            if not isinstance(node.ctx, ast.Load):
                raise UnsafeExpression(text, "assigning to an attribute is not allowed")
        if isinstance(node, ast.Subscript) and not isinstance(node.ctx, ast.Load):
            raise UnsafeExpression(text, "assigning to an item is not allowed")
        if isinstance(node, ast.comprehension) and node.is_async:
            raise UnsafeExpression(text, "async comprehensions are not allowed")
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.MatMult):
            raise UnsafeExpression(text, "the @ operator is not supported")
        if isinstance(node, ast.Constant) and not isinstance(node.value, _SCALARS):
            raise UnsafeExpression(text, f"{type(node.value).__name__} literals are not "
                                         "supported")
    if len(_PARSED) > 20000:
        _PARSED.clear()
    _PARSED[text] = tree
    return tree


def scan(value: str) -> list[UnsafeExpression]:
    """Statically validate every literal ``${...}`` and ``$(eval ...)`` of an attribute value
    or text (split as xacro's lexer splits it). Expressions built from other expressions are
    checked when they are evaluated."""
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
            except (SyntaxError, LimitExceeded):
                pass  # reported when (if) xacro evaluates it
    except Exception:  # noqa: BLE001, S110 - xacro's lexer rejects it; xacro will say so
        pass
    return found


# -- measuring data -------------------------------------------------------------------------


def _measure(value, budget: int, tick=None, work=False) -> int:
    """Characters of ``repr(value)`` (strings and numbers estimated), or with ``work`` the items
    a compare or hash visits, every shared part counted each time it is reached;
    LimitExceeded beyond ``budget`` or MAX_DEPTH levels."""
    total = 0
    stack = [(value, 0)]
    on_path: set = set()
    while stack:
        item, depth = stack.pop()
        if depth < 0:  # leaving a container
            on_path.discard(id(item))
            continue
        if tick is not None:
            tick()
        if isinstance(item, dict):
            children = [*item.keys(), *item.values()]
            total += 2 + 4 * len(item)
        elif isinstance(item, (list, tuple, set, frozenset, *_VIEWS)):
            # a list as stored (YAML's wrapper), a set in a list: C code walks it, and
            # the chunks below slice it
            children = list.copy(item) if isinstance(item, list) else \
                item if isinstance(item, tuple) else list(item)
            total += 2 + 2 * len(item)
        else:
            total += _scalar_size(item)
            children = ()
        if children:
            if id(item) in on_path:
                total += 5  # '[...]'
                continue
            if depth >= MAX_DEPTH:
                raise LimitExceeded(f"data nested more than {MAX_DEPTH} levels deep")
            on_path.add(id(item))
            stack.append((item, -1))
            kinds = set(map(type, children))
            if kinds <= _FLAT and work:
                total += len(children)
                if str in kinds:  # by chunks: a terabyte of references stops early
                    for start in range(0, len(children), 1 << 15):
                        chunk = children[start:start + (1 << 15)]
                        total += sum(map(len, chunk)) if kinds == {str} else \
                            sum([len(c) for c in chunk if type(c) is str])
                        if total > budget:
                            break
            elif kinds <= _FLAT:  # no containers among them: sized without a Python loop
                total += (24 if float in kinds else 4) * len(children)
                if str in kinds:
                    total += sum(len(c) for c in children if type(c) is str)
                if int in kinds:
                    total += max(c.bit_length() for c in children if type(c) is int) * 0.302 \
                        * len(children)
            else:
                for child in children:
                    kind = type(child)
                    if kind is str:
                        total += len(child) + 2
                    elif kind in _FLAT:
                        total += _scalar_size(child)
                    else:
                        stack.append((child, depth + 1))
        if total > budget:
            raise LimitExceeded(f"data of more than {budget} characters (or items)")
    return int(total)


_FLAT = frozenset({str, int, float, bool, type(None), complex})


def _scalar_size(item) -> float:
    kind = type(item)
    if kind is str:
        return len(item) + 2
    if kind is int:
        return item.bit_length() * 0.302 + 2
    return 24


# -- the interpreter --------------------------------------------------------------------------


class _Formatter(string.Formatter):
    """``str.format`` over interpreter values: fields by index, key and item, never by
    attribute; widths and precisions checked; the size of the result bounded."""

    def __init__(self, interpreter):
        self.interpreter, self.size = interpreter, 0

    def get_field(self, field_name, args, kwargs):
        import _string

        first, rest = _string.formatter_field_name_split(field_name)
        value = self.get_value(first, args, kwargs)
        for is_attribute, key in rest:
            if is_attribute:
                raise _unsafe(f"format field '{{{field_name}}}' looks up an attribute")
            value = self.interpreter.getitem(value, key)
        return value, first

    def convert_field(self, value, conversion):
        if conversion is None:
            return value
        if conversion == "s":
            return self.interpreter.to_str(value)
        if conversion in "ra":
            text = self.interpreter.to_str(value, use_repr=True)
            return text if conversion == "r" else _ascii(text)
        raise ValueError(f"Unknown conversion specifier {conversion}")

    def format_field(self, value, format_spec):
        self.interpreter.tick()
        piece = self.interpreter.format_value(value, format_spec)
        self.size += len(piece)
        if self.size > MAX_ITEMS:
            raise LimitExceeded(f"a formatted string of more than {MAX_ITEMS} characters")
        return piece

    def check_unused_args(self, used_args, args, kwargs):
        pass


class Interpreter:
    """Evaluates the expressions of one expansion: the deadline, the size budget, the file
    reader for ``xacro.load_yaml`` (``read_text(path) -> str``, which applies the policy)."""

    def __init__(self, deadline: float | None = None, read_text=None):
        import xacro

        self.deadline = deadline
        self.read_text = read_text or _read_text
        self.spent = 0
        self._ticks = 0
        self._xacro = xacro
        self._yaml_dict, self._yaml_list = xacro.YamlDictWrapper, xacro.YamlListWrapper
        self._values = frozenset({*_SCALARS, list, tuple, dict, set, frozenset, range, slice,
                                  *_VIEWS, *_OWN, self._yaml_dict, self._yaml_list})
        tables = _tables()
        self._by_id = _identity_map(xacro, tables)
        self._substitution_names = tables["substitution"]
        self._loader = None
        # id of a YAML dict handed out -> (it, the file and keys it comes from): a missing key
        # is said with the file's name and keys
        self._yaml_origin: dict[int, tuple[object, str]] = {}
        self._dispatch = {
            ast.Constant: self._constant, ast.Name: self._name, ast.BinOp: self._binop_node,
            ast.UnaryOp: self._unaryop, ast.BoolOp: self._boolop, ast.Compare: self._compare,
            ast.IfExp: self._ifexp, ast.Subscript: self._subscript, ast.Tuple: self._tuple,
            ast.List: self._list, ast.Set: self._set, ast.Dict: self._dict, ast.Call: self._call,
            ast.Attribute: self._attribute, ast.JoinedStr: self._joinedstr,
            ast.FormattedValue: self._formatted, ast.ListComp: self._listcomp,
            ast.SetComp: self._setcomp, ast.DictComp: self._dictcomp,
            ast.GeneratorExp: self._genexp, ast.Slice: self._slice, ast.Lambda: self._lambda,
        }

    # -- entry points --

    def evaluate(self, expression: str, symbols):
        """``${expression}`` with xacro's symbol table (a ``Table``, or any mapping)."""
        return self._run(expression, symbols.__getitem__)

    def evaluate_substitution(self, expression: str, args: dict, functions: dict):
        """``$(eval expression)``: names are ``functions`` (Python callables urdftool wrote,
        called with checked scalar arguments), then urdftool's table (math, builtins), then
        the xacro args (converted as xacro converts them)."""
        from xacro import substitution_args

        def lookup(name):
            if name in functions:
                return Function(name, _native(name, functions[name]))
            if name in self._substitution_names:
                return self._substitution_names[name]
            if name not in args and name in _PYTHON_BUILTINS:
                raise _unsafe(f"Python's '{name}' is not available in $(eval ...)")
            return substitution_args.convert_value(args[name], "auto")

        return self._run(expression, lookup)

    def _run(self, expression, lookup):
        text = expression.strip()
        try:
            tree = check_expression(text)
            saved = self._lookup
            self._lookup = lookup
            try:
                result = self.eval(tree.body, {})
            finally:
                self._lookup = saved
            if type(result) is str:
                if len(result) > MAX_TEXT:  # it goes into the document: refused at its source
                    raise LimitExceeded(f"a string of {len(result)} characters for the "
                                        f"document (limit {MAX_TEXT})")
                self.charge(len(result))  # copied into the document (a property reference)
            elif type(result) not in _SCALARS and not isinstance(result, _OWN):
                self.charge(_measure(result, MAX_RESULT, self.tick))
            return result
        except UnsafeExpression as exc:
            if exc.partial:
                raise UnsafeExpression(text, exc.reason) from None
            raise
        except RecursionError:
            raise LimitExceeded("expression or data nested too deeply") from None
        except MemoryError:
            raise LimitExceeded("out of memory evaluating an expression") from None

    def _lookup(self, name):
        raise KeyError(name)

    # -- bookkeeping --

    def tick(self):
        self._ticks += 1
        if self._ticks & 255 == 0 and self.deadline is not None \
                and time.monotonic() > self.deadline:
            raise Deadline("xacro expansion took longer than the time limit")

    def clock(self):
        """The deadline, read now: before and after every call that can take more than
        constant time (a function or method, C code walking data, a large value built)."""
        if self.deadline is not None and time.monotonic() > self.deadline:
            raise Deadline("xacro expansion took longer than the time limit")

    def charge(self, size: int):
        """Account for ``size`` characters (bytes) of work or data: built, or handed back
        to xacro (a property reference copies its value into the document)."""
        self.spent += size
        if self.spent > MAX_BUDGET:
            raise LimitExceeded(f"expressions built or referenced more than {MAX_BUDGET} "
                                "characters in all")
        if size > 4096:
            self.clock()

    def made(self, value):
        """Account for a value an operation built; refuse it when too large."""
        kind = type(value)
        if kind is int:
            bits = value.bit_length()
            if bits > MAX_INT_BITS:
                raise LimitExceeded(f"an integer of more than {MAX_INT_BITS} bits")
            if bits > 64:
                self.charge(bits >> 3)  # its bytes
        elif kind in (str, list, tuple, dict, set, frozenset) or kind in _VIEWS:
            size = len(value)
            if size > MAX_ITEMS:
                raise LimitExceeded(f"a {kind.__name__} of {size} items (limit {MAX_ITEMS})")
            self.charge(size)
        return value

    def grows(self, size, what="a value"):
        """Refuse, before building it, a value of ``size`` items or characters."""
        if size > MAX_ITEMS:
            raise LimitExceeded(f"{what} of {size} items or characters (limit {MAX_ITEMS})")

    def bounded(self, *values):
        """Measure nested data before C code walks it (compare, hash, sort, membership):
        items and the characters of the strings among them (a million references to one
        1 MB string is a terabyte to compare)."""
        self.clock()
        for value in values:
            if type(value) not in _SCALARS and not isinstance(value, (range, slice, *_OWN)):
                _measure(value, MAX_TREE, self.tick, work=True)

    def admit(self, value):
        """A value from outside the interpreter (xacro's tables): closed types only."""
        if type(value) in self._values:
            return value
        if type(value) is Refused:
            raise DependsOnRefused()
        mine = self._by_id.get(id(value))
        if mine is not None:
            if type(mine) is _Refused:
                raise _unsafe(mine.reason)
            return mine
        if type(value) is self._xacro.NameSpace:
            return UserNamespace(value)
        raise _unsafe(f"a value of type '{type(value).__name__}' cannot be used in an "
                      "expression")

    # -- iteration --

    def iterate(self, value):
        """An iterator over ``value`` that ticks the clock at every item; TypeError now (as
        Python's ``iter``) when ``value`` is not iterable, not at the first item."""
        kind = type(value)
        if kind is Lazy:
            iterator = value.iterator
        elif kind in _ITERABLE or kind in (self._yaml_dict, self._yaml_list):
            iterator = iter(value)
        else:
            raise TypeError(f"'{_typename(value)}' object is not iterable")
        return self._ticking(iterator)

    def _ticking(self, iterator):
        for item in iterator:
            self.tick()
            yield item

    def items(self, value) -> list:
        if type(value) in _ITERABLE and len(value) <= MAX_ITEMS:
            self.tick()
            return self.made(list(value))  # C speed: the size is known first
        result = []
        for item in self.iterate(value):
            result.append(item)
            if len(result) > MAX_ITEMS:
                raise LimitExceeded(f"more than {MAX_ITEMS} items")
        return self.made(result)

    # -- evaluation --

    def eval(self, node, scope):
        self.tick()
        handler = self._dispatch.get(type(node))
        if handler is None:
            raise _unsafe(f"'{type(node).__name__}' is not allowed in a xacro expression")
        return handler(node, scope)

    def _constant(self, node, scope):
        return node.value

    def _name(self, node, scope):
        name = node.id
        if name in scope:
            return scope[name]
        try:
            value = self._lookup(name)
        except KeyError:
            raise NameError(f"name '{name}' is not defined") from None
        return self.admit(value)

    def _ifexp(self, node, scope):
        return self.eval(node.body if self.eval(node.test, scope) else node.orelse, scope)

    def _boolop(self, node, scope):
        value = None
        for operand in node.values:
            value = self.eval(operand, scope)
            if isinstance(node.op, ast.And) and not value:
                return value
            if isinstance(node.op, ast.Or) and value:
                return value
        return value

    def _unaryop(self, node, scope):
        value = self.eval(node.operand, scope)
        if isinstance(node.op, ast.Not):
            return not value
        if type(value) not in _NUMBERS:
            symbol = {ast.USub: "-", ast.UAdd: "+", ast.Invert: "~"}[type(node.op)]
            raise TypeError(f"bad operand type for unary {symbol}: '{_typename(value)}'")
        return {ast.USub: operator.neg, ast.UAdd: operator.pos,
                ast.Invert: operator.invert}[type(node.op)](value)

    def _binop_node(self, node, scope):
        return self.binop(type(node.op), self.eval(node.left, scope), self.eval(node.right, scope))

    def binop(self, op, left, right):
        if isinstance(left, _OWN) or isinstance(right, _OWN):
            raise TypeError(f"unsupported operand type(s): '{_typename(left)}' and "
                            f"'{_typename(right)}'")
        if op is ast.Mod and type(left) is str:
            return self.percent(left, right)
        if op is ast.Add and type(left) in _SEQUENCES and type(right) in _SEQUENCES:
            self.grows(len(left) + len(right))
        elif op is ast.Mult:
            for sequence, count in ((left, right), (right, left)):
                if isinstance(sequence, _SEQUENCES) and type(count) in (int, bool):
                    self.grows(len(sequence) * max(count, 0), "a repeated sequence")
            if type(left) is int and type(right) is int \
                    and left.bit_length() + right.bit_length() > MAX_INT_BITS:
                raise LimitExceeded(f"a product of more than {MAX_INT_BITS} bits")
        elif op is ast.Pow and type(left) in (int, bool) and type(right) in (int, bool):
            if right > 0 and abs(left) > 1 and right * math.log2(abs(left)) > MAX_INT_BITS:
                raise LimitExceeded(f"{left} ** {right} is too large a number")
        elif op is ast.LShift and type(left) in (int, bool) and type(right) in (int, bool):
            if left and right > 0 and left.bit_length() + right > MAX_INT_BITS:
                raise LimitExceeded(f"{left} << {right} is too large a number")
        elif op in (ast.BitOr, ast.BitAnd, ast.BitXor, ast.Sub) \
                and isinstance(left, (set, frozenset, dict, *_VIEWS)):
            self.bounded(left, right)
        return self.made(_BINOPS[op](left, right))

    def _compare(self, node, scope):
        left = self.eval(node.left, scope)
        for op, comparator in zip(node.ops, node.comparators):
            right = self.eval(comparator, scope)
            if not self.compare(type(op), left, right):
                return False
            left = right
        return True

    def compare(self, op, left, right):
        if op in (ast.In, ast.NotIn):
            return self.contains(right, left) == (op is ast.In)
        if op is ast.Is:
            return left is right
        if op is ast.IsNot:
            return left is not right
        self.bounded(left, right)
        return _COMPARE[op](left, right)

    def contains(self, container, item) -> bool:
        kind = type(container)
        if kind is Namespace:
            return item in container.entries
        if kind is UserNamespace:
            return item in container.table
        if kind is Lazy:
            self.bounded(item)
            for value in self.iterate(container):
                self.bounded(value)
                if value is item or value == item:
                    return True
            return False
        if kind is str:
            if type(item) is not str:
                raise TypeError(f"'in <string>' requires string as left operand, not "
                                f"{_typename(item)}")
            return item in container
        if isinstance(container, (list, tuple, dict, set, frozenset, range, *_VIEWS)):
            self.bounded(item, container)
            return item in container
        raise TypeError(f"argument of type '{_typename(container)}' is not iterable")

    def _subscript(self, node, scope):
        return self.getitem(self.eval(node.value, scope), self.eval(node.slice, scope))

    def _slice(self, node, scope):
        parts = [None if part is None else self.eval(part, scope)
                 for part in (node.lower, node.upper, node.step)]
        return slice(*parts)

    def getitem(self, container, key):
        kind = type(container)
        if kind is Namespace:
            if type(key) is not str or key not in container.entries:
                raise KeyError(key)
            value = container.entries[key]
            if type(value) is _Refused:
                raise _unsafe(value.reason)
            return value
        if kind is UserNamespace:
            if type(key) is not str:
                raise KeyError(key)
            return self.admit(container.table[key])
        if kind is self._yaml_dict:
            return self._yaml_key(container, key)
        if kind in (str, list, tuple, range, self._yaml_list) \
                or isinstance(container, dict):
            self.bounded(key)
            result = container[key]
            return self.made(result) if type(key) is slice else result
        raise TypeError(f"'{_typename(container)}' object is not subscriptable")

    def _elements(self, nodes, scope) -> list:
        result = []
        for element in nodes:
            if isinstance(element, ast.Starred):
                result.extend(self.items(self.eval(element.value, scope)))
                self.grows(len(result))
            else:
                result.append(self.eval(element, scope))
        return result

    def _tuple(self, node, scope):
        return self.made(tuple(self._elements(node.elts, scope)))

    def _list(self, node, scope):
        return self.made(self._elements(node.elts, scope))

    def _set(self, node, scope):
        elements = self._elements(node.elts, scope)
        self.bounded(elements)
        return self.made(set(elements))

    def _dict(self, node, scope):
        result = {}
        for key, value in zip(node.keys, node.values):
            if key is None:
                mapping = self.eval(value, scope)
                if not isinstance(mapping, dict):
                    raise TypeError(f"'{_typename(mapping)}' object is not a mapping")
                self.bounded(mapping)
                result.update(mapping)
            else:
                key = self.eval(key, scope)
                self.bounded(key)
                result[key] = self.eval(value, scope)
        return self.made(result)

    def _attribute(self, node, scope):
        return self.getattr(self.eval(node.value, scope), node.attr)

    def getattr(self, obj, name):
        kind = type(obj)
        if kind is Namespace:
            if name not in obj.entries:
                raise NameError(f"name '{name}' is not defined")
            return self.getitem(obj, name)
        if kind is UserNamespace:
            try:
                return self.admit(obj.table[name])
            except KeyError:
                raise NameError(f"name '{name}' is not defined") from None
        if kind is self._yaml_dict and name not in _METHODS[dict]:
            return self._yaml_key(obj, name)  # xacro's YamlDictWrapper: the key, wrapped
        if kind is Function and obj.pytype is not None:
            return _unbound(obj, name)
        pytype = dict if kind is self._yaml_dict else list if kind is self._yaml_list else kind
        properties = _PROPERTIES.get(pytype, ())
        if name in properties:
            return getattr(obj, name)
        if name in _METHODS.get(pytype, ()):
            return Method(obj, name)
        if hasattr(pytype, name) or isinstance(obj, _OWN):
            raise _unsafe(f"attribute '{name}' of a {_typename(obj)} is not available in "
                          "expressions")
        raise AttributeError(f"'{_typename(obj)}' object has no attribute '{name}'")

    def _call(self, node, scope):
        function = self.eval(node.func, scope)
        args = self._elements(node.args, scope)
        kwargs = {}
        for keyword in node.keywords:
            value = self.eval(keyword.value, scope)
            if keyword.arg is not None:
                kwargs[keyword.arg] = value
                continue
            if not isinstance(value, dict) or not all(type(k) is str for k in value):
                raise TypeError("argument after ** must be a mapping with string keys")
            kwargs.update(value)
        return self.call(function, args, kwargs)

    def call(self, function, args, kwargs=None):
        self.tick()
        self.clock()
        kwargs = kwargs or {}
        if type(function) is Function:
            return function.impl(self, list(args), kwargs)
        if type(function) is Method:
            return _call_method(self, function.receiver, function.name, list(args), kwargs)
        if type(function) is Closure:
            scope = self._parameters(function, list(args), kwargs)
            saved, self._lookup = self._lookup, function.lookup
            try:
                return self.eval(function.node.body, scope)
            finally:
                self._lookup = saved
        raise TypeError(f"'{_typename(function)}' object is not callable")

    def _lambda(self, node, scope):
        spec = node.args
        defaults = [self.eval(default, scope) for default in spec.defaults]
        kw_defaults = [_REQUIRED if default is None else self.eval(default, scope)
                       for default in spec.kw_defaults]
        return Closure(node, scope, self._lookup, defaults, kw_defaults)

    def _parameters(self, closure, args, kwargs) -> dict:
        """The scope of a lambda's call: its parameters bound as Python binds them."""
        spec = closure.node.args
        positional = [a.arg for a in (*spec.posonlyargs, *spec.args)]
        scope = dict(closure.scope)
        bound = set()
        for name, value in zip(positional, args):
            scope[name] = value
            bound.add(name)
        extra = args[len(positional):]
        if extra and spec.vararg is None:
            raise TypeError(f"<lambda>() takes {len(positional)} positional arguments but "
                            f"{len(args)} were given")
        if spec.vararg is not None:
            scope[spec.vararg.arg] = self.made(tuple(extra))
        keywords = {a.arg: d for a, d in zip(spec.kwonlyargs, closure.kw_defaults)}
        rest = {}
        for name, value in kwargs.items():
            if name in bound:
                raise TypeError(f"<lambda>() got multiple values for argument '{name}'")
            if name in positional[len(spec.posonlyargs):] or name in keywords:
                scope[name] = value
                bound.add(name)
            elif spec.kwarg is not None:
                rest[name] = value
            else:
                raise TypeError(f"<lambda>() got an unexpected keyword argument '{name}'")
        first_default = len(positional) - len(closure.defaults)
        for index, name in enumerate(positional):
            if name not in bound:
                if index < first_default:
                    raise TypeError(f"<lambda>() missing required positional argument: "
                                    f"'{name}'")
                scope[name] = closure.defaults[index - first_default]
        for name, default in keywords.items():
            if name not in bound:
                if default is _REQUIRED:
                    raise TypeError(f"<lambda>() missing required keyword-only argument: "
                                    f"'{name}'")
                scope[name] = default
        if spec.kwarg is not None:
            scope[spec.kwarg.arg] = self.made(rest)
        return scope

    # -- comprehensions --

    def _bind(self, target, value, scope):
        if isinstance(target, ast.Name):
            scope[target.id] = value
            return
        if not isinstance(target, (ast.Tuple, ast.List)):
            raise _unsafe("a comprehension may only assign to names")
        values = self.items(value)
        starred = [i for i, t in enumerate(target.elts) if isinstance(t, ast.Starred)]
        if not starred:
            if len(values) != len(target.elts):
                raise ValueError(f"expected {len(target.elts)} values to unpack, got "
                                 f"{len(values)}")
            for element, item in zip(target.elts, values):
                self._bind(element, item, scope)
            return
        (at,) = starred
        after = len(target.elts) - at - 1
        if len(values) < at + after:
            raise ValueError(f"not enough values to unpack (expected at least {at + after}, "
                             f"got {len(values)})")
        for element, item in zip(target.elts[:at], values[:at]):
            self._bind(element, item, scope)
        self._bind(target.elts[at].value, values[at:len(values) - after], scope)
        for element, item in zip(target.elts[at + 1:], values[len(values) - after:]):
            self._bind(element, item, scope)

    def _generate(self, generators, scope, first=None):
        """The scope of a comprehension, once per item its ``for``/``if`` clauses produce.
        As Python's, one scope for the whole comprehension (its own: the enclosing one is
        not changed), the first iterable evaluated outside it."""
        iterable = first if first is not None else self.eval(generators[0].iter, scope)
        return self._clauses(generators, dict(scope), iterable)

    def _clauses(self, generators, inner, iterable):
        head, rest = generators[0], generators[1:]
        for item in self.iterate(iterable):
            self._bind(head.target, item, inner)
            if all(self.eval(condition, inner) for condition in head.ifs):
                if rest:
                    yield from self._clauses(rest, inner, self.eval(rest[0].iter, inner))
                else:
                    yield inner

    def _listcomp(self, node, scope):
        result = []
        for inner in self._generate(node.generators, scope):
            result.append(self.eval(node.elt, inner))
            self.grows(len(result), "a list")
        return self.made(result)

    def _setcomp(self, node, scope):
        result = set()
        for inner in self._generate(node.generators, scope):
            value = self.eval(node.elt, inner)
            self.bounded(value)
            result.add(value)
            self.grows(len(result), "a set")
        return self.made(result)

    def _dictcomp(self, node, scope):
        result = {}
        for inner in self._generate(node.generators, scope):
            key = self.eval(node.key, inner)
            self.bounded(key)
            result[key] = self.eval(node.value, inner)
            self.grows(len(result), "a dict")
        return self.made(result)

    def _genexp(self, node, scope):
        first = self.eval(node.generators[0].iter, scope)  # as Python: evaluated at once
        if not isinstance(first, (Lazy, *_ITERABLE)):
            raise TypeError(f"'{_typename(first)}' object is not iterable")
        generated = self._generate(node.generators, scope, first)
        return Lazy((self.eval(node.elt, inner) for inner in generated), "generator")

    # -- strings --

    def _joinedstr(self, node, scope):
        pieces, size = [], 0
        for value in node.values:
            piece = self.eval(value, scope)
            size += len(piece)
            self.grows(size, "an f-string")
            pieces.append(piece)
        return self.made("".join(pieces))

    def _formatted(self, node, scope):
        value = self.eval(node.value, scope)
        if node.conversion == ord("s"):
            value = self.to_str(value)
        elif node.conversion in (ord("r"), ord("a")):
            value = self.to_str(value, use_repr=True)
            if node.conversion == ord("a"):
                value = _ascii(value)
        spec = "" if node.format_spec is None else self.eval(node.format_spec, scope)
        return self.format_value(value, spec)

    def to_str(self, value, use_repr=False) -> str:
        kind = type(value)
        if kind is str:
            return self.made(repr(value)) if use_repr else value
        if kind is int and value.bit_length() > MAX_STR_BITS:
            raise LimitExceeded("an integer too long to convert to a string")
        if kind in _SCALARS or kind in _OWN or kind in (range, slice):
            return repr(value) if use_repr else str(value)
        if kind in _VIEWS:  # dict_keys([...]): its items measured as a list's
            _measure(list(value), MAX_ITEMS, self.tick)
            return self.made(repr(value))
        _measure(value, MAX_ITEMS, self.tick)
        return self.made(repr(value) if use_repr else str(value))

    def format_value(self, value, spec) -> str:
        _check_spec(spec)
        if type(value) not in _SCALARS:
            if spec:
                raise TypeError(f"unsupported format string passed to "
                                f"{_typename(value)}.__format__")
            return self.to_str(value)
        if type(value) is int and value.bit_length() > MAX_STR_BITS:
            raise LimitExceeded("an integer too long to convert to a string")
        return self.made(format(value, spec))

    def format(self, template: str, args, kwargs) -> str:
        formatter = _Formatter(self)
        return self.made(formatter.vformat(template, list(args), kwargs))

    def percent(self, template: str, values) -> str:
        """``template % values`` with every width, precision and argument measured first."""
        args = list(values) if type(values) is tuple else [values]
        mapping = values if isinstance(values, dict) else None
        size, index, i, n = len(template), 0, 0, len(template)
        while i < n:
            self.tick()
            if template[i] != "%":
                i += 1
                continue
            i += 1
            key = None
            if i < n and template[i] == "(":
                close = template.find(")", i)
                if close < 0:
                    raise ValueError("incomplete format key")
                key, i = template[i + 1:close], close + 1
            while i < n and template[i] in "-+ #0":
                i += 1
            for _part in ("width", "precision"):
                if _part == "precision":
                    if i < n and template[i] == ".":
                        i += 1
                    else:
                        continue
                if i < n and template[i] == "*":
                    if index < len(args) and type(args[index]) in (int, bool):
                        size += abs(args[index])
                        if abs(args[index]) > MAX_WIDTH:
                            raise LimitExceeded(f"a format width of {args[index]}")
                    index += 1
                    i += 1
                    continue
                start = i
                while i < n and template[i].isdigit() and template[i].isascii():
                    i += 1
                if i > start:
                    number = int(template[start:i]) if i - start < 9 else MAX_WIDTH + 1
                    if number > MAX_WIDTH:
                        raise LimitExceeded(f"a format width or precision of "
                                            f"{template[start:i]}")
                    size += number
            while i < n and template[i] in "hlL":
                i += 1
            if i < n and template[i] == "%":
                i += 1
                continue
            if key is not None and mapping is not None:
                argument = mapping.get(key)
            else:
                argument = args[index] if index < len(args) else None
                index += 1
            size += len(self.to_str(argument)) if type(argument) not in _NUMBERS else 32
            if type(argument) is int and argument.bit_length() > MAX_STR_BITS:
                raise LimitExceeded("an integer too long to convert to a string")
            self.grows(size, "a formatted string")
            i += 1
        return self.made(template % values)

    # -- YAML --

    def _yaml_key(self, mapping, key):
        """``mapping[key]`` of YAML data (xacro wraps the value); a missing key is the
        AttributeError xacro raises, naming the file, the keys it has and the closest."""
        self.bounded(key)
        try:
            result = mapping[key]
        except AttributeError:
            origin = self._yaml_origin.get(id(mapping))
            if origin is None or origin[0] is not mapping:
                raise
            keys = [str(k) for k in dict.keys(mapping)]
            import difflib

            close = difflib.get_close_matches(str(key), keys, n=1, cutoff=0.6)
            shown = ", ".join(keys[:20]) + (f" and {len(keys) - 20} more" if len(keys) > 20
                                            else "")
            raise AttributeError(
                f"{origin[1]} has no key '{key}' (its keys: {shown or 'none'}"
                + (f"; did you mean '{close[0]}'?)" if close else ")")) from None
        if type(result) is self._yaml_dict:
            origin = self._yaml_origin.get(id(mapping))
            if origin is not None and origin[0] is mapping:
                self._remember(result, f"{origin[1]}, under '{key}'")
        return result

    def _remember(self, mapping, where: str):
        if len(self._yaml_origin) > 4096:
            self._yaml_origin.clear()
        self._yaml_origin[id(mapping)] = (mapping, where)

    def load_yaml(self, filename: str):
        """``xacro.load_yaml``: the safe loader, units through this interpreter, data checked."""
        xacro = self._xacro
        path = xacro.abs_filename_spec(filename)
        text = self.read_text(path)
        if len(text) > MAX_YAML_CHARS:  # YAML's scanner is pure Python: ~1 s per MB
            raise LimitExceeded(f"{filename}: a YAML file of more than {MAX_YAML_CHARS >> 20} "
                                "MB")
        import copy

        known = _YAML_DATA.get(text)
        if known is not None:  # parsed before (the language server expands on every edit)
            xacro.all_includes.append(path)
            return self._loaded(xacro.YamlListWrapper.wrap(copy.deepcopy(known)), filename)
        xacro.filestack.append(path)
        try:
            import yaml

            loader = self._yaml_loader()
            loader.nodes = 0
            data = yaml.load(text, Loader=loader)
        finally:
            xacro.filestack.pop()
            xacro.all_includes.append(path)
        _check_yaml(data, self.tick)
        if "!" not in text or "!" not in re.sub(_LITERAL_UNIT, "", text):  # no expression
            # in a unit tag: the data depend on the text alone, not on the expansion's symbols
            if len(_YAML_DATA) >= 64:
                _YAML_DATA.clear()
            _YAML_DATA[text] = copy.deepcopy(data)  # expressions may change what they get
        return self._loaded(xacro.YamlListWrapper.wrap(data), filename)

    def _loaded(self, data, filename: str):
        """YAML data handed out by ``load_yaml``, remembered with the file's name (as the
        expression gave it; a long absolute path by its last parts)."""
        if type(data) is self._yaml_dict:
            parts = filename.replace("\\", "/").split("/")
            self._remember(data, "YAML file " + (
                "/".join(parts[-3:]) if filename.startswith("/") else filename))
        return data

    def _yaml_loader(self):
        if self._loader is not None:
            return self._loader
        import yaml

        interpreter = self

        class Loader(yaml.SafeLoader):
            """The safe loader, with the deadline checked as it scans and at most MAX_ITEMS
            nodes."""

            nodes = 0

            def fetch_more_tokens(self):
                interpreter.tick()
                return super().fetch_more_tokens()

            def flatten_mapping(self, node):
                # merge keys (<<): PyYAML copies the merged pairs into every mapping that
                # merges them, again for every level (a chain of merges is quadratic): the
                # pairs are charged as they are copied
                super().flatten_mapping(node)
                interpreter.charge(len(node.value))
                interpreter.clock()

            def compose_node(self, parent, index):
                Loader.nodes += 1
                if Loader.nodes > MAX_ITEMS:
                    raise LimitExceeded(f"YAML data of more than {MAX_ITEMS} values")
                return super().compose_node(parent, index)

        def unit(factor):
            def construct(loader, node):
                value = loader.construct_scalar(node)
                try:
                    result = interpreter.evaluate(value, interpreter._xacro._global_symbols)
                except SyntaxError:
                    raise interpreter._xacro.XacroException(
                        f"invalid expression: {value}") from None
                return _to_float(interpreter, result) * factor
            return construct

        for tag, factor in (("!radians", 1.0), ("!degrees", math.pi / 180.0), ("!meters", 1.0),
                            ("!millimeters", 0.001), ("!foot", 0.3048), ("!inches", 0.0254)):
            Loader.add_constructor(tag, unit(factor))
        self._loader = Loader
        return Loader


def _read_text(path: str) -> str:
    import os

    if not os.path.isfile(path):
        raise OSError(f"{path}: not a regular file")
    if os.path.getsize(path) > 64 << 20:
        raise LimitExceeded(f"{path}: larger than 64 MB")
    with open(path, encoding="utf-8") as stream:
        return stream.read()


def _check_yaml(data, tick) -> None:
    """YAML data holds only the interpreter's values (dates become their text) and is not a
    bomb (aliases expanding to more than MAX_RESULT characters)."""
    import datetime

    seen = set()
    stack = [data]
    while stack:
        tick()
        item = stack.pop()
        if id(item) in seen:
            continue
        seen.add(id(item))
        if isinstance(item, dict):
            for key, value in list(item.items()):
                if isinstance(value, (datetime.date, datetime.datetime)):
                    item[key] = str(value)
                stack.append(key)
                stack.append(item[key])
        elif isinstance(item, list):
            for index, value in enumerate(item):
                if isinstance(value, (datetime.date, datetime.datetime)):
                    item[index] = str(value)
            stack.extend(item)
        elif isinstance(item, (tuple, set)):
            stack.extend(item)
        elif not isinstance(item, _SCALARS) or isinstance(item, (datetime.date,)):
            raise _unsafe(f"YAML value of type '{type(item).__name__}' is not supported")
    _measure(data, MAX_RESULT, tick)


def _ascii(text: str) -> str:
    return text.encode("ascii", "backslashreplace").decode("ascii")


def _check_spec(spec) -> None:
    """Numbers in a format spec (width, precision) above MAX_WIDTH are refused."""
    if type(spec) is not str:
        raise TypeError("format spec must be a string")
    number = 0
    for char in spec:
        if "0" <= char <= "9":
            number = number * 10 + ord(char) - 48
            if number > MAX_WIDTH:
                raise LimitExceeded(f"a format width or precision above {MAX_WIDTH}")
        else:
            number = 0


_BINOPS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
           ast.Div: operator.truediv, ast.FloorDiv: operator.floordiv, ast.Mod: operator.mod,
           ast.Pow: operator.pow, ast.LShift: operator.lshift, ast.RShift: operator.rshift,
           ast.BitOr: operator.or_, ast.BitAnd: operator.and_, ast.BitXor: operator.xor}
_COMPARE = {ast.Eq: operator.eq, ast.NotEq: operator.ne, ast.Lt: operator.lt,
            ast.LtE: operator.le, ast.Gt: operator.gt, ast.GtE: operator.ge}

# -- methods ---------------------------------------------------------------------------------

_STR_METHODS = frozenset([
    "capitalize", "casefold", "center", "count", "endswith", "expandtabs", "find", "format",
    "format_map", "index", "isalnum", "isalpha", "isascii", "isdecimal", "isdigit", "isidentifier", "islower",
    "isnumeric", "isprintable", "isspace", "istitle", "isupper", "join", "ljust", "lower",
    "lstrip", "maketrans", "partition", "removeprefix", "removesuffix", "replace", "rfind",
    "rindex", "rjust", "rpartition", "rsplit", "rstrip", "split", "splitlines", "startswith",
    "strip", "swapcase", "title", "translate", "upper", "zfill"])
_LIST_METHODS = frozenset(["append", "clear", "copy", "count", "extend", "index", "insert",
                           "pop", "remove", "reverse", "sort"])
_DICT_METHODS = frozenset(["clear", "copy", "fromkeys", "get", "items", "keys", "pop", "popitem",
                           "setdefault", "update", "values"])
_SET_READ = frozenset(["copy", "difference", "intersection", "isdisjoint", "issubset",
                       "issuperset", "symmetric_difference", "union"])
_SET_METHODS = _SET_READ | {"add", "clear", "discard", "pop", "remove", "update",
                            "difference_update", "intersection_update",
                            "symmetric_difference_update"}
_NUMBER_METHODS = frozenset(["conjugate", "bit_length", "bit_count", "is_integer",
                             "as_integer_ratio", "hex"])
_METHODS = {str: _STR_METHODS, list: _LIST_METHODS, tuple: frozenset({"count", "index"}),
            dict: _DICT_METHODS, set: _SET_METHODS, frozenset: _SET_READ,
            int: _NUMBER_METHODS - {"is_integer", "hex"}, bool: _NUMBER_METHODS - {"is_integer",
                                                                                 "hex"},
            float: frozenset(["conjugate", "is_integer", "as_integer_ratio", "hex"]),
            range: frozenset({"count", "index"}), complex: frozenset(["conjugate"]),
            _VIEWS[0]: frozenset(["isdisjoint"]), _VIEWS[2]: frozenset(["isdisjoint"])}
_PROPERTIES = {int: ("real", "imag", "numerator", "denominator"),
               bool: ("real", "imag", "numerator", "denominator"), float: ("real", "imag"),
               range: ("start", "stop", "step"), slice: ("start", "stop", "step"),
               complex: ("real", "imag")}
_PADDING = frozenset({"center", "ljust", "rjust", "zfill"})


def _arity(name, args, kwargs, low, high, keywords=()):
    if not low <= len(args) <= high:
        raise TypeError(f"{name}() takes {low}..{high} arguments ({len(args)} given)")
    for key in kwargs:
        if key not in keywords:
            raise TypeError(f"{name}() got an unexpected keyword argument '{key}'")


def _scalars(name, values, extra=()):
    for value in values:
        if type(value) not in _SCALARS and type(value) not in extra:
            raise TypeError(f"{name}(): argument of type '{_typename(value)}' is not supported")


def _call_method(it, obj, name, args, kwargs):
    kind = type(obj)
    if kind is str:
        return _str_method(it, obj, name, args, kwargs)
    if isinstance(obj, list):
        return _list_method(it, obj, name, args, kwargs)
    if isinstance(obj, dict):
        return _dict_method(it, obj, name, args, kwargs)
    if kwargs:
        raise TypeError(f"{name}() takes no keyword arguments")
    if kind in (set, frozenset) or kind in _VIEWS:
        many = name in ("union", "intersection", "difference", "update", "difference_update",
                        "intersection_update")
        _arity(f"set.{name}", args, kwargs, 0, MAX_ITEMS if many else 1)
        if many or name in ("isdisjoint", "issubset", "issuperset", "symmetric_difference",
                            "symmetric_difference_update"):
            args = [a if isinstance(a, (set, frozenset)) else it.items(a) for a in args]
        it.bounded(obj, *args)
        if name in ("union", "update"):
            it.grows(len(obj) + sum(len(a) for a in args))
        elif name in ("symmetric_difference", "symmetric_difference_update", "add"):
            it.grows(len(obj) + (len(args[0]) if args and name != "add" else 1))
        return it.made(getattr(obj, name)(*args))
    if kind in (tuple, range):
        it.bounded(obj, *args)
    else:
        _scalars(name, args)
    return it.made(getattr(obj, name)(*args))


def _str_method(it, text, name, args, kwargs):
    if name == "format":
        return it.format(text, args, kwargs)
    if name == "format_map":
        _arity("str.format_map", args, kwargs, 1, 1)
        if not isinstance(args[0], dict):
            raise TypeError(f"str.format_map() takes a dict here, not "
                            f"{_typename(args[0])}")
        return it.format(text, (), args[0])
    if name == "join":
        _arity("str.join", args, kwargs, 1, 1)
        pieces, size = [], 0
        for piece in it.iterate(args[0]):
            if type(piece) is not str:
                raise TypeError(f"sequence item {len(pieces)}: expected str instance, "
                                f"{_typename(piece)} found")
            size += len(piece) + len(text)
            it.grows(size, "a joined string")
            pieces.append(piece)
        return it.made(text.join(pieces))
    if name == "translate":
        _arity("str.translate", args, kwargs, 1, 1)
        table = args[0]
        if not isinstance(table, dict):
            raise TypeError("str.translate() takes a dict here")
        longest = 1
        for key, value in table.items():
            if type(key) is not int or type(value) not in (str, int, type(None)):
                raise TypeError("str.translate(): a table maps ints to str, int or None")
            if type(value) is str:
                longest = max(longest, len(value))
        it.grows(len(text) * longest, "a translated string")
        return it.made(text.translate(table))
    if name == "maketrans":
        _arity("str.maketrans", args, kwargs, 1, 3)
        if len(args) == 1:
            if not isinstance(args[0], dict):
                raise TypeError("if you give only one argument to maketrans it must be a dict")
            it.bounded(args[0])
            _scalars("str.maketrans", [*args[0].keys(), *args[0].values()])
            return it.made(str.maketrans(dict(args[0])))
        _scalars("str.maketrans", args)
        return it.made(str.maketrans(*args))
    keywords = {"split": ("sep", "maxsplit"), "rsplit": ("sep", "maxsplit"),
                "splitlines": ("keepends",), "expandtabs": ("tabsize",)}.get(name, ())
    _arity(f"str.{name}", args, kwargs, 0, 3, keywords)
    values = [*args, *kwargs.values()]
    for value in values:
        if type(value) is tuple and name in ("startswith", "endswith"):
            _scalars(f"str.{name}", value)
        elif type(value) not in _SCALARS:
            raise TypeError(f"str.{name}(): argument of type '{_typename(value)}' is not "
                            "supported")
    if name in _PADDING and args and type(args[0]) in (int, bool):
        it.grows(args[0], f"str.{name}({args[0]})")
    elif name == "expandtabs":
        size = values[0] if values else 8
        if type(size) in (int, bool):
            it.grows(len(text) + max(size, 0) * text.count("\t"), "str.expandtabs")
    elif name == "replace" and len(args) >= 2 and type(args[0]) is str \
            and type(args[1]) is str:
        count = text.count(args[0]) if args[0] else len(text) + 1
        if len(args) > 2 and type(args[2]) is int and args[2] >= 0:
            count = min(count, args[2])
        it.grows(len(text) + count * (len(args[1]) - len(args[0])), "str.replace")
    return it.made(getattr(text, name)(*args, **kwargs))


def _list_method(it, items, name, args, kwargs):
    if name == "sort":
        _arity("list.sort", args, kwargs, 0, 0, ("key", "reverse"))
        items[:] = _sorted(it, items, kwargs.get("key"), kwargs.get("reverse", False))
        return None
    _arity(f"list.{name}", args, kwargs, 0, 3)
    if name == "extend":
        _arity("list.extend", args, kwargs, 1, 1)
        more = it.items(args[0])
        it.grows(len(items) + len(more))
        items.extend(more)
        it.made(more)
        return None
    if name in ("append", "insert"):
        it.grows(len(items) + 1)
        it.spent += 1
    if name in ("count", "index", "remove"):
        it.bounded(items, *args)
    result = getattr(list, name)(items, *args)
    return it.made(result) if name == "copy" else result


def _dict_method(it, mapping, name, args, kwargs):
    if name in ("keys", "values", "items"):
        _arity(f"dict.{name}", args, kwargs, 0, 0)
        return it.made(getattr(dict, name)(mapping))  # Python's view
    if name == "fromkeys":
        return _fromkeys(it, args, kwargs)
    if name == "update":
        _arity("dict.update", args, kwargs, 0, 1, tuple(kwargs))
        update = _dict_of(it, args[0]) if args else {}
        update.update(kwargs)
        it.grows(len(mapping) + len(update))
        dict.update(mapping, update)
        it.made(update)
        return None
    _arity(f"dict.{name}", args, kwargs, 0, 2)
    it.bounded(*args)
    if name == "setdefault":
        it.grows(len(mapping) + 1)
    result = getattr(dict, name)(mapping, *args)
    return it.made(result) if name == "copy" else result


def _fromkeys(it, args, kwargs):
    _arity("dict.fromkeys", args, kwargs, 1, 2)
    keys = it.items(args[0])
    it.bounded(keys)
    return it.made(dict.fromkeys(keys, *args[1:]))


def _dict_of(it, value) -> dict:
    if isinstance(value, dict):
        it.bounded(value)
        return dict(value)
    result = {}
    for index, pair in enumerate(it.iterate(value)):
        pair = it.items(pair)
        if len(pair) != 2:
            raise ValueError(f"dictionary update sequence element #{index} has length "
                             f"{len(pair)}; 2 is required")
        it.bounded(pair[0])
        result[pair[0]] = pair[1]
        it.grows(len(result), "a dict")
    return result


def _unbound(function, name):
    """``str.upper``, ``dict.fromkeys``...: a method of a type-like function."""
    pytype = function.pytype
    if name == "fromkeys" and pytype is dict:
        return Function("dict.fromkeys", _fromkeys)
    if name == "maketrans" and pytype is str:
        return Function("str.maketrans", lambda it, a, k: _str_method(it, "", name, a, k))
    if name == "fromhex" and pytype is float:
        return Function("float.fromhex", lambda it, a, k: (
            _arity("float.fromhex", a, k, 1, 1), _scalars("float.fromhex", a),
            float.fromhex(a[0]))[-1])
    if name not in _METHODS.get(pytype, ()):
        raise _unsafe(f"'{pytype.__name__}.{name}' is not available in expressions")

    def impl(it, args, kwargs):
        if not args or not isinstance(args[0], pytype):
            raise TypeError(f"descriptor '{name}' for '{pytype.__name__}' objects doesn't "
                            "apply to that object")
        return _call_method(it, args[0], name, args[1:], kwargs)

    return Function(f"{pytype.__name__}.{name}", impl)


# -- the function table ------------------------------------------------------------------------


def _sorted(it, values, key=None, reverse=False):
    items = it.items(values)  # a new list, already accounted for
    it.bounded(items)
    if key is None:
        items.sort(reverse=bool(reverse))
        return items
    keys = [it.call(key, [item]) for item in items]
    it.bounded(keys)
    order = sorted(range(len(items)), key=keys.__getitem__, reverse=bool(reverse))
    return [items[i] for i in order]


def _extreme(pick):
    def impl(it, args, kwargs):
        name = pick.__name__
        _arity(name, args, kwargs, 1, MAX_ITEMS, ("key", "default"))
        values = it.items(args[0]) if len(args) == 1 else list(args)
        if not values:
            if "default" in kwargs:
                return kwargs["default"]
            raise ValueError(f"{name}() arg is an empty sequence")
        key = kwargs.get("key")
        keys = values if key is None else [it.call(key, [v]) for v in values]
        it.bounded(keys)
        best = 0
        for index in range(1, len(values)):
            it.tick()
            if (keys[index] < keys[best]) if pick is min else (keys[index] > keys[best]):
                best = index
        return values[best]
    return impl


def _sum(it, args, kwargs):
    _arity("sum", args, kwargs, 1, 2, ("start",))
    total = args[1] if len(args) > 1 else kwargs.get("start", 0)
    if type(total) is str:
        raise TypeError("sum() can't sum strings [use ''.join(seq) instead]")
    for item in it.iterate(args[0]):
        total = it.binop(ast.Add, total, item)
    return total


def _prod(it, args, kwargs):
    _arity("prod", args, kwargs, 1, 1, ("start",))
    total = kwargs.get("start", 1)
    for item in it.iterate(args[0]):
        total = it.binop(ast.Mult, total, item)
    return total


def _lazy(kind, make):
    def impl(it, args, kwargs):
        return Lazy(make(it, args, kwargs), kind)
    return impl


# map/filter/zip/enumerate/reversed check their arguments when called, as Python's do (an
# argument that is not iterable is a TypeError even when nothing is taken from the result:
# zip('', 2.0)); only the items are made lazily


def _map(it, args, kwargs):
    _arity("map", args, kwargs, 2, MAX_ITEMS)
    function, iterables = args[0], [it.iterate(a) for a in args[1:]]
    return (it.call(function, list(values)) for values in zip(*iterables))


def _filter(it, args, kwargs):
    _arity("filter", args, kwargs, 2, 2)
    function = args[0]
    return (value for value in it.iterate(args[1])
            if (value if function is None else it.call(function, [value])))


def _zip(it, args, kwargs):
    _arity("zip", args, kwargs, 0, MAX_ITEMS, ("strict",))
    iterables = [it.iterate(a) for a in args]
    return (tuple(v) for v in zip(*iterables, strict=bool(kwargs.get("strict"))))


def _enumerate(it, args, kwargs):
    _arity("enumerate", args, kwargs, 1, 2, ("start",))
    start = args[1] if len(args) > 1 else kwargs.get("start", 0)
    _scalars("enumerate", [start])
    return enumerate(it.iterate(args[0]), start)


def _reversed(it, args, kwargs):
    _arity("reversed", args, kwargs, 1, 1)
    value = args[0]
    if not isinstance(value, (list, tuple, str, range, dict, *_VIEWS)):
        raise TypeError(f"'{_typename(value)}' object is not reversible")
    return it._ticking(reversed(value))


def _range(it, args, kwargs):
    _arity("range", args, kwargs, 1, 3)
    for value in args:
        if type(value) not in (int, bool):
            raise TypeError(f"'{_typename(value)}' object cannot be interpreted as an integer")
    result = range(*args)
    try:
        size = len(result)
    except OverflowError:
        size = MAX_ITEMS + 1
    if size > MAX_ITEMS:
        raise LimitExceeded(f"a range of more than {MAX_ITEMS} items")
    return result


def _to_float(it, value):
    if type(value) not in (int, float, bool, str):
        raise TypeError(f"float() argument must be a string or a real number, not "
                        f"'{_typename(value)}'")
    return float(value)


def _int(it, args, kwargs):
    _arity("int", args, kwargs, 0, 2, ("base",))
    _scalars("int", [*args, *kwargs.values()])
    if args and type(args[0]) is str and len(args[0]) > 5000:
        raise LimitExceeded("a number of more than 5000 digits")
    return it.made(int(*args, **kwargs))


def _str(it, args, kwargs):
    _arity("str", args, kwargs, 0, 1)
    return it.to_str(args[0]) if args else ""


def _collection(pytype):
    def impl(it, args, kwargs):
        _arity(pytype.__name__, args, kwargs, 0, 1)
        values = it.items(args[0]) if args else []  # a new list, already accounted for
        if pytype is list:
            return values
        if pytype in (set, frozenset):
            it.bounded(values)
        return pytype(values)
    return impl


def _dict(it, args, kwargs):
    _arity("dict", args, kwargs, 0, 1, tuple(kwargs))
    result = _dict_of(it, args[0]) if args else {}
    result.update(kwargs)
    return it.made(result)


def _isinstance(it, args, kwargs):
    _arity("isinstance", args, kwargs, 2, 2)
    return isinstance(args[0], _types_of(args[1]))


def _issubclass(it, args, kwargs):
    _arity("issubclass", args, kwargs, 2, 2)
    (first,) = _types_of(args[0], single=True)
    return issubclass(first, _types_of(args[1]))


def _types_of(value, single=False):
    if type(value) is Function and value.pytype is not None:
        return (value.pytype,)
    if type(value) is tuple and not single:
        return tuple(t for v in value for t in _types_of(v))
    raise TypeError("isinstance() arg 2 must be a type (str, int, float, bool, list, tuple, "
                    "dict, set, frozenset) or a tuple of them")


def _plain(name, function, low, high, keywords=()):
    def impl(it, args, kwargs):
        _arity(name, args, kwargs, low, high, keywords)
        _scalars(name, [*args, *kwargs.values()])
        return it.made(function(*args, **kwargs))
    return impl


def _round(it, args, kwargs):
    _arity("round", args, kwargs, 1, 2, ("ndigits",))
    _scalars("round", [*args, *kwargs.values()])
    digits = args[1] if len(args) > 1 else kwargs.get("ndigits")
    if type(args[0]) is int and type(digits) is int and digits < -5000:
        return 0
    return it.made(round(*args, **kwargs))


def _hash(it, args, kwargs):
    _arity("hash", args, kwargs, 1, 1)
    it.bounded(args[0])
    return hash(args[0])


def _len(it, args, kwargs):
    _arity("len", args, kwargs, 1, 1)
    value = args[0]
    if isinstance(value, (str, list, tuple, dict, set, frozenset, range, *_VIEWS)):
        return len(value)
    raise TypeError(f"object of type '{_typename(value)}' has no len()")


def _all_any(want):
    def impl(it, args, kwargs):
        _arity("all" if want else "any", args, kwargs, 1, 1)
        for value in it.iterate(args[0]):
            if bool(value) != want:
                return not want
        return want
    return impl


def _bool(it, args, kwargs):
    _arity("bool", args, kwargs, 0, 1)
    return bool(args[0]) if args else False


def _slice_function(it, args, kwargs):
    _arity("slice", args, kwargs, 1, 3)
    _scalars("slice", args)
    return slice(*args)


def _native(name, function):
    """A Python function urdftool wrote ($(eval)'s arg, env, find...): str arguments only."""
    def impl(it, args, kwargs):
        _arity(name, args, kwargs, 0, 3)
        for value in args:
            if type(value) is not str:
                raise TypeError(f"{name}(): arguments must be strings")
        result = function(*args)
        if type(result) not in _SCALARS:
            raise _unsafe(f"{name}() returned a '{type(result).__name__}'")
        return result
    return impl


# math: every public function, with the ones that can grow checked first

def _big_math(name, function):
    def impl(it, args, kwargs):
        _arity(f"math.{name}", args, kwargs, 1, 2)
        _scalars(f"math.{name}", args)
        if all(type(a) in (int, bool) for a in args):
            n, k = args[0], args[-1] if len(args) > 1 else args[0]
            if n > 1 and 0 <= k <= n:
                bits = (math.lgamma(n + 1) - (math.lgamma(n - k + 1) if name != "factorial"
                                              else 0)
                        - (math.lgamma(k + 1) if name == "comb" else 0)) / math.log(2)
                if bits > MAX_INT_BITS:
                    raise LimitExceeded(f"math.{name}{tuple(args)} is too large a number")
        return it.made(function(*args))
    return impl


def _lcm(it, args, kwargs):
    _arity("math.lcm", args, kwargs, 0, MAX_ITEMS)
    _scalars("math.lcm", args)
    total = 1
    for value in args:
        it.tick()
        if type(total) is int and type(value) is int \
                and total.bit_length() + value.bit_length() > MAX_INT_BITS:
            raise LimitExceeded(f"math.lcm of more than {MAX_INT_BITS} bits")
        total = math.lcm(total, value)
    return total


def _numbers_math(name, function):
    iterables = {"fsum": (0,), "dist": (0, 1)}.get(name, ())

    def impl(it, args, kwargs):
        args = [it.items(a) if i in iterables else a for i, a in enumerate(args)]
        for index, value in enumerate(args):
            _scalars(f"math.{name}", value if index in iterables else [value])
        _scalars(f"math.{name}", kwargs.values())
        return it.made(function(*args, **kwargs))
    return impl


def _math_entries() -> dict:
    entries = {}
    for name, value in vars(math).items():
        if name.startswith("_"):
            continue
        if isinstance(value, float):
            entries[name] = value
        elif name in ("factorial", "comb", "perm"):
            entries[name] = Function(name, _big_math(name, value))
        elif name == "prod":
            entries[name] = Function(name, _prod)
        elif name == "lcm":
            entries[name] = Function(name, _lcm)
        elif callable(value):
            entries[name] = Function(name, _numbers_math(name, value))
    return entries


# xacro.*

def _tokenize(it, args, kwargs):
    """xacro.tokenize without a regex: ``sep`` is read as the regex character class xacro
    builds from it (literal characters, ``a-z`` ranges, a leading ``^``, ``\\s``/``\\d``/``\\w``),
    and the string split on any of them; a ``]`` that would end the class (and make the rest
    a regex) is refused."""
    _arity("xacro.tokenize", args, kwargs, 1, 3, ("sep", "skip_empty"))
    text = args[0]
    sep = args[1] if len(args) > 1 else kwargs.get("sep", ",; ")
    skip_empty = args[2] if len(args) > 2 else kwargs.get("skip_empty", True)
    if type(text) is not str or type(sep) is not str:
        raise TypeError("xacro.tokenize() takes strings")
    separator = _char_class(sep)
    pieces, start = [], 0
    for index, char in enumerate(text):
        if index & 255 == 0:
            it.tick()
        if separator(char):
            pieces.append(text[start:index])
            start = index + 1
    pieces.append(text[start:])
    return it.made([p for p in pieces if p] if skip_empty else pieces)


_CLASSES = {"s": str.isspace, "d": str.isdecimal, "w": lambda c: c.isalnum() or c == "_"}
_ESCAPES = {"n": "\n", "t": "\t", "r": "\r", "f": "\f", "v": "\v", "a": "\a", "0": "\0"}


def _char_class(sep: str):
    if not sep:
        raise ValueError("unterminated character set (xacro.tokenize with an empty separator)")
    negate = sep[0] == "^" and len(sep) > 1
    body = sep[1:] if negate else sep
    chars, ranges, classes = set(), [], []
    i = 0
    while i < len(body):
        char = body[i]
        if char == "\\" and i + 1 < len(body):
            escaped = body[i + 1]
            if escaped.lower() in _CLASSES:
                test = _CLASSES[escaped.lower()]
                classes.append(test if escaped.islower() else (lambda c, t=test: not t(c)))
            else:
                chars.add(_ESCAPES.get(escaped, escaped))
            i += 2
        elif char == "]" and i > 0:
            raise _unsafe("xacro.tokenize's separator closes the character class xacro builds "
                          "a regular expression from; urdftool splits on characters only")
        elif i + 2 < len(body) and body[i + 1] == "-":
            ranges.append((char, body[i + 2]))
            i += 3
        else:
            chars.add(char)
            i += 1

    def separator(c):
        hit = c in chars or any(a <= c <= b for a, b in ranges) or any(t(c) for t in classes)
        return hit != negate

    return separator


def _messages(name):
    def impl(it, args, kwargs):
        _arity(f"xacro.{name}", args, kwargs, 0, MAX_ITEMS, ("print_location",))
        location = kwargs.get("print_location", name in ("warning", "error"))
        xacro = it._xacro
        texts = [it.to_str(a) for a in args]
        if name != "print_location":
            getattr(xacro, name)(*texts)
        if location or name == "print_location":
            xacro.print_location()
        return ""
    return impl


def _fatal(it, args, kwargs):
    _arity("xacro.fatal", args, kwargs, 0, MAX_ITEMS)
    raise it._xacro.XacroException(" ".join(it.to_str(a) for a in args))


def _load_yaml(it, args, kwargs):
    _arity("xacro.load_yaml", args, kwargs, 1, 1)
    if type(args[0]) is not str:
        raise TypeError("xacro.load_yaml() takes a file name")
    return it.load_yaml(args[0])


def _abs_filename(it, args, kwargs):
    _arity("xacro.abs_filename", args, kwargs, 1, 1)
    if type(args[0]) is not str:
        raise TypeError("xacro.abs_filename() takes a file name")
    return it._xacro.abs_filename_spec(args[0])


def _dotify(it, args, kwargs):
    _arity("xacro.dotify", args, kwargs, 0, 1, tuple(kwargs))
    data = _dict_of(it, args[0]) if args else {}
    data.update(kwargs)
    return it._yaml_dict(data)


def _arg(it, args, kwargs):
    _arity("xacro.arg", args, kwargs, 1, 1)
    return it.admit(it._xacro.substitution_args_context["arg"][args[0]])


def _complex(it, args, kwargs):
    _arity("complex", args, kwargs, 0, 2, ("real", "imag"))
    _scalars("complex", [*args, *kwargs.values()])
    if args and type(args[0]) is str and len(args[0]) > 5000:
        raise LimitExceeded("a number of more than 5000 characters")
    return complex(*args, **kwargs)


def _type(it, args, kwargs):
    """``python.type(value)``: the type-like function of the table (``python.type(1) is
    python.int``); the three-argument form (which builds a class) is refused."""
    if len(args) == 3 or kwargs:
        raise _unsafe("python.type(name, bases, dict) builds classes; urdftool's interpreter "
                      "does not offer it")
    _arity("type", args, kwargs, 1, 1)
    kind = type(args[0])
    function = _TYPES.get(kind)
    if function is None:
        if isinstance(args[0], _OWN):
            raise _unsafe(f"python.type() of a {_typename(args[0])} is not available in "
                          "expressions")
        # NoneType, a dict view, YAML data: compared and printed, never called
        name = kind.__name__ if kind.__module__ == "builtins" else \
            f"{kind.__module__}.{kind.__qualname__}"
        function = _TYPES[kind] = Function(name, _uncallable(name), kind)
    return function


def _uncallable(name):
    def impl(it, args, kwargs):
        raise _unsafe(f"calling the type {name} is not available in expressions")
    return impl


_TABLES: dict | None = None
_TYPES: dict = {}  # Python type -> its type-like Function of the table
_REFUSED = {"vars": "python.vars exposes objects' internals; urdftool's interpreter does not "
                    "offer it"}


def _tables() -> dict:
    """urdftool's symbol tables (built once): ``python``, ``math``, ``xacro`` namespaces, the
    top-level names xacro defines, and the names ``$(eval ...)`` sees."""
    global _TABLES
    if _TABLES is not None:
        return _TABLES
    python = {
        "list": Function("list", _collection(list), list),
        "tuple": Function("tuple", _collection(tuple), tuple),
        "set": Function("set", _collection(set), set),
        "frozenset": Function("frozenset", _collection(frozenset), frozenset),
        "dict": Function("dict", _dict, dict), "str": Function("str", _str, str),
        "int": Function("int", _int, int),
        "float": Function("float", lambda it, a, k: (_arity("float", a, k, 0, 1),
                                                     _to_float(it, a[0]) if a else 0.0)[-1],
                          float),
        "bool": Function("bool", _bool, bool),
        "complex": Function("complex", _complex, complex), "type": Function("type", _type),
        "len": Function("len", _len), "map": Function("map", _lazy("map", _map)),
        "filter": Function("filter", _lazy("filter", _filter)),
        "zip": Function("zip", _lazy("zip", _zip)),
        "enumerate": Function("enumerate", _lazy("enumerate", _enumerate)),
        "reversed": Function("reversed", _lazy("list_reverseiterator", _reversed)),
        "sorted": Function("sorted", lambda it, a, k: (
            _arity("sorted", a, k, 1, 1, ("key", "reverse")),
            _sorted(it, a[0], k.get("key"), k.get("reverse", False)))[-1]),
        "min": Function("min", _extreme(min)), "max": Function("max", _extreme(max)),
        "sum": Function("sum", _sum), "all": Function("all", _all_any(True)),
        "any": Function("any", _all_any(False)), "range": Function("range", _range, range),
        "round": Function("round", _round), "abs": Function("abs", _plain("abs", abs, 1, 1)),
        "divmod": Function("divmod", _plain("divmod", divmod, 2, 2)),
        "ord": Function("ord", _plain("ord", ord, 1, 1)), "hash": Function("hash", _hash),
        "repr": Function("repr", lambda it, a, k: (_arity("repr", a, k, 1, 1),
                                                   it.to_str(a[0], use_repr=True))[-1]),
        "isinstance": Function("isinstance", _isinstance),
        "issubclass": Function("issubclass", _issubclass),
        "slice": Function("slice", _slice_function, slice),
        "True": True, "False": False,
    }
    python.update({name: _Refused(reason) for name, reason in _REFUSED.items()})
    _TYPES.update((entry.pytype, entry) for entry in python.values()
                  if type(entry) is Function and entry.pytype is not None)
    math_entries = _math_entries()
    xacro_entries = {
        "load_yaml": Function("load_yaml", _load_yaml),
        "abs_filename": Function("abs_filename", _abs_filename),
        "dotify": Function("dotify", _dotify), "arg": Function("arg", _arg),
        "tokenize": Function("tokenize", _tokenize), "fatal": Function("fatal", _fatal),
        **{name: Function(name, _messages(name))
           for name in ("message", "warning", "error", "print_location")},
    }
    namespaces = {"python": Namespace("python", python), "math": Namespace("math", math_entries),
                  "xacro": Namespace("xacro", xacro_entries)}
    substitution = {**{k: v for k, v in python.items() if type(v) is not _Refused},
                    **math_entries, "None": None}
    _TABLES = {"namespaces": namespaces, "substitution": substitution}
    return _TABLES


def _identity_map(xacro, tables) -> dict:
    """xacro's global symbols (real builtins, math, its helpers) -> urdftool's entries, by
    identity: the names a file has not redefined resolve to urdftool's functions."""
    key = id(xacro._global_symbols)
    cached = _IDENTITY.get(key)
    if cached is not None:
        return cached
    namespaces = tables["namespaces"]
    top = {**namespaces["python"].entries, **namespaces["math"].entries,
           **namespaces["xacro"].entries}
    mapping = {}
    for name, value in xacro._global_symbols.items():
        if isinstance(value, xacro.NameSpace) and name in namespaces:
            mapping[id(value)] = namespaces[name]
            for inner, entry in dict.items(value):
                if callable(entry):
                    mapping[id(entry)] = namespaces[name].entries.get(
                        inner, _Refused(f"'{name}.{inner}' is not available in expressions"))
        elif callable(value) or isinstance(value, xacro.NameSpace):
            mapping[id(value)] = top.get(name, _Refused(f"'{name}' is not available in "
                                                        "expressions"))
    _IDENTITY.clear()
    _IDENTITY[key] = mapping
    return mapping


_IDENTITY: dict = {}
_PYTHON_BUILTINS = frozenset(dir(__builtins__) if not isinstance(__builtins__, dict)
                             else __builtins__)
