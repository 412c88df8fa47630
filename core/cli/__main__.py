"""``python -m geobrep.cli``."""

import sys

from geobrep.cli.main import main

sys.exit(main())
