"""fastjsonschema's compiled validators and jsonschema agree on what is valid.

A valid document is passed by the compiled validator alone; only an invalid one reaches
jsonschema, whose errors word the message. If the two disagreed, a document could pass
unchecked, or an invalid one get no message.
"""

from __future__ import annotations

import copy
import json
from typing import Any

import fastjsonschema
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from jsonschema import Draft202012Validator

from tests.conftest import EXAMPLES
from unstack.jsonio import FORMATS, load_schema

DOCUMENTS = [json.loads(path.read_text()) for path in sorted(EXAMPLES.glob("*.json"))]
LEAVES = st.one_of(st.none(), st.booleans(), st.integers(-3, 3), st.floats(-2, 2), st.text(max_size=3),
                   st.lists(st.integers(0, 1), max_size=3), st.dictionaries(st.text(max_size=2), st.integers(), max_size=1))  # fmt: skip


def agree(document: dict[str, Any]) -> None:
    tag = document["format"]
    try:
        fastjsonschema.compile(load_schema(tag))(document)
        compiled_valid = True
    except fastjsonschema.JsonSchemaValueException:
        compiled_valid = False
    assert compiled_valid == Draft202012Validator(load_schema(tag)).is_valid(document), document


def paths(value: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    found = [prefix] if prefix else []
    if isinstance(value, dict):
        found += [p for key, item in value.items() for p in paths(item, (*prefix, key))]
    elif isinstance(value, list):
        found += [p for index, item in enumerate(value[:4]) for p in paths(item, (*prefix, index))]
    return found


@pytest.mark.parametrize("document", DOCUMENTS, ids=lambda d: d["format"])
def test_every_example_is_valid_for_both(document: dict[str, Any]) -> None:
    assert document["format"] in FORMATS
    agree(document)


@settings(max_examples=300, deadline=None)
@given(st.sampled_from(DOCUMENTS), st.data(), LEAVES)
def test_a_document_with_one_value_replaced_is_judged_alike(
    document: dict[str, Any], data: st.DataObject, leaf: Any
) -> None:
    mutated = copy.deepcopy(document)
    where = data.draw(st.sampled_from([p for p in paths(mutated) if p[0] != "format"]))
    target = mutated
    for key in where[:-1]:
        target = target[key]
    target[where[-1]] = leaf
    agree(mutated)
