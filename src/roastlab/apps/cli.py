"""Deprecated: the command line moved to :mod:`roastlab.cli` (one module per command).

``roastlab.apps.cli.main`` still works for one release, with a DeprecationWarning.
"""

import warnings

warnings.warn("roastlab.apps.cli moved to roastlab.cli; import main from there", DeprecationWarning, stacklevel=2)

from ..cli import build_parser, main  # noqa: E402

__all__ = ["build_parser", "main"]
