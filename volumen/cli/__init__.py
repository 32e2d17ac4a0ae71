"""The ``volumen`` command: one sub-command per module, errors as one line, never a traceback.

Exit codes: 0 success, 1 a volumen error (a bad file, option, choice or point, a missing
optional package: one line naming the command and the problem, and the outputs a
failed command began are removed: ``_contract``), 3 an unexpected internal error
(the message says how to get the traceback: ``VOLUMEN_DEBUG=1``).
"""

from __future__ import annotations

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
    "measure": "_measure",
    "batch": "_batch",
    "bench": "_bench",
    "demo": "_demo",
    "warm": "_warm",
}
#: sub-commands that draw, so may compile kernels on first use: they say so when they do (volumen.jit.announce)
COMPILING = {"render", "fly", "cpr", "mesh", "batch", "demo", "warm"}


def build_parser():
    """The argument parser with every sub-command registered."""
    from volumen import __version__

    from ._parser import Parser

    parser = Parser(prog="volumen", description="See inside medical volumes (CT, MRI).")
    parser.add_argument("--version", action="version", version=f"volumen {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for mod in COMMANDS.values():
        module = importlib.import_module(f"{__name__}.{mod}")
        p = module.register(sub)
        p.set_defaults(_run=module.run, _outputs=getattr(module, "OUTPUTS", ()))
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit code (also used by ``python -m volumen``)."""
    from ._common import join_negative_values
    from ._contract import FAILED, OutputFiles, explain

    parser = build_parser()
    args = parser.parse_args(join_negative_values(sys.argv[1:] if argv is None else list(argv)))
    if args.command in COMPILING:
        from volumen.jit import announce

        announce()
    outputs = OutputFiles(args, args._outputs)
    try:
        result = args._run(args)
    except KeyboardInterrupt:
        outputs.discard()
        print(f"volumen {args.command}: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # every failure is one line (_contract.explain); developers set VOLUMEN_DEBUG
        outputs.discard()
        code, line = explain(exc)
        if code != FAILED and os.environ.get("VOLUMEN_DEBUG"):
            raise
        print(f"volumen {args.command}: {line}", file=sys.stderr)
        return code
    return int(result or 0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
