"""``python -m pdw``: the command line (see `pdw.present.cli`)."""
import sys

from .present.cli import main

sys.exit(main())
