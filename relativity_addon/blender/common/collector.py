"""Python's cyclic garbage collector paused while the add-on syncs (issue 26: 1,000 objects).

A sync makes many short-lived tuples (signatures, keys, the settings it reads), which reference
counting frees; yet every 700 allocations start a collection of the youngest objects, and every
tenth of those an older generation's, which walks what Python tracks (about 90,000 objects in
issue 26's 1,000-object scene): 126 collections and 35 ms of a 0.5 s observer's velocity change
there. While :func:`paused` none starts; the collector runs again as before when it ends (what the
sync left in cycles, if anything, is collected then). Nested uses leave it to the outermost.
"""

from __future__ import annotations

import gc
from contextlib import contextmanager
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Iterator


@contextmanager
def paused() -> Iterator[None]:
    """Inside (also as a decorator): no automatic collection; enabled again after, if it was."""
    if not gc.isenabled():
        yield
        return
    gc.disable()
    try:
        yield
    finally:
        gc.enable()
