"""``python -m collidium``: the command line."""

import sys

from collidium.cli import console

if __name__ == "__main__":
    sys.exit(console())
