"""What every command line of the project does with errors and signals.

A user error (a bad argument, configuration, input file or output path, a
size that cannot fit in memory, a full disk) ends the command with exactly one
line on stderr, ``PROG: error: MESSAGE``, and exit status 2. SIGINT (Ctrl-C)
and SIGTERM (what a batch scheduler sends) end it with one line and status
128 + the signal number; a command with workers stops them first (the
``finally`` blocks run, since the signal is raised as :class:`Interrupted`).
"""

from __future__ import annotations

import argparse
import errno
import signal
import sys

from data_schema.common import DataFormatError
from data_schema.output import OutputError

EXIT_USAGE = 2


class Interrupted(KeyboardInterrupt):
    """SIGINT or SIGTERM arrived; ``signal_number`` says which."""

    def __init__(self, signal_number: int):
        super().__init__(signal.Signals(signal_number).name)
        self.signal_number = signal_number


class CommandParser(argparse.ArgumentParser):
    """argparse with a one-line error: ``PROG: error: MESSAGE`` on stderr, exit 2 (no usage block)."""

    def error(self, message):
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


def _raise_interrupted(signal_number, frame):
    raise Interrupted(signal_number)


def _message(exc: BaseException) -> str:
    if isinstance(exc, MemoryError):
        return "not enough memory for this size; choose a smaller one"
    if isinstance(exc, OSError) and not isinstance(exc, (FileNotFoundError, FileExistsError)) and exc.errno:
        where = f"{exc.filename}: " if exc.filename else ""
        text = exc.strerror or errno.errorcode.get(exc.errno, str(exc))
        if exc.errno == errno.ENOSPC:
            text += "; nothing was written, free some space and rerun"
        return where + text
    return " ".join(str(exc).split())


# ImportError: an optional dependency is missing (the message says what to install)
USER_ERRORS = (DataFormatError, OutputError, ValueError, OSError, MemoryError, ImportError)


def run(prog: str, command, args, on_interrupt=None) -> int:
    """``command(args)`` with the project's error and signal conventions (module doc); its exit status.

    ``on_interrupt(signal_number)`` may return the line to print when interrupted.
    """
    previous = signal.signal(signal.SIGTERM, _raise_interrupted)
    try:
        return command(args)
    except Interrupted as exc:
        return _interrupted(prog, exc.signal_number, on_interrupt)
    except KeyboardInterrupt:
        return _interrupted(prog, signal.SIGINT, on_interrupt)
    except USER_ERRORS as exc:
        print(f"{prog}: error: {_message(exc)}", file=sys.stderr)
        return EXIT_USAGE
    finally:
        signal.signal(signal.SIGTERM, previous)


def _interrupted(prog, signal_number, on_interrupt) -> int:
    line = (on_interrupt(signal_number) if on_interrupt else None) or "stopped"
    print(f"{prog}: interrupted by {signal.Signals(signal_number).name}: {line}", file=sys.stderr)
    return 128 + int(signal_number)


SEED_LIMIT = 2 ** 63        # seeds are stored as signed 64-bit integers in every file


def seed_argument(text: str) -> int:
    """argparse type of ``--seed``: an integer in [0, 2**63)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be an integer in [0, 2**63); got {text!r}") from None
    if not 0 <= value < SEED_LIMIT:
        raise argparse.ArgumentTypeError(f"must be an integer in [0, 2**63); got {value}")
    return value


def count_argument(text: str) -> int:
    """argparse type of ``-n``: an integer >= 1 (written as 1000 or 1e3)."""
    try:
        value = int(text)
    except ValueError:
        try:
            number = float(text)
        except ValueError:
            number = float("nan")
        if not number.is_integer():
            raise argparse.ArgumentTypeError(f"must be an integer >= 1; got {text!r}") from None
        value = int(number)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be an integer >= 1; got {value}")
    return value
