"""The ``albot1`` console script: Ctrl-C or SIGTERM at any moment of a command is one line and the shell's status.

Why a module of its own: ``albot1.cli.app`` imports Typer and every command
module before its ``main`` runs (0.2 s on an idle machine, 1.5-2 s on a
loaded one), and a command imports its layers (numpy, numba, ...) when it
starts. A Ctrl-C in that time printed Python's KeyboardInterrupt traceback
(exit -2 rather than 130); a SIGTERM ended the process without a word (-15);
once the command ran, Typer turned Ctrl-C into exit 130, silently. Here the
handlers of :mod:`albot1.cli.interrupt` are in place before anything slow is
imported (this module and that one import only the standard library, ~10 ms),
and every stop the command did not report itself (``albot1 bench`` says what it
kept) becomes ``albot1: interrupted`` (exit 130) or ``albot1: terminated
(SIGTERM)`` (exit 143). A stop while the finished process exits ends it at
once the same way, rather than with Python's default action and no word; in
Python's last step (its modules torn down, tens of milliseconds) it is ignored.

What is left to Python: the interpreter's own start up to this module's import
(60-80 ms here, most of it Python's start and ``site``).
"""

from __future__ import annotations

import atexit
import contextlib
import os
import signal
import sys
from types import FrameType

from albot1.cli.interrupt import Interrupts, noting_interrupts, terminating_as_interrupt


def main() -> None:
    """Run the ``albot1`` command line (:func:`albot1.cli.app.main`) under the interrupt handlers."""
    atexit.register(_ignore_stops)  # registered first, so run last: after the atexit work of every library
    noted = Interrupts()
    status: str | int | None = 0
    try:
        with noting_interrupts(noted), terminating_as_interrupt(noted):
            try:
                from albot1.cli.app import main as command_line  # the slow part: Typer and every command module

                command_line()
            except KeyboardInterrupt:
                noted.note()  # its handler noted it; or other code raised it: a stop all the same
            except SystemExit as exc:  # Typer turns a KeyboardInterrupt into exit 130, silently
                status = exc.code
    except KeyboardInterrupt:  # in the instant the handlers were being put back
        noted.note()
    _stop_at_once_while_exiting(noted)
    if noted.received and not noted.told:
        print(noted.line(), file=sys.stderr)
        status = noted.status()
    sys.exit(status)


def _stop_at_once_while_exiting(noted: Interrupts) -> None:
    """From here to Python's teardown a stop says its line (unless said) and exits with its status at once.

    The command is over: a KeyboardInterrupt would only interrupt the exit's work (joining threads, the
    atexit callbacks: a Dask cluster closing, printed as "Exception ignored"), and SIGTERM's default action
    would end the process silently with -15. Only where the signal is at the action the handlers above found
    (not ignored, no host program's handler).
    """

    def stop(signum: int, frame: FrameType | None) -> None:
        said = noted.told
        noted.note(terminated=signum == signal.SIGTERM)
        with contextlib.suppress(OSError, ValueError):  # a closed pipe: nothing more to say
            sys.stdout.flush()
            if not said:
                print(noted.line(), file=sys.stderr, flush=True)
        os._exit(noted.status())

    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, stop)
    if signal.getsignal(signal.SIGTERM) is signal.SIG_DFL:
        signal.signal(signal.SIGTERM, stop)


def _ignore_stops() -> None:
    """Python's last step, tearing its modules down (tens of ms): a stop is ignored, the command's status kept.

    Python gives every signal with a handler its default action back there (-2 or -15, no word), but keeps an
    ignored one ignored. Nothing is left to stop: the work, the atexit callbacks and the output are done.
    """
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, signal.SIG_IGN)
