"""``python -m ddwmmr.bench``: see :mod:`ddwmmr.cli.bench`."""

import sys

from ddwmmr.cli.bench import main

if __name__ == "__main__":
    sys.exit(main())
