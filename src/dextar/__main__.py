"""python -m dextar: the command line."""

from .cli import entry

entry()
