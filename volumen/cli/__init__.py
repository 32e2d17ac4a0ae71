"""The ``volumen`` command: one sub-command per module, errors as one line, never a traceback.

Exit codes: 0 success, 1 a volumen error (bad file, bad option), 2 usage error
(argparse), 3 an unexpected internal error (the message says how to get the
traceback: ``VOLUMEN_DEBUG=1``).
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys

__all__ = ["main", "build_parser"]

# sub-command name -> module in this package (each has register(subparsers) and run(args))
COMMANDS = {
    "info": "_info",
    "convert": "_convert",
    "slices": "_slices",
    "render": "_render",
    "fly": "_fly",
    "cpr": "_cpr",
    "mesh": "_mesh",
    "view": "_view",
    "serve": "_serve",
    "pacs": "_pacs",
    "batch": "_batch",
    "bench": "_bench",
    "demo": "_demo",
    "warm": "_warm",
}
#: sub-commands that draw, so may compile kernels on first use: they say so when they do (volumen.jit.announce)
COMPILING = {"render", "fly", "cpr", "mesh", "batch", "demo", "warm"}


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every sub-command registered."""
    from volumen import __version__

    parser = argparse.ArgumentParser(prog="volumen", description="See inside medical volumes (CT, MRI).")
    parser.add_argument("--version", action="version", version=f"volumen {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for mod in COMMANDS.values():
        module = importlib.import_module(f"{__name__}.{mod}")
        p = module.register(sub)
        p.set_defaults(_run=module.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit code (also used by ``python -m volumen``)."""
    from volumen.errors import VolumenError

    from ._common import join_negative_values

    parser = build_parser()
    args = parser.parse_args(join_negative_values(sys.argv[1:] if argv is None else list(argv)))
    if args.command in COMPILING:
        from volumen.jit import announce

        announce()
    try:
        result = args._run(args)
    except VolumenError as exc:
        print(f"volumen {args.command}: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"volumen {args.command}: interrupted", file=sys.stderr)
        return 130
    except (ValueError, IndexError) as exc:
        print(f"volumen {args.command}: error: {exc}", file=sys.stderr)
        return 1
    except OSError as exc:  # a file or folder the command reads or writes
        where = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
        print(f"volumen {args.command}: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 1
    except Exception as exc:  # the user gets one line, developers set VOLUMEN_DEBUG
        if os.environ.get("VOLUMEN_DEBUG"):
            raise
        print(f"volumen {args.command}: internal error: {type(exc).__name__}: {exc} "
              "(set VOLUMEN_DEBUG=1 for the traceback)", file=sys.stderr)
        return 3
    return int(result or 0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
