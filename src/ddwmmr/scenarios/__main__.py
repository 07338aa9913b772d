"""``python -m ddwmmr.scenarios``: see :mod:`ddwmmr.cli.scenarios`."""

import sys

from ddwmmr.cli.scenarios import main

if __name__ == "__main__":
    sys.exit(main())
