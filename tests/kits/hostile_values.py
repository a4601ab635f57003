"""Hypothesis strategies of hostile values for spec fields (needs hypothesis, in the test extra)."""

from __future__ import annotations

import math

from hypothesis import strategies as st

#: Values that are wrong for almost every field, never an in-range number (so a valid run stays the test town).
HOSTILE = st.one_of(
    st.sampled_from([math.nan, math.inf, -math.inf, 10**400, -(10**400), 1e308, "", "x" * 10_000, [], {}, None,
                     True, [[[[]]]], {"": None}]),
    st.text(max_size=20), st.lists(st.text(max_size=4), max_size=5),
    st.dictionaries(st.text(max_size=8), st.text(max_size=8), max_size=3),
)
