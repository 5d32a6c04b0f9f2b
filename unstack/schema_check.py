"""A small JSON Schema (draft 2020-12) validator for the keywords unstack's schemas use.

``jsonschema`` takes longer to import than a whole decision on five boxes; this module
checks the subset of keywords the shipped schemas use, with the same semantics and errors
shaped like ``jsonschema.ValidationError`` (``validator``, ``validator_value``, ``instance``,
``schema``, ``absolute_path``, ``message``, ``context``). A schema holding any other
keyword is handed to ``jsonschema`` (see :func:`iter_errors`), and the tests compare both on
fuzzed documents.

Examples
--------
>>> schema = {"type": "object", "required": ["n"], "properties": {"n": {"type": "integer", "minimum": 1}}}
>>> [(list(e.absolute_path), e.validator) for e in iter_errors(schema, {"n": 0})]
[(['n'], 'minimum')]
"""

from __future__ import annotations

import re
from collections import deque
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

__all__ = ["KEYWORDS", "SchemaError", "iter_errors"]

#: Keywords this module evaluates; annotations (title, description, ...) are ignored.
KEYWORDS = frozenset(
    {
        "type", "properties", "required", "additionalProperties", "items", "minItems", "maxItems",
        "uniqueItems", "minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum", "minLength",
        "maxLength", "pattern", "enum", "const", "not", "oneOf", "anyOf",
    }
)  # fmt: skip
_ANNOTATIONS = frozenset({"$schema", "$id", "title", "description", "default", "examples", "$comment", "format"})


@dataclass
class SchemaError:
    """One violation, shaped like ``jsonschema.ValidationError``."""

    validator: str
    validator_value: Any
    instance: Any
    schema: dict[str, Any]
    absolute_path: deque[str | int]
    message: str
    context: list[SchemaError] = field(default_factory=list)


def _supported(schema: Any) -> bool:
    if isinstance(schema, bool):
        return True
    if not isinstance(schema, dict):
        return False
    for key, value in schema.items():
        if key in _ANNOTATIONS:
            continue
        if key not in KEYWORDS:
            return False
        if key == "properties" and not all(_supported(child) for child in value.values()):
            return False
        if key in ("items", "additionalProperties", "not") and not _supported(value):
            return False
        if key in ("oneOf", "anyOf") and not all(_supported(child) for child in value):
            return False
    return True


_SUPPORTED: dict[int, tuple[Any, bool]] = {}


def _supported_once(schema: Any) -> bool:
    """:func:`_supported`, remembered per schema object (the schema is kept alive with it)."""
    known = _SUPPORTED.get(id(schema))
    if known is None or known[0] is not schema:
        known = (schema, _supported(schema))
        _SUPPORTED[id(schema)] = known
    return known[1]


def _is_type(instance: Any, kind: str) -> bool:
    if kind == "object":
        return isinstance(instance, dict)
    if kind == "array":
        return isinstance(instance, list)
    if kind == "string":
        return isinstance(instance, str)
    if kind == "boolean":
        return isinstance(instance, bool)
    if kind == "null":
        return instance is None
    if isinstance(instance, bool):
        return False
    if kind == "number":
        return isinstance(instance, int | float)
    if kind == "integer":
        return isinstance(instance, int) or (isinstance(instance, float) and instance.is_integer())
    return False


def _equal(one: Any, other: Any) -> bool:
    """JSON equality: ``True`` is not ``1``, ``1`` is ``1.0``, containers compared deeply."""
    if isinstance(one, bool) or isinstance(other, bool):
        return isinstance(one, bool) and isinstance(other, bool) and one == other
    if isinstance(one, list) and isinstance(other, list):
        return len(one) == len(other) and all(_equal(a, b) for a, b in zip(one, other, strict=True))
    if isinstance(one, dict) and isinstance(other, dict):
        return one.keys() == other.keys() and all(_equal(one[key], other[key]) for key in one)
    if isinstance(one, int | float) and isinstance(other, int | float):
        return one == other
    return type(one) is type(other) and bool(one == other)


Path = tuple[str | int, ...]


def _error(keyword: str, schema: dict[str, Any], instance: Any, path: Path, message: str) -> SchemaError:
    return SchemaError(keyword, schema[keyword], instance, schema, deque(path), message)


def _errors(schema: Any, instance: Any, path: tuple[str | int, ...]) -> Iterator[SchemaError]:
    if schema is True:
        return
    if schema is False:
        yield SchemaError("false", False, instance, {}, deque(path), "False schema does not allow the value")
        return
    for keyword, value in schema.items():
        if keyword == "type":
            kinds = [value] if isinstance(value, str) else value
            if not any(_is_type(instance, kind) for kind in kinds):
                yield _error(keyword, schema, instance, path, f"{instance!r} is not of type {value!r}")
        elif keyword == "properties" and isinstance(instance, dict):
            for name, child in value.items():
                if name in instance:
                    yield from _errors(child, instance[name], (*path, name))
        elif keyword == "required" and isinstance(instance, dict):
            for name in value:
                if name not in instance:
                    yield _error(keyword, schema, instance, path, f"{name!r} is a required property")
        elif keyword == "additionalProperties" and isinstance(instance, dict):
            extra = [name for name in instance if name not in schema.get("properties", {})]
            if value is False:
                if extra:
                    yield _error(keyword, schema, instance, path, "Additional properties are not allowed")
            else:
                for name in extra:
                    yield from _errors(value, instance[name], (*path, name))
        elif keyword == "items" and isinstance(instance, list):
            for index, item in enumerate(instance):
                yield from _errors(value, item, (*path, index))
        elif keyword == "minItems" and isinstance(instance, list) and len(instance) < value:
            yield _error(keyword, schema, instance, path, f"{instance!r} is too short")
        elif keyword == "maxItems" and isinstance(instance, list) and len(instance) > value:
            yield _error(keyword, schema, instance, path, f"{instance!r} is too long")
        elif keyword == "uniqueItems" and value and isinstance(instance, list):
            if any(_equal(a, b) for i, a in enumerate(instance) for b in instance[i + 1 :]):
                yield _error(keyword, schema, instance, path, f"{instance!r} has non-unique elements")
        elif keyword in ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum"):
            if _is_type(instance, "number"):
                broken = {
                    "minimum": instance < value,
                    "maximum": instance > value,
                    "exclusiveMinimum": instance <= value,
                    "exclusiveMaximum": instance >= value,
                }[keyword]
                if broken:
                    yield _error(keyword, schema, instance, path, f"{instance!r} is out of range ({keyword} {value})")
        elif keyword == "minLength" and isinstance(instance, str) and len(instance) < value:
            yield _error(keyword, schema, instance, path, f"{instance!r} is too short")
        elif keyword == "maxLength" and isinstance(instance, str) and len(instance) > value:
            yield _error(keyword, schema, instance, path, f"{instance!r} is too long")
        elif keyword == "pattern" and isinstance(instance, str) and not re.search(value, instance):
            yield _error(keyword, schema, instance, path, f"{instance!r} does not match {value!r}")
        elif keyword == "enum" and not any(_equal(instance, option) for option in value):
            yield _error(keyword, schema, instance, path, f"{instance!r} is not one of {value!r}")
        elif keyword == "const" and not _equal(instance, value):
            yield _error(keyword, schema, instance, path, f"{value!r} was expected")
        elif keyword == "not" and not any(True for _ in _errors(value, instance, path)):
            yield _error(keyword, schema, instance, path, f"{instance!r} should not be valid under {value!r}")
        elif keyword in ("oneOf", "anyOf"):
            context: list[SchemaError] = []
            matches = 0
            for child in value:
                found = list(_errors(child, instance, path))
                context.extend(found)
                matches += not found
            if (keyword == "oneOf" and matches != 1) or (keyword == "anyOf" and matches == 0):
                error = _error(keyword, schema, instance, path, f"{instance!r} is not valid under {keyword}")
                error.context = context if matches == 0 else []
                yield error


def iter_errors(schema: dict[str, Any], instance: Any) -> Iterator[Any]:
    """Every violation of ``schema`` by ``instance`` (this module's or ``jsonschema``'s errors).

    Parameters
    ----------
    schema : dict
        A JSON Schema (draft 2020-12).
    instance : Any
        The parsed JSON value.

    Returns
    -------
    iterator
        Errors with ``validator``, ``validator_value``, ``instance``, ``schema``,
        ``absolute_path``, ``message`` and ``context``.

    Examples
    --------
    >>> [e.message for e in iter_errors({"type": "array", "maxItems": 1}, [1, 2])]
    ['[1, 2] is too long']
    """
    if _supported_once(schema):
        return _errors(schema, instance, ())
    from jsonschema import Draft202012Validator

    return iter(Draft202012Validator(schema).iter_errors(instance))
