"""``python -m biped``: the ``biped`` command line."""

import sys

from biped_cli import main

if __name__ == "__main__":
    sys.exit(main())
