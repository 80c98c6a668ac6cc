"""The project's one test of a number as text: what a log writes, a user types in ``--set`` or an environment
variable. Here in ``config`` (the lowest layer that reads user text) so that the data layer's parsers
(:mod:`albot1.data.tokens`) and the config resolution (:mod:`albot1.config.resolve`) share it."""

from __future__ import annotations


def is_plain(token: str | bytes) -> bool:
    """Whether ``token`` has neither Python's digit grouping nor a non-ASCII character (:func:`is_number`
    without ``float()``: the bulk parsers test a whole line this way before converting it)."""
    if isinstance(token, str):
        return "_" not in token and token.isascii()
    return b"_" not in token and token.isascii()


def is_number(token: str | bytes) -> bool:
    """Whether ``token`` is a number as the logs write them: what ``float()`` reads, but neither Python's digit
    grouping (``3_05`` would be read as 305) nor non-ASCII digits (full-width ``１``, Arabic-Indic ``٣``), which
    ``float()`` also reads but numpy, whose bulk conversion the CARMEN parser uses, refuses. ``nan`` and ``inf``
    are numbers here; a caller that needs a finite value tests that itself."""
    if not is_plain(token):
        return False
    try:
        float(token)
    except ValueError:
        return False
    return True
