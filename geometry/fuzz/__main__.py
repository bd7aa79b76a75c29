"""``python -m geometry.fuzz``: see :mod:`geometry.fuzz`."""

from .run import main

raise SystemExit(main())
