"""The ``roastlab`` command line (:mod:`.main`); ``python -m roastlab`` and the ``roastlab`` script run :func:`main`."""

from .main import build_parser, main

__all__ = ["build_parser", "main"]
