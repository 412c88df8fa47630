"""The ``geobrep`` command line: ``geobrep info``, ``geobrep plugins``, ``geobrep demo``.

Exit codes: 0 success; 1 a geobrep error (bad input, unreadable file, ...), printed as one line;
2 a usage error; 3 ``fit --check`` not met; 4 an empty result (without ``--allow-empty``);
70 an unexpected internal error (``GEOBREP_TRACEBACK=1`` shows the traceback);
130 interrupted.
"""

from geobrep.cli.main import main

__all__ = ["main"]
