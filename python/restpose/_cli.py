"""The ``restpose`` command installed by the wheel: the same command line as the Rust binary,
compiled into the extension module."""

from __future__ import annotations

import signal
import sys
from typing import List, Optional


def main(argv: Optional[List[str]] = None) -> int:
    """Runs ``restpose`` with ``argv`` (default: ``sys.argv``) and exits with its code."""
    from restpose._native import run_cli

    if argv is None:
        argv = sys.argv
    # Ctrl-C ends the command at once, as it ends the native binary.
    try:
        signal.signal(signal.SIGINT, signal.SIG_DFL)
    except ValueError:  # not the main thread
        pass
    sys.stdout.flush()
    code = run_cli(["restpose", *argv[1:]])
    sys.exit(code)


if __name__ == "__main__":
    main()
