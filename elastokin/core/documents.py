"""The one reader of YAML files: a document's plain data with the line of every key, and typed access
to its mappings whose errors name file:line, the dotted key, the value and what was expected.

Every YAML file of the product (vehicles, scenarios, benches, parameter sets, truths, datasets, rig
metadata) is read through :class:`Document`, which also refuses duplicate keys (YAML would let the
last one win silently). Values built in code are checked with the same readers
(:meth:`Document.of_data`: no lines to name).
"""

from __future__ import annotations

import math
import re
import sys
from pathlib import Path
from typing import Any, Mapping

import yaml
from yaml.composer import Composer

from elastokin.core.errors import InputError
from elastokin.core.files import is_file, read_text

#: Where a value sits in a document: mapping keys and list indices from the top.
KeyPath = tuple[Any, ...]


def dotted(path: KeyPath) -> str:
    """``("cases", 2, "amplitude_mm")`` → ``"cases[2].amplitude_mm"``."""
    out = ""
    for part in path:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


class _Refused(Exception):
    """What the loader refuses in a document that YAML itself accepts, at a line."""

    def __init__(self, message: str, line: int):
        super().__init__(message)
        self.line = line


try:   # libyaml's scanner and parser under PyYAML's composer: 7x faster than the pure-Python loader on a vehicle file
    from yaml._yaml import CParser

    class _SafeLoader(Composer, CParser, yaml.constructor.SafeConstructor, yaml.resolver.Resolver):
        """YAML's safe loader, its scanning and parsing in C (the composer stays Python: it sees the aliases)."""

        def __init__(self, stream: str):
            CParser.__init__(self, stream)
            yaml.constructor.SafeConstructor.__init__(self)
            yaml.resolver.Resolver.__init__(self)
            Composer.__init__(self)
except ImportError:   # PyYAML built without libyaml
    _SafeLoader = yaml.SafeLoader


#: The most values (nodes) and characters of text a document may hold once its aliases are
#: expanded: a vehicle file holds some 2000 values, a sweep of 300 cases some 5000; a few lines of
#: anchors and aliases can otherwise stand for gigabytes (a "billion laughs").
MAX_EXPANDED_NODES = 200_000
MAX_EXPANDED_CHARS = 20_000_000
_MERGE = "tag:yaml.org,2002:merge"


class _Loader(_SafeLoader):
    """YAML's safe loader; anchors, aliases and merge keys (``<<: *base``) are YAML's, their
    expansion bounded (:func:`_check_expansion`)."""

    aliased = False

    def compose_node(self, parent: yaml.Node | None, index: Any) -> yaml.Node:
        if self.check_event(yaml.AliasEvent):
            self.aliased = True
        return super().compose_node(parent, index)

    def construct_object(self, node: yaml.Node, deep: bool = False) -> Any:
        """YAML's construction, with the line of a scalar Python cannot convert (a 13th month, an
        integer of more than 4300 digits) rather than a bare ValueError."""
        try:
            return super().construct_object(node, deep)
        except ValueError as exc:
            if isinstance(exc, InputError):
                raise
            raise _Refused(f"{str(node.value)[:40]!r} cannot be read as a value ({exc})", node.start_mark.line + 1) from None


class _Dumper(yaml.SafeDumper):
    """YAML's safe dumper, quoting the texts that the loader reads as numbers (``'2e3'``)."""


# YAML 1.1 reads 1e-6 and 1.5e3 (no dot, or no exponent sign) as text; engineers mean numbers, as YAML 1.2 does.
for _yaml_class in (_Loader, _Dumper):
    _yaml_class.add_implicit_resolver("tag:yaml.org,2002:float",
                                      re.compile(r"^[-+]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)[eE][-+]?[0-9]+$"),
                                      list("-+0123456789."))


def dump_yaml(data: Any, **options: Any) -> str:
    """``data`` as YAML text that :class:`Document` reads back as the same data (``yaml.safe_dump``'s
    ``options``)."""
    return yaml.dump(data, Dumper=_Dumper, **options)


def _check_expansion(root: yaml.Node) -> None:
    """Refuse, at its line, the first value whose aliases expand beyond the bounds, or that an alias
    inside it refers back to (the sizes are counted over the node graph, not expanded)."""
    sizes: dict[int, tuple[int, int]] = {}
    open_: set[int] = set()

    def size(node: yaml.Node) -> tuple[int, int]:
        if id(node) in sizes:
            return sizes[id(node)]
        if id(node) in open_:
            raise _Refused("a YAML alias refers to a value from inside it", node.start_mark.line + 1)
        open_.add(id(node))
        if isinstance(node, yaml.ScalarNode):
            nodes, chars = 1, len(node.value)
        else:
            children = [n for pair in node.value for n in pair] if isinstance(node, yaml.MappingNode) else node.value
            counted = [size(child) for child in children]
            nodes, chars = 1 + sum(n for n, _ in counted), sum(c for _, c in counted)
        open_.discard(id(node))
        if nodes > MAX_EXPANDED_NODES or chars > MAX_EXPANDED_CHARS:
            raise _Refused(f"YAML aliases here expand to more than {MAX_EXPANDED_NODES} values or "
                           f"{MAX_EXPANDED_CHARS} characters; write less of it, or share less", node.start_mark.line + 1)
        sizes[id(node)] = nodes, chars
        return nodes, chars

    size(root)


def _pairs(loader: _Loader, node: yaml.MappingNode, source: str, path: KeyPath) -> list[tuple[Any, yaml.Node]]:
    """The (key as the data holds it, value node) pairs of a mapping, its merge keys' mappings
    (``<<: *base`` or ``<<: [*a, *b]``) giving the keys it does not set itself; InputError at a key
    written twice (``1e3`` and ``1000.0`` are one key, as they are in the data)."""
    own: dict[Any, tuple[yaml.ScalarNode, yaml.Node]] = {}
    merged: list[yaml.Node] = []
    for key, value in node.value:
        if not isinstance(key, yaml.ScalarNode):
            raise _Refused(f"keys must be plain names (at {dotted(path) or 'the top'})", key.start_mark.line + 1)
        if key.tag == _MERGE:
            merged += value.value if isinstance(value, yaml.SequenceNode) else [value]
            continue
        name = loader.construct_object(key)
        if name in own:
            first = own[name][0]
            also = "" if first.value == key.value else f" (the key {first.value!r} of line {first.start_mark.line + 1})"
            raise InputError(f"duplicate key {key.value!r}{also}", source=f"{source}:{key.start_mark.line + 1}",
                             key=dotted(path + (name,)))
        own[name] = key, value
    pairs = {name: value for name, (_, value) in own.items()}
    for base in merged:
        if not isinstance(base, yaml.MappingNode):
            raise _Refused("a merge key (<<) takes a mapping or a list of mappings", base.start_mark.line + 1)
        for name, value in _pairs(loader, base, source, path):
            pairs.setdefault(name, value)
    return list(pairs.items())


def _unshared(data: Any) -> Any:
    """``data`` with every mapping and list its own (aliases make one object stand in two places)."""
    if isinstance(data, dict):
        return {key: _unshared(value) for key, value in data.items()}
    if isinstance(data, list):
        return [_unshared(value) for value in data]
    return data


class Document:
    """A YAML document as plain data plus the line of every key path (from the composed nodes)."""

    def __init__(self, text: str, source: str):
        """Parse ``text``; InputError naming ``source`` when it is not valid YAML, repeats a key
        (as the data holds it: ``1e3`` and ``1000.0`` are one key), uses a key that is not a plain
        scalar, expands its aliases beyond :data:`MAX_EXPANDED_NODES` values, refers to a value from
        inside it, or nests beyond Python's recursion limit."""
        self.source, self.text = source, text
        self.lines: dict[KeyPath, int] = {}
        loader = _Loader(text)
        try:
            node = loader.get_single_node()
            if node is not None:
                _check_expansion(node)
                self._index(loader, node, ())
            data = loader.construct_document(node) if node is not None else None
            # values an alias shares are copies, as if written out: a change to one is not a change to the other
            self.data = _unshared(data) if loader.aliased else data
        except yaml.YAMLError as exc:
            if "maximum nesting depth" in str(exc):   # libyaml's own limit, before Python's recursion limit
                raise InputError("not valid here: nested too deeply", source=source) from None
            raise InputError(f"not valid YAML: {exc}", source=source) from None
        except _Refused as exc:
            raise InputError(str(exc), source=f"{source}:{exc.line}") from None
        except RecursionError:
            raise InputError("not valid here: nested too deeply", source=source) from None
        finally:
            loader.dispose()

    @classmethod
    def read(cls, path: str | Path, missing: str = "no such file") -> "Document":
        """The document in the file ``path``; InputError naming it (with the message ``missing`` when
        it does not exist) if it cannot be read, is not UTF-8 text or not valid YAML."""
        if not is_file(path):
            raise InputError(missing, source=str(path))
        return cls(read_text(path), str(path))

    @classmethod
    def of_data(cls, data: Any, source: str) -> "Document":
        """Data built in code, checked by the same readers; errors name ``source`` (no line)."""
        doc = cls.__new__(cls)
        doc.source, doc.text, doc.data, doc.lines = source, "", data, {}
        return doc

    def _index(self, loader: _Loader, node: yaml.Node, path: KeyPath) -> None:
        self.lines[path] = node.start_mark.line + 1
        if isinstance(node, yaml.MappingNode):
            for key, value in _pairs(loader, node, self.source, path):
                self._index(loader, value, path + (key,))
        elif isinstance(node, yaml.SequenceNode):
            for i, item in enumerate(node.value):
                self._index(loader, item, path + (i,))

    def where(self, path: KeyPath) -> str:
        """``file:line`` of ``path`` (or of its closest enclosing node that has a line), else the file."""
        at = path
        while at not in self.lines and at:
            at = at[:-1]
        line = self.lines.get(at)
        return f"{self.source}:{line}" if line else self.source

    def error(self, path: KeyPath, message: str) -> InputError:
        """An InputError at ``path``, naming its file:line and dotted key."""
        return InputError(message, source=self.where(path), key=dotted(path) or None)

    def top(self, allowed: tuple[str, ...]) -> "Fields":
        """The document's top mapping, checked against the ``allowed`` keys."""
        return Fields.of(self, (), self.data, allowed)


def check_number(doc: Document, path: KeyPath, value: Any, *, positive: bool = False, nonneg: bool = False,
                 nonzero: bool = False, integer: bool = False, at_most: float = math.inf, unit: str = "") -> float:
    """``value`` (found at ``path`` of ``doc``) as a finite float with the properties asked for, and
    at most ``at_most`` in magnitude (a physical range; ``unit`` for the message); InputError at
    ``path`` otherwise."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not abs(value) <= sys.float_info.max:
        raise doc.error(path, f"expected a finite number, got {value!r:.60}")
    if integer and value != int(value):
        raise doc.error(path, f"expected a whole number, got {value!r}")
    for bad, what in ((positive and value <= 0, "positive"), (nonneg and value < 0, "non-negative"),
                      (nonzero and value == 0, "non-zero")):
        if bad:
            raise doc.error(path, f"expected a {what} number, got {value!r}")
    if abs(value) > at_most:
        raise doc.error(path, f"expected at most {at_most:g}{f' {unit}' if unit else ''} in magnitude, got {value!r}")
    return float(value)


def check_vector(doc: Document, path: KeyPath, value: Any, n: int, *, at_most: float = math.inf,
                 unit: str = "") -> tuple[float, ...]:
    """``value`` (found at ``path``) as a list of ``n`` finite numbers, each at most ``at_most`` in
    magnitude; InputError at ``path`` otherwise."""
    if not isinstance(value, (list, tuple)) or len(value) != n:
        raise doc.error(path, f"expected a list of {n} numbers, got {value!r:.80}")
    return tuple(check_number(doc, path + (i,), v, at_most=at_most, unit=unit) for i, v in enumerate(value))


class Fields:
    """Typed access to a mapping of a document; each value remembers where it was written."""

    def __init__(self, doc: Document, values: Mapping[str, tuple[Any, KeyPath]], where: KeyPath):
        """``values`` maps each key to (value, where it was written); ``where`` is the mapping's own path."""
        self.doc, self.values, self.where = doc, values, where

    @classmethod
    def of(cls, doc: Document, path: KeyPath, data: Any, allowed: tuple[str, ...]) -> "Fields":
        """The mapping ``data`` at ``path``, checked against the ``allowed`` keys."""
        if not isinstance(data, Mapping):
            raise doc.error(path, f"expected a mapping with keys {', '.join(allowed)}, got {data!r}")
        fields = cls(doc, {k: (v, path + (k,)) for k, v in data.items()}, path)
        fields.check_keys(allowed)
        return fields

    def check_keys(self, allowed: tuple[str, ...], context: str = "") -> None:
        """InputError at the first key not in ``allowed`` (``context`` says for what)."""
        for key, (_, path) in self.values.items():
            if key not in allowed:
                raise self.doc.error(path, f"unknown key {key!r}{context}; expected one of {', '.join(allowed)}")

    def has(self, key: str) -> bool:
        """Whether ``key`` was given."""
        return key in self.values

    def path(self, key: str) -> KeyPath:
        """Where ``key``'s value was written (or would be)."""
        return self.values[key][1] if key in self.values else self.where + (key,)

    def raw(self, key: str, default: Any = ...) -> Any:
        """The value as written, ``default`` when absent; InputError ``missing key`` without a default."""
        if key not in self.values:
            if default is ...:
                raise self.doc.error(self.where + (key,), "missing key")
            return default
        return self.values[key][0]

    def fail(self, key: str, message: str) -> InputError:
        """An InputError at ``key`` (to raise)."""
        return self.doc.error(self.path(key), message)

    def number(self, key: str, default: Any = ..., *, positive: bool = False, nonneg: bool = False,
               nonzero: bool = False, integer: bool = False, at_most: float = math.inf, unit: str = "") -> float:
        """A finite number (:func:`check_number`)."""
        return check_number(self.doc, self.path(key), self.raw(key, default), positive=positive, nonneg=nonneg,
                            nonzero=nonzero, integer=integer, at_most=at_most, unit=unit)

    def vector(self, key: str, n: int = 3, *, at_most: float = math.inf, unit: str = "") -> tuple[float, ...]:
        """A list of ``n`` finite numbers, each at most ``at_most`` in magnitude."""
        return check_vector(self.doc, self.path(key), self.raw(key), n, at_most=at_most, unit=unit)

    def choice(self, key: str, options: tuple[str, ...], default: Any = ...) -> Any:
        """One of ``options`` (or ``default`` when absent)."""
        value = self.raw(key, default)
        if value not in options and not (value is None and default is None):
            raise self.fail(key, f"expected one of {', '.join(options)}, got {value!r}")
        return value

    def text(self, key: str, default: Any = ...) -> str:
        """A string."""
        value = self.raw(key, default)
        if not isinstance(value, str):
            raise self.fail(key, f"expected a string, got {value!r}")
        return value

    def fields(self, key: str, allowed: tuple[str, ...], default: Any = ...) -> "Fields":
        """The mapping under ``key`` (``default`` when absent), checked against ``allowed``."""
        return Fields.of(self.doc, self.path(key), self.raw(key, default), allowed)
