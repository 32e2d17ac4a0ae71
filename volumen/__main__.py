"""``python -m volumen`` runs the command line."""

import sys

from volumen.cli import main

sys.exit(main())
