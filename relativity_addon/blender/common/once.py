"""What a sync reads once: a sync changes no setting, key or modifier, yet its parts ask about every
object several times (issue 26's 1,000 objects). An :class:`Once` holds one dict for its callers to
fill while :meth:`Once.kept` is open (the outermost opening's); outside it :meth:`Once.values` is
None and nothing is kept."""

from __future__ import annotations

import threading
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from collections.abc import Iterator


class Once:
    def __init__(self) -> None:
        self._local = threading.local()

    @contextmanager
    def kept(self, known: dict[Any, Any] | None = None) -> Iterator[None]:
        """Inside: :meth:`values` is one dict, ``known`` when given (and no outer opening holds one)."""
        outer = getattr(self._local, "values", None)
        self._local.values = outer if outer is not None else {} if known is None else known
        try:
            yield
        finally:
            self._local.values = outer

    def values(self) -> dict[Any, Any] | None:
        return getattr(self._local, "values", None)
