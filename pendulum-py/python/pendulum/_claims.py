"""``pendulum.check_claims``: a hand derivation in a claims file checked against the sympy
reference built into the package (``cargo xtask verify --claims FILE``)."""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any, Optional, Union

from . import _pendulum


@dataclass(frozen=True)
class ClaimCheck:
    """One claim's outcome: its ``title`` and ``line``, the reference ``cases`` it covered,
    the ``verdict`` ("agrees", "disagrees", "untested"), the ``worst`` relative error, the
    ``corrected`` form's (verdict, error) if the claim has one, the first disagreeing
    entry and state, the ``diagnosis`` (the common slips found) and the ``fixes``: for
    each diagnosed entry, its line, the slip and the corrected entry."""

    title: str
    line: int
    cases: list[str]
    verdict: str
    worst: float
    corrected: Optional[tuple[str, float]]
    first_disagreement: Optional[str]
    diagnosis: str
    fixes: list[tuple[int, str, str]]


@dataclass(frozen=True)
class ClaimsReport:
    """Every claim's :class:`ClaimCheck` and the command's table (markdown; a notebook
    shows it as a table)."""

    claims: list[ClaimCheck]
    table: str

    def __str__(self) -> str:
        return self.table

    def _repr_markdown_(self) -> str:
        return self.table


def check_claims(
    path: Union[str, "os.PathLike[str]", None] = None,
    *,
    text: Optional[str] = None,
    states: Optional[int] = None,
    seed: Optional[int] = None,
) -> ClaimsReport:
    """Checks the claims file at ``path`` (or its ``text``) against the sympy reference:
    every entry at ``states`` random states (200) of every case it covers (planar chains of
    1–8 links, spatial of 1–5), drawn from ``seed`` (that of ``cargo xtask verify``); a
    disagreeing entry is diagnosed (a sign, a factor, swapped indices, …) and corrected.
    The file's format: ``reference/CLAIMS.md`` in the repository. A file with errors raises
    ValueError naming each error's line and column."""
    options: dict[str, Any] = {}
    if states is not None:
        options["states"] = states
    if seed is not None:
        options["seed"] = seed
    claims, table = _pendulum.check_claims(None if path is None else os.fspath(path), text=text, **options)
    return ClaimsReport([ClaimCheck(**c) for c in claims], table)
