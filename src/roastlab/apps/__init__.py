"""Deprecated location of the command line (now :mod:`roastlab.cli`)."""
