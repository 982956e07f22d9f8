"""The optional parts of collisionlab and the extra that installs each.

``pip install collisionlab`` brings what the lab and the engines need (numpy, numba, matplotlib,
orjson). Sweeps need the ``sweep`` extra (dask[distributed], pyarrow, pandas), the interactive
page (``--html``) the ``html`` extra (plotly), GSD trajectories (``gas --trajectory FILE.gsd``)
the ``trajectory`` extra (gsd); ``collisionlab[all]`` installs the three. A module of
an extra is imported only inside the function that needs it, through :func:`require`, so a
missing one is one line naming the extra, not a traceback.
"""

from __future__ import annotations

import importlib
from types import ModuleType

from .errors import CollisionLabError

__all__ = ["MissingExtraError", "require"]


class MissingExtraError(CollisionLabError, ImportError):
    """A feature whose extra is not installed; the message names the extra and how to install it.

    >>> str(MissingExtraError("sweeps", "sweep"))
    "sweeps need the 'sweep' extra: pip install 'collisionlab[sweep]'"
    """

    def __init__(self, what: str, extra: str) -> None:
        self.what = what
        self.extra = extra
        super().__init__(f"{what} need the {extra!r} extra: pip install 'collisionlab[{extra}]'")


def require(module: str, extra: str, what: str) -> ModuleType:
    """``module``, imported; :class:`MissingExtraError` naming ``extra`` (and ``what`` needs it)
    when it cannot be imported.

    >>> require("json", "none", "tests").__name__
    'json'
    >>> require("no_such_module_here", "sweep", "sweeps")
    Traceback (most recent call last):
    ...
    collisionlab.extras.MissingExtraError: sweeps need the 'sweep' extra: pip install 'collisionlab[sweep]'
    """
    try:
        return importlib.import_module(module)
    except ImportError:
        raise MissingExtraError(what, extra) from None
