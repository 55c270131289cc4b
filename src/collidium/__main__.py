"""``python -m collidium``: the command line."""

import sys

from collidium.cli import main

if __name__ == "__main__":
    sys.exit(main())
