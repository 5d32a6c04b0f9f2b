"""Input validators in the style of pytransform3d's ``check_*``.

Each validator takes what a user handed in (nested lists from JSON, or arrays), checks it
and returns a canonical, C-contiguous float64 array (or a tuple of ids). A problem raises
an :class:`~unstack.errors.InvalidFile` subclass naming the source, the JSON path and the
shape or value it got, so the same checks serve files and in-process callers.

Examples
--------
>>> check_probability_matrix([[0, 0.7], [0.1, 0]], n_objects=2)
array([[0. , 0.7],
       [0.1, 0. ]])
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from unstack.errors import InvalidFile, InvalidScene, InvalidSupports

if TYPE_CHECKING:
    from unstack.jsonio import Document

__all__ = [
    "HEIGHT_RANGE",
    "LIGHT_BOX",
    "MAX_BOX_EDGE",
    "MAX_COORDINATE",
    "MAX_HIDDEN_LOAD",
    "MAX_ID_LENGTH",
    "MAX_MASS",
    "MIN_BOX_EDGE",
    "QUATERNION_NORM_TOLERANCE",
    "REFUSED_HIDDEN_LOAD",
    "REFUSED_OVERLAP",
    "check_decision_document",
    "check_ids",
    "check_metadata",
    "check_payoff_document",
    "check_plan_document",
    "check_points",
    "check_probability_matrix",
    "check_quaternion_xyzw",
    "check_vector",
    "counted",
    "finite_number",
    "heavy_loads",
    "light_boxes",
    "number_text",
]

#: The longest box id accepted (characters): an id is a label in tables and pictures.
MAX_ID_LENGTH = 200


def long_id(item: str) -> str:
    """The message for an id longer than :data:`MAX_ID_LENGTH`."""
    return f"expected an id of at most {MAX_ID_LENGTH} characters, got one of {len(item):,} ({item[:20]!r}...)"


#: An integer of more bits than this is beyond the largest float (about 1.8e308).
FLOAT_BITS = 1024
#: A quaternion whose norm is within this of 1 is normalised; further away it is an error.
QUATERNION_NORM_TOLERANCE = 1e-3


#: Shortest box edge accepted (metres): smaller is not a carton, or the unit is not metres.
MIN_BOX_EDGE = 0.02
#: Longest box edge accepted (metres): longer is not a carton, or the unit is millimetres.
MAX_BOX_EDGE = 5.0
#: Farthest coordinate accepted, boxes and cloud (metres from the origin along any axis).
MAX_COORDINATE = 100.0
#: Two boxes sharing more than this share of the smaller one's volume are refused.
REFUSED_OVERLAP = 0.5
#: A box lighter than this (kg) is warned about: no carton weighs less, so the masses are
#: likely in another unit.
LIGHT_BOX = 0.01
#: More undetected boxes than this on one box are warned about with the load cost: a stack on
#: one carton in a container 2.4 m high holds some 25 of the smallest cartons.
MAX_HIDDEN_LOAD = 50.0
#: A box heavier than this (kg) is refused, as the schemas refuse it: a unit error.
MAX_MASS = 10_000.0
#: Most undetected boxes one box may carry in a supports document (``hidden_load``; the schema's
#: maximum): beyond it the number is no load (:data:`MAX_HIDDEN_LOAD` is warned about).
REFUSED_HIDDEN_LOAD = 1_000.0
#: The heights a box may rest at in a supports document, metres (``heights``; the schema's bounds).
HEIGHT_RANGE = (-1.0, 100.0)


def number_text(value: Any) -> str:
    """``value`` for a message: an integer too long to print (or to make a float of) by its size.

    Examples
    --------
    >>> number_text(10**400), number_text(0.5)
    ('an integer of about 401 digits', '0.5')
    """
    if isinstance(value, int | np.integer) and not isinstance(value, bool) and int(value).bit_length() > 64:
        return f"an integer of about {int(int(value).bit_length() * math.log10(2)) + 1} digits"
    return repr(value)


def counted(number: int, noun: str, plural: str | None = None) -> str:
    """``number`` and ``noun`` for a message, plural unless it is one (``plural``: the plural
    when it is not ``noun`` + "s").

    Examples
    --------
    >>> counted(1, "configuration"), counted(3, "configuration"), counted(1, "box", "boxes")
    ('1 configuration', '3 configurations', '1 box')
    >>> counted(2_000, "box", "boxes")
    '2,000 boxes'
    """
    return f"{number:,} {noun if number == 1 else plural or noun + 's'}"


def finite_number(value: Any) -> float | None:
    """``value`` as a finite float, or ``None`` when it is not one (a bool, a string, NaN, an
    integer too large for a float).

    Examples
    --------
    >>> finite_number(3), finite_number(float("nan")), finite_number(10**400), finite_number("1")
    (3.0, None, None, None)
    """
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        return None
    try:
        number = float(value)
    except OverflowError:
        return None
    return number if math.isfinite(number) else None


def float_array(
    value: Any, *, source: str = "<array>", path: str = "$", error: type[InvalidFile] = InvalidScene
) -> np.ndarray:
    """``numpy.asarray(value, dtype=float64)``, an integer too large for a float refused by its path.

    Raises
    ------
    InvalidFile
        ``error`` at the first such integer (a JSON number of 309 digits or more parses as one).
    TypeError, ValueError
        As :func:`numpy.asarray` for what is not numbers (the caller says what it expected).

    Examples
    --------
    >>> float_array([[1, 2.5]]).tolist()
    [[1.0, 2.5]]
    >>> float_array([[0, 10**400]], path="$.points")
    Traceback (most recent call last):
    ...
    unstack.errors.InvalidScene: <array>: $.points[0][1]: expected a finite number, got an integer of about 401 digits
    """
    _refuse_masked(value, source, path, error)
    try:
        return np.asarray(value, dtype=np.float64)
    except OverflowError:
        where, number = _first_huge_integer(value, path)
        raise error(source, where, f"expected a finite number, got {number_text(number)}") from None


def _refuse_masked(value: Any, source: str, path: str, error: type[InvalidFile]) -> None:
    """Refuse a masked array: numpy reads the values under its mask, which nobody meant to give."""
    if np.ma.isMaskedArray(value):
        raise error(source, path, "expected a plain array, got a masked array: fill its masked cells first")


def _first_huge_integer(value: Any, path: str) -> tuple[str, Any]:
    """The path and value of the first integer in nested lists that no float holds."""
    if isinstance(value, int | np.integer) and not isinstance(value, bool):
        if finite_number(value) is None:
            return path, value
    elif isinstance(value, Sequence) and not isinstance(value, str):
        for index, item in enumerate(value):
            found = _first_huge_integer(item, f"{path}[{index}]")
            if found[0]:
                return found
    return "", None


def light_boxes(ids: Sequence[str], masses: Any) -> str | None:
    """A warning naming the boxes lighter than :data:`LIGHT_BOX` (``None`` when there are none);
    the caller puts the source before it.

    Examples
    --------
    >>> light_boxes(["a", "b", "c"], [12.0, 1e-9, 3e-9])
    "boxes 'b' (1e-09 kg), 'c' (3e-09 kg) weigh less than 0.01 kg, lighter than a carton; masses in kg?"
    """
    light = [(box_id, float(mass)) for box_id, mass in zip(ids, masses, strict=True) if float(mass) < LIGHT_BOX]
    if not light:
        return None
    named = ", ".join(f"{box_id!r} ({mass:.3g} kg)" for box_id, mass in light[:5])
    more = f" and {len(light) - 5} more" if len(light) > 5 else ""
    boxes, weigh = ("boxes", "weigh") if len(light) > 1 else ("box", "weighs")
    return f"{boxes} {named}{more} {weigh} less than {LIGHT_BOX:g} kg, lighter than a carton; masses in kg?"


def heavy_loads(ids: Sequence[str], hidden_load: Any) -> str | None:
    """A warning naming the boxes with more undetected boxes on them than
    :data:`MAX_HIDDEN_LOAD` (``None`` when there are none); the caller puts the source before it.

    Examples
    --------
    >>> heavy_loads(["a", "b"], [1.5, 1000.0])
    "box 'b' carries 1,000 undetected boxes, more than a stack on one carton holds (50); a count of boxes, not kg?"
    """
    heavy = [
        (box_id, float(load)) for box_id, load in zip(ids, hidden_load, strict=True) if float(load) > MAX_HIDDEN_LOAD
    ]
    if not heavy:
        return None
    named = ", ".join(f"{box_id!r} carries {load:,.4g}" for box_id, load in heavy[:5])
    more = f" and {len(heavy) - 5} more" if len(heavy) > 5 else ""
    boxes = "boxes" if len(heavy) > 1 else "box"
    return (
        f"{boxes} {named}{more} undetected boxes, more than a stack on one carton holds ({MAX_HIDDEN_LOAD:g}); "
        "a count of boxes, not kg?"
    )


def _matrix(value: Any, n_objects: int, source: str, path: str, error: type[InvalidFile]) -> np.ndarray:
    """Turn nested lists or an array into an ``n x n`` float64 array, naming bad cells."""
    if isinstance(value, np.ndarray):
        if value.ndim != 2 or value.shape != (n_objects, n_objects):
            raise error(source, path, f"expected a {n_objects} x {n_objects} matrix, got shape {value.shape}")
        _refuse_masked(value, source, path, error)
        if not np.issubdtype(value.dtype, np.number) or np.iscomplexobj(value):  # booleans, as true/false cells
            raise error(source, path, f"expected real numbers, got dtype {value.dtype}")
        return np.ascontiguousarray(value, dtype=np.float64)
    if not isinstance(value, Sequence) or isinstance(value, str):
        raise error(source, path, f"expected a {n_objects} x {n_objects} matrix (a list of rows)")
    if len(value) != n_objects:
        raise error(source, path, f"expected {n_objects} rows (one per object), got {len(value)}")
    for i, row in enumerate(value):
        if not isinstance(row, Sequence) or isinstance(row, str):
            raise error(source, f"{path}[{i}]", f"expected a row of {n_objects} numbers")
        if len(row) != n_objects:
            raise error(source, f"{path}[{i}]", f"expected {n_objects} numbers (one per object), got {len(row)}")
        for j, cell in enumerate(row):
            if isinstance(cell, bool) or not isinstance(cell, int | float | np.number):
                raise error(source, f"{path}[{i}][{j}]", f"expected a number, got {cell!r}")
            if isinstance(cell, np.complexfloating):
                raise error(source, f"{path}[{i}][{j}]", f"expected a real number, got {cell!r}")
    return float_array(value, source=source, path=path, error=error).reshape(n_objects, n_objects)


def check_probability_matrix(
    value: Any,
    n_objects: int,
    *,
    source: str = "<array>",
    path: str = "$.probabilities",
    error: type[InvalidFile] = InvalidSupports,
) -> np.ndarray:
    """Check a support-probability matrix and return it as float64.

    Parameters
    ----------
    value : array-like
        ``n x n`` matrix with ``value[i][j] = P(SUPP(i, j))``.
    n_objects : int
        The number of objects the matrix must cover.
    source, path : str
        Where the value came from, for error messages.
    error : type
        The error class to raise.

    Returns
    -------
    numpy.ndarray
        The matrix, shape ``(n, n)``, float64, C-contiguous.

    Raises
    ------
    InvalidSupports
        Wrong shape, ragged rows, non-numeric, non-finite or out-of-range entries, or a
        non-zero diagonal; the message names the first bad cell.

    Examples
    --------
    >>> check_probability_matrix([[0, 2], [0, 0]], n_objects=2)
    Traceback (most recent call last):
    ...
    unstack.errors.InvalidSupports: <array>: $.probabilities[0][1]: expected a probability in [0, 1], got 2.0
    """
    matrix = _matrix(value, n_objects, source, path, error)
    bad = np.argwhere(~np.isfinite(matrix))
    if bad.size:
        i, j = bad[0]
        raise error(source, f"{path}[{i}][{j}]", f"expected a finite number, got {matrix[i, j]}")
    bad = np.argwhere((matrix < 0) | (matrix > 1))
    if bad.size:
        i, j = bad[0]
        raise error(source, f"{path}[{i}][{j}]", f"expected a probability in [0, 1], got {matrix[i, j]}")
    diagonal = np.flatnonzero(np.diag(matrix))
    if diagonal.size:
        i = diagonal[0]
        raise error(source, f"{path}[{i}][{i}]", f"expected 0 on the diagonal, got {matrix[i, i]}")
    return matrix


def check_ids(
    value: Any, *, source: str = "<array>", path: str = "$.objects", error: type[InvalidFile] = InvalidSupports
) -> tuple[str, ...]:
    """Check a list of object ids: non-empty, strings, unique. Returns them as a tuple.

    Examples
    --------
    >>> check_ids(["a", "b"])
    ('a', 'b')
    """
    if isinstance(value, str) or not isinstance(value, Sequence | np.ndarray):
        raise error(source, path, "expected a list of ids")
    if len(value) == 0:
        raise error(source, path, "expected at least one object, got an empty list")
    seen: dict[str, int] = {}
    for index, item in enumerate(value):
        if not isinstance(item, str) or not item:
            raise error(source, f"{path}[{index}]", f"expected a non-empty string id, got {item!r}")
        if len(item) > MAX_ID_LENGTH:
            raise error(source, f"{path}[{index}]", long_id(item))
        if item in seen:
            raise error(source, f"{path}[{index}]", f"duplicate id {item!r} (also at index {seen[item]})")
        seen[item] = index
    return tuple(value)


def check_metadata(value: Any, *, source: str = "<array>", error: type[InvalidFile] = InvalidScene) -> dict[str, Any]:
    """Check free-form metadata (an object with string keys, or None) and return a deep copy
    of it as its JSON document holds it: what the file would not keep is refused here, not
    when it is saved (numpy numbers become numbers, tuples lists, non-finite numbers an error).

    Examples
    --------
    >>> check_metadata(None)
    {}
    >>> check_metadata([1, 2])
    Traceback (most recent call last):
    ...
    unstack.errors.InvalidScene: <array>: $.metadata: expected an object (a dict with string keys), got list
    """
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise error(source, "$.metadata", f"expected an object (a dict with string keys), got {type(value).__name__}")
    for key in value:
        if not isinstance(key, str):
            raise error(source, "$.metadata", f"expected string keys, got the key {key!r} ({type(key).__name__})")
    try:  # the quick way; the walk below only to say where the first value JSON cannot hold is
        text = json.dumps(value, allow_nan=False, default=_numpy_to_json)
    except (TypeError, ValueError, RecursionError) as failure:
        reason = str(failure)
        try:
            _json_value(value, "$.metadata", source, error)  # raises where the dump failed
        except RecursionError:
            reason = "nested too deeply, or holding itself"
        raise error(source, "$.metadata", f"expected a JSON object: {reason}") from None
    copied: dict[str, Any] = json.loads(text)
    return copied


def _numpy_to_json(value: Any) -> Any:
    """numpy's numbers and arrays as the numbers and lists JSON holds; anything else refused."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"{type(value).__name__} is not JSON")


def _json_value(value: Any, path: str, source: str, error: type[InvalidFile]) -> Any:
    """A deep copy of ``value`` as the JSON document would hold it (numpy scalars and arrays as
    numbers and lists, tuples as lists); an error at ``path`` for anything JSON cannot hold."""
    if value is None or isinstance(value, bool | str):
        return value
    if isinstance(value, np.ndarray | np.generic):
        return _json_value(value.tolist() if isinstance(value, np.ndarray) else value.item(), path, source, error)
    if isinstance(value, int):
        return value
    if isinstance(value, float):
        if not np.isfinite(value):
            raise error(source, path, f"expected a finite number, got {value}")
        return float(value)
    if isinstance(value, Mapping):
        for key in value:
            if not isinstance(key, str):
                raise error(source, path, f"expected an object with string keys, got the key {key!r}")
        return {key: _json_value(item, f"{path}.{key}", source, error) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [_json_value(item, f"{path}[{index}]", source, error) for index, item in enumerate(value)]
    raise error(
        source,
        path,
        f"expected a JSON value (text, a number, true, false, null, a list or an object), got {type(value).__name__}",
    )


def check_vector(
    value: Any,
    length: int,
    *,
    positive: bool = False,
    source: str = "<array>",
    path: str = "$",
    error: type[InvalidFile] = InvalidScene,
) -> np.ndarray:
    """Check a fixed-length vector of finite numbers (optionally all positive).

    Examples
    --------
    >>> check_vector([0.6, 0.4, 0.4], 3, positive=True)
    array([0.6, 0.4, 0.4])
    """
    _refuse_masked(value, source, path, error)
    array = np.asarray(value, dtype=object if not isinstance(value, np.ndarray) else None)
    if array.shape != (length,):
        raise error(source, path, f"expected {length} numbers, got shape {array.shape}")
    for index, item in enumerate(array):
        if isinstance(item, bool) or not isinstance(item, int | float | np.number):
            raise error(source, f"{path}[{index}]", f"expected a number, got {item!r}")
        if isinstance(item, np.complexfloating):
            raise error(source, f"{path}[{index}]", f"expected a real number, got {item!r}")
        if isinstance(item, int) and item.bit_length() > FLOAT_BITS:
            raise error(source, f"{path}[{index}]", f"expected a finite number, got {number_text(item)}")
    vector = np.array(array, dtype=np.float64)
    for index, item in enumerate(vector):
        if not np.isfinite(item):
            raise error(source, f"{path}[{index}]", f"expected a finite number, got {item}")
        if positive and item <= 0:
            raise error(source, f"{path}[{index}]", f"expected a positive number, got {item}")
    return vector


def check_quaternion_xyzw(
    value: Any,
    *,
    tolerance: float = QUATERNION_NORM_TOLERANCE,
    source: str = "<array>",
    path: str = "$.orientation_xyzw",
    error: type[InvalidFile] = InvalidScene,
) -> np.ndarray:
    """Check a scalar-last quaternion ``[x, y, z, w]`` and return it normalised.

    A norm within ``tolerance`` of 1 is normalised; anything else is an error.

    Examples
    --------
    >>> check_quaternion_xyzw([0, 0, 0, 1.0002])
    array([0., 0., 0., 1.])
    """
    quaternion = check_vector(value, 4, source=source, path=path, error=error)
    with np.errstate(over="ignore", invalid="ignore"):  # a huge component is reported below, not warned
        norm = float(np.linalg.norm(quaternion))
    if abs(norm - 1.0) > tolerance:
        raise error(
            source, path, f"expected a unit quaternion [x, y, z, w] (norm within {tolerance} of 1), got norm {norm:.6g}"
        )
    normalised: np.ndarray = quaternion / norm
    return normalised


def check_points(
    value: Any, *, source: str = "<array>", path: str = "$.points", error: type[InvalidFile] = InvalidScene
) -> np.ndarray:
    """Check a point cloud and return it as an ``(N, 3)`` float64 array (N may be 0).

    Examples
    --------
    >>> check_points([[0.0, 1.0, 2.0]]).shape
    (1, 3)
    >>> check_points([]).shape
    (0, 3)
    """
    _refuse_masked(value, source, path, error)
    if isinstance(value, np.ndarray):
        array = value
    else:
        if isinstance(value, Sequence) and len(value) == 0:
            return np.zeros((0, 3))
        try:
            array = np.asarray(value)  # numbers stay numbers: text and true/false are refused below
            if array.dtype == object:  # integers too large for int64, or anything mixed in
                array = float_array(value, source=source, path=path, error=error)
        except (TypeError, ValueError):
            raise error(source, path, "expected an N x 3 array of numbers") from None
    if array.ndim != 2 or array.shape[1] != 3:
        raise error(source, path, f"expected an N x 3 array of points, got shape {array.shape}")
    if not np.issubdtype(array.dtype, np.number) or np.issubdtype(array.dtype, np.complexfloating):
        kind = {"U": "text", "S": "text", "b": "true or false"}.get(array.dtype.kind, f"dtype {array.dtype}")
        raise error(source, path, f"expected real numbers, got {kind}")
    points = np.ascontiguousarray(array, dtype=np.float64)
    bad = np.argwhere(~np.isfinite(points))
    if bad.size:
        i, k = bad[0]
        raise error(source, f"{path}[{i}][{k}]", f"expected a finite coordinate, got {points[i, k]}")
    return points


def check_decision_document(document: Document) -> None:
    """What the ``unstack.decision/1`` schema cannot say: one cost (and error) per object, a
    square matrix of them, the choice and the ties among them, a physics veto that is one thing.

    Raises
    ------
    InvalidFile
        At the first array of another length, or a box that is not one of the objects.

    Examples
    --------
    >>> from pathlib import Path
    >>> from unstack.jsonio import Document
    >>> check_decision_document(Document({"objects": ["a"], "choice": "b", "expected_costs": [0.0],
    ...                                   "marginals": [[0.0]]}, "d.json", Path(".")))
    Traceback (most recent call last):
    ...
    unstack.errors.InvalidFile: d.json: $.choice: expected one of the objects, got 'b'
    """
    data, source = document.data, document.source
    objects = data["objects"]
    n = len(objects)
    _check_unique(objects, source, "$.objects")
    for key in ("expected_costs", "expected_cost_errors"):
        if key in data and len(data[key]) != n:
            raise InvalidFile(source, f"$.{key}", f"expected {n} numbers (one per object), got {len(data[key])}")
        if key in data:
            float_array(data[key], source=source, path=f"$.{key}", error=InvalidFile)
    marginals = data["marginals"]
    if len(marginals) != n or any(len(row) != n for row in marginals):
        raise InvalidFile(source, "$.marginals", f"expected a {n} x {n} matrix (one row and column per object)")
    diagonal = np.flatnonzero(np.diag(float_array(marginals, source=source, path="$.marginals", error=InvalidFile)))
    if diagonal.size:
        k = int(diagonal[0])
        raise InvalidFile(source, f"$.marginals[{k}][{k}]", f"expected 0 on the diagonal, got {marginals[k][k]}")
    errors = data.get("marginal_errors")
    if errors is not None and (len(errors) != n or any(len(row) != n for row in errors)):
        raise InvalidFile(source, "$.marginal_errors", f"expected a {n} x {n} matrix (one row and column per object)")
    known = set(objects)
    if data["choice"] not in known:
        raise InvalidFile(source, "$.choice", f"expected one of the objects, got {data['choice']!r}")
    _check_known(data.get("ties", []), known, source, "$.ties")
    components = data.get("components", [])
    for index, component in enumerate(components):
        _check_known(component, known, source, f"$.components[{index}]")
    _check_unique([box for component in components for box in component], source, "$.components")
    methods = data.get("component_methods")
    if methods is not None and len(methods) != len(components):
        raise InvalidFile(source, "$.component_methods", f"expected one method per component ({len(components)})")
    evidence = data.get("evidence", {})
    for kind in ("forced", "forbidden"):  # the schema's two lists (other keys are not read)
        for index, pair in enumerate(evidence.get(kind, [])):
            _check_known(pair, known, source, f"$.evidence.{kind}[{index}]")
    if "reasons" in data:
        _check_reasons(data["reasons"], objects, source)
    pick = data.get("pick", {})
    if pick.get("height_rank", 1) > pick.get("boxes", n):
        raise InvalidFile(source, "$.pick.height_rank", f"expected at most the {pick.get('boxes', n)} boxes ranked")
    veto = data.get("physics_veto")
    if veto is not None:
        _check_physics_veto(veto, source)


def _check_unique(boxes: Sequence[str], source: str, path: str) -> None:
    seen: set[str] = set()
    for box in boxes:
        if not isinstance(box, str):
            raise InvalidFile(source, path, f"expected box ids, got {box!r:.60}")
        if box in seen:
            raise InvalidFile(source, path, f"expected each box once, {box!r} appears twice")
        seen.add(box)


def _check_known(boxes: Sequence[str], known: set[str], source: str, path: str) -> None:
    for index, box in enumerate(boxes):
        if not isinstance(box, str) or box not in known:  # where the schema leaves an id untyped: a list, say
            raise InvalidFile(source, f"{path}[{index}]", f"expected one of the objects, got {box!r:.60}")


def _check_reasons(reasons: list[dict[str, Any]], objects: Sequence[str], source: str) -> None:
    """One reason per object, in their order; the boxes they name are objects, with probabilities."""
    if [reason["box"] for reason in reasons] != list(objects):
        raise InvalidFile(
            source, "$.reasons", f"expected one reason per object, in the objects' order ({len(objects)})"
        )
    known = set(objects)
    for index, reason in enumerate(reasons):
        where = f"$.reasons[{index}]"
        named: list[tuple[str, int | None, Any]] = [
            ("holds_up", k, entry) for k, entry in enumerate(reason["holds_up"])
        ]
        named += [("held_by", None, reason["held_by"])] if reason["held_by"] is not None else []
        named += [("may_hold_up", None, reason["may_hold_up"])] if "may_hold_up" in reason else []
        for key, k, entry in named:
            path = f"{where}.{key}" + ("" if k is None else f"[{k}]")
            _check_known(entry[:1], known, source, path)
            probability = finite_number(entry[1])
            if probability is None or not 0.0 <= probability <= 1.0:
                raise InvalidFile(
                    source, f"{path}[1]", f"expected a probability from 0 to 1, got {number_text(entry[1])}"
                )


def check_payoff_document(document: Document) -> None:
    """What the ``unstack.payoff/1`` schema cannot say: each object once, one expected cost and
    one cost per world for each, worlds of objects counted as ``consistent_worlds``, their
    probabilities summing to 1 and the expected costs their weighted sums (Eq. 13).

    Raises
    ------
    InvalidFile
        At the first part that disagrees.
    """
    data, source = document.data, document.source
    objects, worlds = data["objects"], data["worlds"]
    n, known = len(objects), set(data["objects"])
    _check_unique(objects, source, "$.objects")
    if data["consistent_worlds"] != len(worlds):
        raise InvalidFile(source, "$.consistent_worlds", f"expected the {len(worlds):,} worlds listed")
    if len(data["expected_costs"]) != n:
        raise InvalidFile(source, "$.expected_costs", f"expected {n} numbers (one per object)")
    for index, world in enumerate(worlds):
        if len(world["costs"]) != n:
            raise InvalidFile(source, f"$.worlds[{index}].costs", f"expected {n} numbers (one per object)")
        for k, pair in enumerate(world["supports"]):
            _check_known(pair, known, source, f"$.worlds[{index}].supports[{k}]")
    probabilities = float_array([world["probability"] for world in worlds], source=source, error=InvalidFile)
    if abs(float(probabilities.sum()) - 1.0) > 1e-6:
        raise InvalidFile(source, "$.worlds", f"expected probabilities summing to 1, got {probabilities.sum():.6g}")
    costs = float_array([world["costs"] for world in worlds], source=source, path="$.worlds", error=InvalidFile)
    given = float_array(data["expected_costs"], source=source, path="$.expected_costs", error=InvalidFile)
    weighted = probabilities @ costs.reshape(len(worlds), n)
    off = np.flatnonzero(~np.isclose(given, weighted, rtol=1e-6, atol=1e-9))
    if off.size:
        k = int(off[0])
        raise InvalidFile(source, f"$.expected_costs[{k}]", f"expected the worlds' weighted cost {weighted[k]:.6g}, "
                          f"got {given[k]:.6g}")  # fmt: skip


def _check_physics_veto(veto: dict[str, Any], source: str) -> None:
    """A veto not applied (``skipped``) vetoed nothing and tried nothing; one applied tried the pick."""
    if "skipped" in veto:
        if veto["vetoed"]:
            raise InvalidFile(source, "$.physics_veto.vetoed", "expected false: the veto was not applied (skipped)")
        if veto["tried"]:
            raise InvalidFile(
                source, "$.physics_veto.tried", "expected no box tried: the veto was not applied (skipped)"
            )
    elif not veto["tried"]:
        raise InvalidFile(
            source, "$.physics_veto.tried", "expected at least the pick tried (or skipped, saying why not)"
        )


def check_plan_document(document: Document) -> None:
    """What the ``unstack.plan/1`` schema cannot say: the order takes each object once, and
    step ``k`` takes the ``k``-th box of the order from the boxes still in place.

    Raises
    ------
    InvalidFile
        At the first box out of place.
    """
    data, source = document.data, document.source
    order, objects = data["order"], data["objects"]
    if sorted(order) != sorted(objects) or len(set(order)) != len(order):
        raise InvalidFile(source, "$.order", "expected each of the objects once")
    if len(data["steps"]) != len(order):
        raise InvalidFile(source, "$.steps", f"expected {len(order)} steps (one per box of the order)")
    for index, (step, box) in enumerate(zip(data["steps"], order, strict=True)):
        if step["choice"] != box:
            raise InvalidFile(source, f"$.steps[{index}].choice", f"expected {box!r}, the order's box")
        if box not in step["remaining"]:
            raise InvalidFile(source, f"$.steps[{index}].remaining", f"expected the boxes in place to hold {box!r}")
