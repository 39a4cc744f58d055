"""Text for people: the first sentence of a description, counts with their noun, and listings
wrapped to the terminal's width (never cut mid-sentence)."""

from __future__ import annotations

import shutil
import textwrap

_ABBREVIATIONS = ("Eq", "Eqs", "Sec", "Secs", "Fig", "Figs", "Tab", "e.g", "i.e", "cf", "vs", "approx", "No")


def first_sentence(text: str) -> str:
    """The first sentence of ``text`` on one line: up to the first '.', ';' or '!' that is followed
    by a space or the end, outside parentheses and quotes, and not after an abbreviation
    ("Fig. 5", "Eqs. 6-14", "e.g. x")."""
    text = " ".join((text or "").split())
    depth, quote = 0, False
    for i, ch in enumerate(text):
        if ch in "([":
            depth += 1
        elif ch in ")]":
            depth = max(0, depth - 1)
        elif ch == '"':
            quote = not quote
        elif ch in ".;!" and depth == 0 and not quote and (i + 1 == len(text) or text[i + 1] == " "):
            word = text[:i].rsplit(" ", 1)[-1].lstrip("(")
            if ch == "." and (word in _ABBREVIATIONS or word.endswith(("e.g", "i.e", ".."))):
                continue
            return text[: i + 1] if ch == "." else text[:i] + "."
    return text


def count(n: int, noun: str) -> str:
    """``1 increment``, ``0 increments``, ``13 increments`` (nouns that take an -s)."""
    return f"{n} {noun}{'' if n == 1 else 's'}"


def width() -> int:
    """Columns to wrap listings to: the terminal's (80 when it reports none), at most 120."""
    cols = shutil.get_terminal_size((80, 24)).columns
    return max(40, min(cols if cols > 0 else 80, 120))


def hanging(head: str, body: str, indent: int, columns: int | None = None) -> str:
    """``head`` (padded to ``indent`` columns) followed by ``body`` wrapped to the terminal's width,
    the continuation lines indented by ``indent``: a listing line that wraps instead of being cut."""
    columns = columns or width()
    first = head.ljust(indent) if len(head) < indent else head + " "
    return textwrap.fill(
        body, width=columns, initial_indent=first, subsequent_indent=" " * indent, break_on_hyphens=False
    )
