"""python -m dextar: the command line."""

from .cli import main

raise SystemExit(main())
