"""``python -m pyoa`` runs the command line (see :mod:`pyoa.commands`)."""

import sys

from .commands import main

sys.exit(main())
