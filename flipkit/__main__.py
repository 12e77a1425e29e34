import sys

from flipkit.cli import main

sys.exit(main())
