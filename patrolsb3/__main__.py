"""``python -m patrolsb3``: the command line of :mod:`patrolsb3.cli`."""
import sys

from .cli import main

sys.exit(main())
