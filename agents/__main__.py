"""``python -m agents ...`` is the ``sensorplan`` command (:mod:`agents.cli`), for a checkout
without the console script installed: ``python -m agents train --env ... --algo ppo``."""

import sys

from .cli import main

if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
