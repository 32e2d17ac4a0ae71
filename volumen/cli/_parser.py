"""The command line's argument parser: a wrong or missing argument is one line and exit status 1, a wrong choice
names the valid ones and the closest (``volumen render: error: argument --preset: 'ct-vessel' is not one of
ct-bone, ...; did you mean 'ct-vessels'?``), never a usage dump."""

from __future__ import annotations

import argparse
import sys

from volumen.errors import choice_message

__all__ = ["Parser", "USAGE_ERROR"]

#: exit status of a command line the parser refuses (as of any other volumen error)
USAGE_ERROR = 1


class Parser(argparse.ArgumentParser):
    """``argparse.ArgumentParser`` with the volumen error contract; its sub-command parsers are of this class too."""

    def _check_value(self, action, value):
        """argparse's check of a ``choices`` value, with the message of :func:`volumen.errors.choice_message`.

        A private hook (called by every argparse from 3.2 to 3.14); should one stop calling it, argparse's own
        message stands, still one line and exit 1 through :meth:`error`, and tests/cli/test_error_contract.py
        fails on the missing suggestion."""
        if action.choices is not None and value not in action.choices:
            what = "/".join(action.option_strings) or "command"
            raise argparse.ArgumentError(None, choice_message(what, value, action.choices))

    def error(self, message: str):
        """Say ``message`` in one line on stderr, with where to find the options, and exit with :data:`USAGE_ERROR`."""
        one_line = " ".join(message.split())
        print(f"{self.prog}: error: {one_line} (see {self.prog} --help)", file=sys.stderr)
        sys.exit(USAGE_ERROR)
