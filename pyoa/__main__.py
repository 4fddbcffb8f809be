"""``python -m pyoa`` runs the command line (see :mod:`pyoa.cli`)."""

import sys

from .cli import main

sys.exit(main())
