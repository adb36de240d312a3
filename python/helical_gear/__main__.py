"""``python -m helical_gear study designs.csv --out results.parquet [--scheduler ADDRESS]
[--workers N]``: see `helical_gear.study.main`."""

import sys

from .study import main

if __name__ == "__main__":
    sys.exit(main())
