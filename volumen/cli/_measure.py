"""``volumen measure ACTION``: the measurement commands, one module per action.

An action is one line in :data:`ACTIONS`: its name and the module of this package that holds ``register(actions)``
(adds its parser to the ``measure`` group and returns it) and ``run(args)``. ``OUTPUTS`` of every action's module
join the command's (the error contract removes what a failed run began: ``_contract``).
"""

from __future__ import annotations

import importlib

__all__ = ["register", "run", "ACTIONS", "OUTPUTS"]

#: action name -> module of this package with register(actions) and run(args)
ACTIONS = {
    "export": "_measure_export",
    "volumes": "_measure_volumes",
    "vessel": "_measure_vessel",
}


def _modules():
    return {name: importlib.import_module(f"{__package__}.{mod}") for name, mod in ACTIONS.items()}


#: the output arguments of every action (``-o`` paths)
OUTPUTS = tuple(sorted({o for m in _modules().values() for o in getattr(m, "OUTPUTS", ())}))


def register(sub):
    p = sub.add_parser("measure", help="measurements: export a session's as a DICOM SR, CSV or JSON; structure volumes")
    acts = p.add_subparsers(dest="action", metavar="ACTION")
    acts.required = True
    for module in _modules().values():
        module.register(acts).set_defaults(_action=module.run)
    return p


def run(args):
    return args._action(args)
