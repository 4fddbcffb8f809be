"""How the analysis results show themselves: as tables, in a REPL and in a notebook.

A result's ``__repr__`` is its table as plain text and its ``_repr_markdown_``
the same table for Jupyter, as scipy's result objects show their fields
rather than one long constructor call. :class:`Markdown` is the text a
result's ``table()`` returns: a ``str`` that a REPL prints as itself, not as a
quoted literal full of ``\\n``.
"""

from __future__ import annotations

__all__ = ["Markdown", "field_table"]


class Markdown(str):
    """Markdown text: a ``str`` whose ``repr`` is the text itself (a REPL shows
    the table, not an escaped literal) and which a notebook renders.

    Examples
    --------
    >>> t = Markdown("| a | b |\\n|---|---|\\n| 1 | 2 |\\n")
    >>> t
    | a | b |
    |---|---|
    | 1 | 2 |
    >>> t == "| a | b |\\n|---|---|\\n| 1 | 2 |\\n"
    True
    """

    __slots__ = ()

    def __repr__(self) -> str:
        return str.__str__(self).rstrip("\n")  # the REPL adds its own

    def _repr_markdown_(self) -> str:
        return str.__str__(self)


def field_table(title: str, rows) -> Markdown:
    """``title``, then a Markdown table of ``(field, value)`` pairs."""
    lines = [title, "", "| field | value |", "|---|---|"]
    lines += [f"| {name} | {value} |" for name, value in rows]
    return Markdown("\n".join(lines) + "\n")
