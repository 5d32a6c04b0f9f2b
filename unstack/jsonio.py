"""Reading, validating and atomically writing unstack's versioned JSON documents.

Every document carries a ``format`` tag such as ``"unstack.supports/1"`` and is checked
against the JSON Schema shipped for that tag (``unstack/schemas/``). Problems become
:class:`~unstack.errors.InvalidFile` errors that name the file, the JSON path and what
was expected.

Examples
--------
>>> from unstack.jsonio import format_json_path
>>> format_json_path(["probabilities", 2, 1])
'$.probabilities[2][1]'
"""

from __future__ import annotations

import errno
import json
import math
import os
import stat
import sys
from collections.abc import Callable, Iterable, Iterator
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

from unstack.errors import InvalidFile, UnknownFormat

__all__ = [
    "FORMATS",
    "MAX_DEPTH",
    "MAX_DOCUMENT_BYTES",
    "Document",
    "document_text",
    "finite_json",
    "format_json_path",
    "json_kind",
    "load_schema",
    "parse_json",
    "read_document",
    "refuse_special_file",
    "report_text",
    "special_file",
    "too_deep",
    "validate_document",
]

#: Format tag -> schema file shipped in ``unstack/schemas``.
FORMATS: dict[str, str] = {
    "unstack.supports/1": "supports-1.schema.json",
    "unstack.scene/1": "scene-1.schema.json",
    "unstack.decision/1": "decision-1.schema.json",
    "unstack.dataset/1": "dataset-1.schema.json",
    "unstack.plan/1": "plan-1.schema.json",
    "unstack.payoff/1": "payoff-1.schema.json",
}

STDIN_NAME = "<stdin>"
#: Deepest nesting of arrays and objects a document may have (unstack's formats need 5).
MAX_DEPTH = 64
#: Largest JSON document read, in bytes (64 MiB: a scene with about two million inline points);
#: a larger file is refused before it is read.
MAX_DOCUMENT_BYTES = 64 * 2**20
#: Above this many characters a schema violation is reported in fastjsonschema's words (its
#: compiled validator finds it in a second; the hand-written messages' checker walks every value).
LARGE_DOCUMENT = 2**20


class Document:
    """A parsed JSON document with where it came from.

    Attributes
    ----------
    data : dict
        The parsed JSON object.
    source : str
        The file name as the user gave it, or ``<stdin>``.
    base_dir : pathlib.Path
        The folder that relative references (``points_file``) are resolved against.
    size : int
        Characters of the JSON text it was parsed from (0 when built in memory).
    """

    def __init__(self, data: dict[str, Any], source: str, base_dir: Path, size: int = 0) -> None:
        self.data = data
        self.source = source
        self.base_dir = base_dir
        self.size = size  # characters of the JSON text (0: built in memory)


def format_json_path(parts: Iterable[str | int]) -> str:
    """Render a sequence of keys and indices as a JSONPath such as ``$.boxes[0].size``."""
    text = "$"
    for part in parts:
        text += f"[{part}]" if isinstance(part, int) else f".{part}"
    return text


def _short(value: Any, limit: int = 40) -> str:
    """A short, one-line rendering of a JSON value for error messages."""
    text = json.dumps(value, allow_nan=True) if not isinstance(value, str) else repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _walk(value: Any) -> Iterator[tuple[list[str | int], Any]]:
    """Every value nested in ``value`` with its JSON path, depth first in the document's order.

    Iterative, with one iterator per open container and one shared path (the caller copies a
    path it keeps): work in proportion to the values, memory to the depth, so a wide document
    deep down costs no copy of its path per value.
    """
    keys: list[str | int] = []
    open_containers: list[Iterator[tuple[Any, Any]]] = [_children(value)] if isinstance(value, dict | list) else []
    while open_containers:
        step = next(open_containers[-1], None)
        if step is None:  # this container is done: back to its parent
            open_containers.pop()
            if keys:
                keys.pop()
            continue
        key, child = step
        keys.append(key)
        yield keys, child
        if isinstance(child, dict | list):
            open_containers.append(_children(child))
        else:
            keys.pop()


def _children(container: dict[str, Any] | list[Any]) -> Iterator[tuple[Any, Any]]:
    return iter(container.items()) if isinstance(container, dict) else enumerate(container)


def _find_non_finite(value: Any, path: list[str | int]) -> Iterator[list[str | int]]:
    """JSON paths of non-finite numbers, in the document's order."""
    if isinstance(value, float) and not math.isfinite(value):
        yield path
    for keys, item in _walk(value):
        if isinstance(item, float) and not math.isfinite(item):
            yield [*path, *keys]


def too_deep(value: Any, limit: int) -> list[str | int] | None:
    """The keys to the first value nested deeper than ``limit`` levels, or None.

    Examples
    --------
    >>> too_deep({"a": [[1]]}, 2)
    ['a', 0, 0]
    >>> too_deep({"a": [1]}, 2) is None
    True
    """
    for keys, _ in _walk(value):
        if len(keys) > limit:
            return list(keys)
    return None


def _get(data: Any, path: list[str | int]) -> Any:
    for part in path:
        data = data[part]
    return data


class _DuplicateKey(Exception):
    def __init__(self, key: str) -> None:
        super().__init__(key)
        self.key = key


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """A JSON object's dict; a key given twice is refused rather than the last one kept silently."""
    data: dict[str, Any] = {}
    for key, value in pairs:
        if key in data:
            raise _DuplicateKey(key)
        data[key] = value
    return data


#: The UTF-8 byte order mark, decoded.
BYTE_ORDER_MARK = "\ufeff"


def parse_json(text: str, source: str) -> Any:
    """The JSON value in ``text``, read strictly: a key given twice in one object, invalid JSON
    (NaN, Infinity, an empty text), nesting too deep for Python or an integer of more digits than
    Python converts are one-line :class:`InvalidFile` errors naming ``source``.

    Examples
    --------
    >>> parse_json('[{"id": "a"}]', "d.json")
    [{'id': 'a'}]
    >>> parse_json('{"id": "a", "id": "b"}', "d.json")
    Traceback (most recent call last):
    ...
    unstack.errors.InvalidFile: d.json: $: the key 'id' appears twice in one JSON object

    A byte order mark before the document (Windows editors write one) is passed over, as RFC
    8259 allows:

    >>> parse_json('\\ufeff{"id": "a"}', "d.json")
    {'id': 'a'}
    """
    text = text.removeprefix(BYTE_ORDER_MARK)
    if not text.strip():
        raise InvalidFile(source, "$", "expected a JSON document, got an empty text")
    try:
        return json.loads(text, object_pairs_hook=_unique_keys)
    except _DuplicateKey as error:
        raise InvalidFile(source, "$", f"the key {error.key!r} appears twice in one JSON object") from None
    except json.JSONDecodeError as error:
        raise InvalidFile(
            source, "$", f"invalid JSON at line {error.lineno} column {error.colno}: {error.msg}"
        ) from None
    except RecursionError:
        raise InvalidFile(source, "$", f"expected JSON nested at most {MAX_DEPTH} levels deep") from None
    except ValueError:  # an integer of more digits than Python converts
        raise InvalidFile(
            source,
            "$",
            f"invalid JSON: an integer of more than {sys.get_int_max_str_digits():,} digits, "
            "no number an unstack file holds",
        ) from None


def json_kind(value: Any) -> str:
    """What a JSON value is, in JSON's words (``null``, a list, ...), for a message.

    Examples
    --------
    >>> json_kind(None), json_kind([1]), json_kind(True)
    ('null', 'a list', 'true')
    """
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    kinds = {list: "a list", str: "a string", int: "a number", float: "a number"}
    return kinds.get(type(value), type(value).__name__)


def _mib(size: int) -> str:
    """A byte count in MiB for a message."""
    return f"{size / 2**20:,.1f} MiB"


def finite_json(value: Any) -> Any:
    """``value`` with every NaN or infinity replaced by ``None``, so that it is written as strict
    JSON (``null``), which every reader takes -- unstack's own refuses ``NaN``.

    Examples
    --------
    >>> finite_json({"mean": float("nan"), "bins": [0.5, float("inf")], "n": 3})
    {'mean': None, 'bins': [0.5, None], 'n': 3}
    """
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {key: finite_json(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [finite_json(item) for item in value]
    return value


def report_text(value: Any) -> str:
    """A report (an experiment's results, a fit report, an evaluation) as indented strict JSON:
    undefined values (NaN, infinity) are ``null`` (:func:`finite_json`), the text ends in a newline.

    Examples
    --------
    >>> report_text({"spearman": float("nan")})
    '{\\n  "spearman": null\\n}\\n'
    """
    return json.dumps(finite_json(value), indent=2, allow_nan=False) + "\n"


def document_text(document: dict[str, Any], target: str = "the document", advice: str = "") -> str:
    """The JSON text of ``document`` as unstack writes it: indented, or on one line when the
    indented text would be larger than unstack reads back (:data:`MAX_DOCUMENT_BYTES`).

    Parameters
    ----------
    document : dict
        A JSON-serialisable document.
    target : str
        Where the text goes, for the message.
    advice : str
        What to do instead, ending the message when the text is too large.

    Returns
    -------
    str
        The text, ending in a newline.

    Raises
    ------
    InvalidArgument
        Even on one line the text is larger than :data:`MAX_DOCUMENT_BYTES`: a file nobody could
        read back is not written.

    Examples
    --------
    >>> document_text({"format": "unstack.supports/1", "objects": ["a"]})
    '{\\n  "format": "unstack.supports/1",\\n  "objects": [\\n    "a"\\n  ]\\n}\\n'
    """
    try:  # strict JSON: unstack's reader refuses NaN and Infinity, so they are never written
        text = json.dumps(document, indent=2, allow_nan=False) + "\n"
    except (TypeError, ValueError) as error:
        from unstack.errors import InvalidArgument

        raise InvalidArgument(
            f"{target}: the document holds a value JSON cannot ({error}); nothing was written"
        ) from None
    if len(text) <= MAX_DOCUMENT_BYTES:  # characters: the JSON is ASCII
        return text
    text = json.dumps(document, separators=(",", ":"), allow_nan=False) + "\n"
    if len(text) <= MAX_DOCUMENT_BYTES:
        return text
    from unstack.errors import InvalidArgument

    raise InvalidArgument(
        f"{target}: the JSON would be {_mib(len(text))} even without indentation, more than the "
        f"{_mib(MAX_DOCUMENT_BYTES)} unstack reads back; nothing was written{'; ' + advice if advice else ''}"
    )


def read_document(path: str | os.PathLike[str]) -> Document:
    """Read a JSON document from a file (``"-"`` reads standard input).

    Parameters
    ----------
    path : str or path-like
        The file to read, or ``"-"`` for standard input.

    Returns
    -------
    Document
        The parsed object with its source name and base folder.

    Raises
    ------
    InvalidFile
        The file is missing, a directory, unreadable, not JSON, not a JSON object, or
        holds a non-finite number (``NaN``, ``Infinity``).
    """
    if not isinstance(path, str | os.PathLike):
        from unstack.errors import InvalidArgument

        raise InvalidArgument(f"expected a file name (a str or path-like), got {type(path).__name__}")
    source = str(path)
    if source == "-":
        source, base_dir = STDIN_NAME, Path.cwd()
        if sys.stdin is None or sys.stdin.closed:
            raise InvalidFile(source, "$", "standard input is closed; give a file name or pipe a document in")
        try:
            raw = getattr(sys.stdin, "buffer", None)  # bytes, decoded as UTF-8 like a file
            read = raw.read(MAX_DOCUMENT_BYTES + 1) if raw is not None else sys.stdin.read(MAX_DOCUMENT_BYTES + 1)
            if len(read) > MAX_DOCUMENT_BYTES:
                raise InvalidFile(source, "$", f"expected a document of at most {_mib(MAX_DOCUMENT_BYTES)}; got more")
            text = read.decode("utf-8") if isinstance(read, bytes) else read
        except (OSError, ValueError, UnicodeDecodeError) as error:
            raise InvalidFile(source, "$", f"cannot read standard input: {error}") from None
    else:
        file = Path(path)
        if source == "":
            raise InvalidFile("''", "$", "expected a file name, got an empty one")
        if "\0" in source:
            raise InvalidFile(source.replace("\0", "\\0"), "$", "expected a file name, got one with a NUL character")
        try:
            refuse_special_file(file)
            is_dir = file.is_dir()
        except OSError as error:  # a name longer than the system allows, say
            raise InvalidFile(source, "$", f"cannot read the file: {error.strerror}") from None
        if is_dir:
            raise InvalidFile(source, "$", "expected a JSON file, got a directory")
        try:
            size = file.stat().st_size
            if size > MAX_DOCUMENT_BYTES:
                raise InvalidFile(
                    source, "$", f"expected a document of at most {_mib(MAX_DOCUMENT_BYTES)}, the file has {_mib(size)}"
                )
            text = file.read_text(encoding="utf-8")
        except FileNotFoundError:
            raise InvalidFile(source, "$", "no such file") from None
        except UnicodeDecodeError:
            raise InvalidFile(
                source, "$", "expected a JSON document (UTF-8 text), got a binary file (a model .skops, an array .npy?)"
            ) from None
        except OSError as error:
            raise InvalidFile(source, "$", f"cannot read the file: {error}") from None
        base_dir = file.resolve().parent
    data = parse_json(text, source)
    if not isinstance(data, dict):
        raise InvalidFile(source, "$", f"expected a JSON object, got {json_kind(data)}: not an unstack document")
    deep = too_deep(data, MAX_DEPTH)
    if deep is not None:
        where = format_json_path(deep[:8]) + "..."
        raise InvalidFile(source, where, f"expected JSON nested at most {MAX_DEPTH} levels deep")
    for bad in _find_non_finite(data, []):
        raise InvalidFile(source, format_json_path(bad), f"expected a finite number, got {_get(data, bad)}")
    return Document(data, source, base_dir, len(text))


def special_file(path: str | os.PathLike[str]) -> str | None:
    """What ``path`` names when it is there but no regular file or folder (reading it would block
    or never end), in words; ``None`` for a file, a folder or nothing.

    Examples
    --------
    >>> special_file("/dev/zero"), special_file("examples"), special_file("no-such-file")
    ('a device', None, None)
    """
    try:
        mode = os.stat(path).st_mode
    except OSError as error:
        return "a symlink loop" if error.errno == errno.ELOOP else None
    if stat.S_ISREG(mode) or stat.S_ISDIR(mode):
        return None
    if stat.S_ISFIFO(mode):
        return "a pipe (FIFO)"
    return "a socket" if stat.S_ISSOCK(mode) else "a device"


def refuse_special_file(path: str | os.PathLike[str], error: type[InvalidFile] = InvalidFile, **where: str) -> None:
    """Raise ``error`` when ``path`` is a pipe, a device, a socket or a symlink loop.

    ``where`` gives the error's ``source`` and ``json_path`` (default: the path and ``$``).
    """
    kind = special_file(path)
    if kind is not None:
        source = where.get("source", str(path))
        named = "" if source == str(path) else f": {path}"
        raise error(source, where.get("json_path", "$"), f"expected a regular file, got {kind}{named}")


@cache
def load_schema(format_tag: str) -> dict[str, Any]:
    """Return the JSON Schema shipped for a format tag such as ``unstack.scene/1``."""
    text = resources.files("unstack.schemas").joinpath(FORMATS[format_tag]).read_text("utf-8")
    schema: dict[str, Any] = json.loads(text)
    return schema


#: What the schemas' string patterns ask for, in words.
_PATTERNS = {r"\.(npy|ply)$": "a .npy or .ply file name"}


def _describe(error: Any) -> str:
    """Turn a jsonschema ValidationError into 'expected ..., got ...'."""
    validator, expected, instance = error.validator, error.validator_value, error.instance
    if validator == "type":
        kinds = expected if isinstance(expected, str) else " or ".join(expected)
        return f"expected {kinds}, got {_short(instance)}"
    if validator == "required":
        missing = [key for key in expected if key not in instance]
        return f"missing required key {missing[0]!r}"
    if validator == "additionalProperties":
        allowed = set(error.schema.get("properties", {}))
        extra = sorted(key for key in instance if key not in allowed)
        return f"unexpected key {extra[0]!r} (allowed: {', '.join(sorted(allowed))})"
    if validator in {"minimum", "exclusiveMinimum", "maximum", "exclusiveMaximum"}:
        words = {
            "minimum": ">=",
            "exclusiveMinimum": ">",
            "maximum": "<=",
            "exclusiveMaximum": "<",
        }
        return f"expected a number {words[validator]} {expected}, got {_short(instance)}"
    if validator in {"minItems", "maxItems"}:
        word = "at least" if validator == "minItems" else "at most"
        return f"expected {word} {expected} items, got {len(instance)}"
    if validator == "uniqueItems":
        seen: set[str] = set()
        for item in instance:
            key = json.dumps(item, sort_keys=True)
            if key in seen:
                return f"expected unique items, {_short(item)} appears twice"
            seen.add(key)
    if validator == "const":
        return f"expected {_short(expected)}, got {_short(instance)}"
    if validator == "enum":
        return f"expected one of {', '.join(_short(e) for e in expected)}, got {_short(instance)}"
    if validator == "pattern":
        wanted = _PATTERNS.get(expected, f"a string matching {expected!r}")
        return f"expected {wanted}, got {_short(instance)}"
    if validator == "oneOf" and isinstance(instance, dict):
        options = [sorted(option.get("required", [])) for option in expected]
        return "expected exactly one of " + " or ".join("/".join(option) for option in options if option)
    return str(error.message if len(error.message) < 120 else error.message[:117] + "...")


@cache
def _compiled_schema(format_tag: str) -> Callable[[Any], Any]:
    """The format's schema compiled to Python by fastjsonschema (once per process)."""
    import fastjsonschema

    compiled: Callable[[Any], Any] = fastjsonschema.compile(load_schema(format_tag))
    return compiled


def _data_path(data: Any, parts: Iterable[str]) -> list[str | int]:
    """fastjsonschema's path (strings) as JSON path parts: indices into lists become integers."""
    path: list[str | int] = []
    for part in parts:
        if isinstance(data, list):
            path.append(int(part))
            data = data[int(part)]
        else:
            path.append(part)
            data = data.get(part) if isinstance(data, dict) else None
    return path


def validate_document(
    document: Document, expected: Iterable[str] | None = None, error_class: type[InvalidFile] = InvalidFile
) -> str:
    """Check a document's ``format`` tag and validate it against that format's schema.

    Parameters
    ----------
    document : Document
        The parsed document.
    expected : iterable of str, optional
        The format tags acceptable here (default: every format this release reads).
    error_class : type, optional
        The :class:`InvalidFile` subclass to raise for schema violations.

    Returns
    -------
    str
        The document's format tag.

    Raises
    ------
    UnknownFormat
        The tag is missing, unknown, or names a version this release cannot read.
    InvalidFile
        The document violates its schema (the first problem, by JSON path).
    """
    accepted = list(expected) if expected is not None else list(FORMATS)
    tag = document.data.get("format")
    if tag is None:
        raise UnknownFormat(
            document.source,
            "$",
            f"missing required key 'format' (expected {', '.join(accepted)}): not an unstack document (a fit "
            "report, an experiment's results or a checkpoint carries no format tag and is not checked)",
        )
    if not isinstance(tag, str):
        raise UnknownFormat(
            document.source, "$.format", f"expected a format tag string ({' or '.join(accepted)}), got {_short(tag)}"
        )
    if tag not in accepted:
        family = str(tag).rsplit("/", 1)[0]
        same_family = [known for known in accepted if known.rsplit("/", 1)[0] == family]
        if same_family:
            why = "unsupported version"
        elif tag in FORMATS:
            why = "this command does not take"
        else:
            why = "unknown format"
        raise UnknownFormat(
            document.source,
            "$.format",
            f"{why} {_short(tag)}; expected {' or '.join(accepted)}",
        )
    import fastjsonschema

    try:
        _compiled_schema(tag)(document.data)
        return str(tag)  # valid: the compiled validator is 50x faster than the checker below
    except fastjsonschema.JsonSchemaValueException as error:
        if document.size > LARGE_DOCUMENT:
            where = format_json_path(_data_path(document.data, error.path[1:]))
            raise error_class(document.source, where, error.message.split(" ", 1)[-1]) from None
    from jsonschema import Draft202012Validator  # only for an invalid document: it words the message

    errors = sorted(
        Draft202012Validator(load_schema(tag)).iter_errors(document.data), key=lambda e: list(e.absolute_path)
    )
    if errors:
        first = errors[0]
        if first.validator in {"oneOf", "anyOf"} and first.context:
            deepest = max(first.context, key=lambda e: len(e.absolute_path))
            if len(deepest.absolute_path) > len(first.absolute_path):
                first = deepest
        raise error_class(document.source, format_json_path(first.absolute_path), _describe(first))
    return str(tag)
