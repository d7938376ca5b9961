"""Hypothesis strategies for fuzz cases: a seed file of a target, mutated structure-aware or byte by byte."""

from __future__ import annotations

from functools import cache

from hypothesis import strategies as st

from .harness import (
    BYTE_ACTIONS,
    JSON_ACTIONS,
    NASTY_U32,
    NASTY_VALUES,
    TARGETS,
    TEXT_ACTIONS,
    mutate_bytes,
    mutate_json,
    mutate_text,
)

_index = st.integers(min_value=0, max_value=10**7)

json_ops = st.lists(
    st.tuples(
        st.sampled_from(JSON_ACTIONS),
        _index,
        st.one_of(
            st.sampled_from(NASTY_VALUES),
            st.floats(),
            st.integers(min_value=-(2**70), max_value=2**70),
            st.text(max_size=8),
        ),
    ),
    min_size=1,
    max_size=4,
)
text_ops = st.lists(st.tuples(st.sampled_from(TEXT_ACTIONS), _index, _index), min_size=1, max_size=4)
byte_ops = st.lists(
    st.tuples(
        st.sampled_from(BYTE_ACTIONS), _index, st.one_of(st.sampled_from(NASTY_U32), st.binary(min_size=1, max_size=16))
    ),
    min_size=1,
    max_size=4,
)


@cache
def seeds(target: str) -> tuple[bytes, ...]:
    return tuple(TARGETS[target].seeds())


def cases(target: str) -> st.SearchStrategy[bytes]:
    """Mutated files of `target`: its structure-aware mutations (JSON tree, text tokens) about two times in three,
    raw byte mutations otherwise."""
    kind = TARGETS[target].kind
    seed = st.sampled_from(seeds(target))
    raw = st.builds(mutate_bytes, seed, byte_ops)
    if kind == "json":
        structured = st.builds(mutate_json, seed, json_ops)
    elif kind == "text":
        structured = st.builds(mutate_text, seed, text_ops)
    else:
        return raw
    return st.one_of(structured, structured, raw)
