#!/usr/bin/python3
"""benchgen: independent resolver-bench log generator (see README.md beside this file)."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from benchgen.cli import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
