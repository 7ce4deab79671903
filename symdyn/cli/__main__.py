"""`python -m symdyn.cli`: the symdyn command."""

import sys

from .main import main

sys.exit(main())
