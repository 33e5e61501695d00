"""``python -m pdw``: the command line (see `pdw.cli`)."""
import sys

from .cli import main

sys.exit(main())
