"""``python -m ddwmmr.bounds``: see :mod:`ddwmmr.cli.bounds`."""

import sys

from ddwmmr.cli.bounds import main

if __name__ == "__main__":
    sys.exit(main())
