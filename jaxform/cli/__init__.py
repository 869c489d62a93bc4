"""The ``jaxform`` command. Host side only: argument parsing, files, printing.

Each sub-command lives in its own module with ``add_parser(subparsers)`` registering itself and a
``run(args) -> int`` doing the work; this module only wires them together.
"""
from __future__ import annotations

import argparse
import importlib
import signal
import sys
import threading

# Sub-command modules, in the order ``jaxform --help`` lists them.
_COMMANDS = ("demo", "cases", "run", "sweep", "study", "wrinkles", "check", "quasi_static")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="jaxform",
        description="Differentiable forming simulation of engineering fabrics (JAX).",
    )
    from jaxform import __version__

    parser.add_argument("--version", action="version", version=f"jaxform {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in _COMMANDS:
        try:
            module = importlib.import_module(f"jaxform.cli.{name}")
        except ModuleNotFoundError as err:  # a sub-command not built yet in this checkout
            if err.name == f"jaxform.cli.{name}":
                continue
            raise
        module.add_parser(sub)
    return parser


def use_case_dtype(case) -> None:
    """The command owns its process: a case computed in float64 (``numerics.dtype = "float64"``)
    switches JAX's 64-bit mode on before its rig is built. The library only checks that the mode is
    on (:func:`jaxform.forming.build`), since switching it is the program's choice, which a command
    line user could not make."""
    if getattr(case, "dtype", "float32") == "float64":
        import jax

        jax.config.update("jax_enable_x64", True)


TERMINATED = "terminated by SIGTERM"
"""The reason a run stopped by ``kill`` or a scheduler records (the command exits 143)."""


_STOP: list[str] = []
"""Set by :func:`_terminate`. Python runs a signal handler at any bytecode, and where that is inside
a hook that ignores exceptions (JAX's garbage-collection callback, seen on a 4 mm run) its
``KeyboardInterrupt`` is lost and the run went on; :func:`raise_if_stopped` raises it again at the
next chunk (the progress callback calls it)."""


def _terminate(signum, frame):
    _STOP.append(TERMINATED)
    raise KeyboardInterrupt(TERMINATED)


def raise_if_stopped() -> None:
    """Raise the ``KeyboardInterrupt`` of a SIGTERM already received (one a hook swallowed)."""
    if _STOP:
        raise KeyboardInterrupt(_STOP[0])


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    # SIGTERM (kill, a scheduler) stops a run like Ctrl-C does: what was written stays valid and says why
    _STOP.clear()
    previous = signal.signal(signal.SIGTERM, _terminate) if threading.current_thread() is threading.main_thread() else None
    try:
        return int(args.handler(args) or 0)
    except (ValueError, FileNotFoundError, FileExistsError) as err:
        print(f"jaxform {args.command}: error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as err:
        print(f"jaxform {args.command}: {err or 'interrupted'}", file=sys.stderr)
        return 143 if str(err) == TERMINATED else 130
    finally:
        _STOP.clear()  # a later run in this process (tests, notebooks) starts unstopped
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


if __name__ == "__main__":
    sys.exit(main())
