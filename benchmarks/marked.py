"""Marked sections: the parts of a Markdown page that a benchmark writes.

A marked section is the text between two HTML comments, which Markdown
renderers hide::

    <!-- NAME:begin sha256=0123456789abcdef -->
    ...generated text...
    <!-- NAME:end -->

or, inside one line (a table cell, a sentence),
``<!-- NAME:begin sha256=... -->2.63<!-- NAME:end -->``. ``NAME`` is lower
case letters, digits and hyphens, and appears once per page (a marker
inside a fenced code block is an example, not a marker). The begin
marker carries the first 16 hex digits of the SHA-256 of the UTF-8 text
between the markers (:func:`digest`), so a test can tell generated text from
a hand edit: an edit leaves the recorded digest behind.

Only the text between a section's markers is ever replaced; the page around
it is the author's. A missing or repeated marker is refused, never guessed
at: a benchmark that wrote its figures "near" where a section used to be
would put them in the wrong place silently. Pages are written through
:func:`pyoa.util.atomic.atomic_path`, so an interrupted run leaves the old page.
"""

from __future__ import annotations

import hashlib
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from pyoa.util.atomic import atomic_path

#: Hex digits of SHA-256 kept in a marker: 64 bits, enough to tell an edit from the generated text.
DIGEST_HEX = 16
_NAME = r"[a-z0-9]+(?:-[a-z0-9]+)*"
#: Any begin or end marker, well formed or not, so that a misspelt one is refused rather than skipped.
_MARKER = re.compile(r"<!--\s*(?P<name>[^\s:>]+):(?P<kind>begin|end)\b(?P<rest>[^>]*?)\s*-->")
_DIGEST = re.compile(rf"sha256=(?P<hex>[0-9a-f]{{{DIGEST_HEX}}})")
#: A fenced code block (CommonMark: a line of 3+ backticks or tildes up to the same fence): a marker
#: inside one is an example in the text, not a marker.
_FENCE = re.compile(r"^[ ]{0,3}(`{3,}|~{3,})[^\n]*\n.*?^[ ]{0,3}\1[ \t]*$", re.M | re.S)


class MarkerError(ValueError):
    """A page's markers are missing, repeated, unpaired or malformed."""


@dataclass(frozen=True)
class Section:
    """One marked section of a page: its ``name``, the ``digest`` recorded in
    its begin marker (None if it has none), its ``body`` (the text between the
    markers), where that body lies in the page (``start``, ``end``) and where
    the section does, markers included (``outer``)."""

    name: str
    digest: str | None
    body: str
    start: int
    end: int
    outer: tuple[int, int]

    @property
    def edited(self) -> bool:
        """Whether the body is not the text whose digest the marker records
        (a hand edit, or a section never written by :func:`replace`)."""
        return self.digest != digest(self.body)


def digest(body: str) -> str:
    """The digest a begin marker records for ``body``: the first
    :data:`DIGEST_HEX` hex digits of SHA-256 (FIPS 180-4) of its UTF-8 bytes."""
    return hashlib.sha256(body.encode("utf-8")).hexdigest()[:DIGEST_HEX]


def begin(name: str, body: str) -> str:
    return f"<!-- {name}:begin sha256={digest(body)} -->"


def end(name: str) -> str:
    return f"<!-- {name}:end -->"


def wrap(name: str, body: str) -> str:
    """``body`` between ``name``'s markers, exactly (an inline section)."""
    _check_name(name)
    return begin(name, body) + body + end(name)


def block_body(text: str) -> str:
    """The body of a block section holding ``text``: each marker then stands on a line of its own."""
    return "\n" + text.strip("\n") + "\n"


def block(name: str, text: str) -> str:
    """``text`` as a block section, markers included."""
    return wrap(name, block_body(text))


def _check_name(name: str) -> None:
    if not re.fullmatch(_NAME, name):
        raise MarkerError(f"section name {name!r}: use lower case letters, digits and single hyphens")


def sections(text: str, where: str = "the page") -> dict[str, Section]:
    """Every marked section of ``text`` by name, in page order.

    Raises :class:`MarkerError` for a malformed name or digest, a name marked
    twice, an end without its begin, a begin without its end, or a section
    inside another."""
    found: dict[str, Section] = {}
    opened = None  # (name, digest, start and end of the begin marker)
    fences = [f.span() for f in _FENCE.finditer(text)]
    for m in _MARKER.finditer(text):
        if any(a <= m.start() < b for a, b in fences):
            continue
        name, kind, rest = m["name"], m["kind"], m["rest"].strip()
        line = text.count("\n", 0, m.start()) + 1
        try:
            _check_name(name)
        except MarkerError as exc:
            raise MarkerError(f"{where}, line {line}: {exc}") from None
        if kind == "begin":
            d = _DIGEST.fullmatch(rest)
            if rest and not d:
                raise MarkerError(f"{where}, line {line}: {m[0]!r}: after ':begin' only "
                                  f"'sha256=' and {DIGEST_HEX} hex digits may follow")
            if opened:
                raise MarkerError(f"{where}, line {line}: {name!r} begins inside {opened[0]!r}")
            if name in found:
                raise MarkerError(f"{where}, line {line}: {name!r} is marked twice")
            opened = (name, d["hex"] if d else None, m.start(), m.end())
        else:
            if rest:
                raise MarkerError(f"{where}, line {line}: {m[0]!r}: nothing may follow ':end'")
            if not opened or opened[0] != name:
                raise MarkerError(f"{where}, line {line}: {name!r} ends but "
                                  + (f"{opened[0]!r} is open" if opened else "never began"))
            found[name] = Section(name, opened[1], text[opened[3]:m.start()], opened[3], m.start(),
                                  (opened[2], m.end()))
            opened = None
    if opened:
        raise MarkerError(f"{where}: {opened[0]!r} begins but never ends")
    return found


def replace(text: str, bodies: Mapping[str, str], where: str = "the page") -> str:
    """``text`` with each named section's body replaced by ``bodies[name]``
    and its begin marker's digest updated. Every name must be marked in
    ``text`` exactly once."""
    have = sections(text, where)
    missing = [n for n in bodies if n not in have]
    if missing:
        n = missing[0]
        raise MarkerError(f"{where} has no section {', '.join(map(repr, missing))}: put "
                          f"'<!-- {n}:begin -->' and '{end(n)}' where it belongs")
    for n, b in bodies.items():
        if _MARKER.search(b):
            raise MarkerError(f"the text for {where}'s section {n!r} holds a marker: {_MARKER.search(b)[0]!r}")
    out, at = [], 0
    for s in sorted((have[n] for n in bodies), key=lambda s: s.start):
        # the begin marker is written again, with the new text's digest
        out += [text[at:s.outer[0]], begin(s.name, bodies[s.name]), bodies[s.name]]
        at = s.end
    return "".join(out) + text[at:]


def write(path: Path, bodies: Mapping[str, str]) -> bool:
    """Replace sections of the page ``path`` (:func:`replace`), atomically;
    the page is left untouched (not even rewritten) when nothing changes.
    Returns whether it changed."""
    path = Path(path)
    old = path.read_text(encoding="utf-8")
    new = replace(old, bodies, where=str(path))
    if new == old:
        return False
    with atomic_path(path) as tmp:  # keeps the page's mode
        tmp.write_text(new, encoding="utf-8")
    return True
