"""``python -m flipkit``: the command line (:mod:`flipkit.cli`)."""

import sys

from flipkit.cli import main

sys.exit(main())
