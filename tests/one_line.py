"""The message of a caught ParameterError, checked to be one line (for the input tests)."""

from __future__ import annotations


def one_line(info) -> str:
    """``str`` of the exception in a ``pytest.raises`` info, asserted single-line and short."""
    text = str(info.value)
    assert "\n" not in text and len(text) < 600
    return text
