"""``pyoa ARGS``: the parser of every command, and how a command ends (status, streams, Ctrl-C)."""

from __future__ import annotations

import argparse
import os
import sys
import warnings

from ..backends import BackendUnavailable, PyoaFallbackWarning
from ..cluster import TasksLost
from ..samplers import ENV_MAX_BYTES
from . import render, samplers, study
from .options import CONVENTION

#: The modules of the commands, each with ``add_parsers(sub)``, in the order ``pyoa --help`` lists them.
COMMANDS = (samplers, render, study)


class _Parser(argparse.ArgumentParser):
    """argparse's parser with its usage errors in one line, as every other refusal
    (``pyoa render: error: unrecognized arguments: --bogus; see pyoa render --help``), not the usage
    block first; exit status 2 as before."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message}; see {self.prog} --help\n")


def build_parser() -> argparse.ArgumentParser:
    from .. import __version__

    ap = _Parser(prog="pyoa", description="Orthogonal-array sampling for Monte Carlo rendering.",
                 epilog=CONVENTION, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--version", action="version", version=f"pyoa {__version__}")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=_Parser)
    ap.set_defaults(commands=sub.choices)  # _main: an unknown option is refused by its command's parser

    for module in COMMANDS:  # each module adds its own commands, in the order --help lists them
        module.add_parsers(sub)
    return ap


def _show_warning(message, category, filename, lineno, file=None, line=None):
    """pyoa's own fallback warning as its two plain lines (no file name or
    source line: on the command line they point into pyoa, not at the user)."""
    if issubclass(category, PyoaFallbackWarning):
        print(message, file=sys.stderr if file is None else file)
    else:
        print(warnings.formatwarning(message, category, filename, lineno, line), end="",
              file=sys.stderr if file is None else file)


def _open_closed_streams() -> None:
    """Standard output or error closed when pyoa started (``pyoa ... >&-``): Python makes it None, and
    the command would fail at its first message with nothing written. Its descriptor gets /dev/null
    instead, so that the command runs as with that output discarded, and no file the command opens
    takes descriptor 1 or 2 (where a worker process's output would land in it)."""
    for fd, name in ((1, "stdout"), (2, "stderr")):
        if getattr(sys, name) is not None:
            continue
        try:
            os.fstat(fd)
        except OSError:  # closed: /dev/null takes its number
            devnull = os.open(os.devnull, os.O_WRONLY)
            if devnull != fd:
                os.dup2(devnull, fd)
                os.close(devnull)
        setattr(sys, name, open(fd, "w", closefd=False))  # noqa: SIM115 - the process's own stream


class _ReaderMayLeave:
    """``sys.stdout`` or ``sys.stderr`` while a command runs. When the reader of the pipe has gone
    (``pyoa compare ... | head -1``), or the stream cannot be written (``> /dev/full``), the rest of
    what is written goes to /dev/null and the command carries on, so that the work it finishes still
    reaches its files (the error would end it with nothing written); :func:`main` then ends with the
    status of a tool that SIGPIPE ends, or with one line naming the stream's error."""

    def __init__(self, stream):
        self.stream = stream
        #: whether the reader has gone
        self.gone = False
        #: an error other than a closed pipe met while writing (``ENOSPC``...), said at the end
        self.error: OSError | None = None

    def __getattr__(self, name):
        return getattr(self.stream, name)

    def _guarded(self, call, *args):
        try:
            return call(*args)
        except OSError as exc:
            if isinstance(exc, BrokenPipeError):
                self.gone = True
            elif self.error is None:
                self.error = exc
            # the stream's descriptor goes to /dev/null, so that what is still buffered, and Python's flush
            # at exit, do not fail again (https://docs.python.org/3/library/signal.html#note-on-sigpipe)
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, self.stream.fileno())
            os.close(devnull)
            return call(*args)

    def write(self, text: str) -> int:
        return self._guarded(self.stream.write, text)

    def flush(self) -> None:
        self._guarded(self.stream.flush)


def main(argv: list[str] | None = None) -> int:
    """``pyoa ARGS``: run the command, with a one-line message and status 2 for what it refuses. A
    closed standard output (``| head``) neither stops the command nor makes it say anything: it
    finishes, writes its files and ends with 141 = 128 + SIGPIPE, as a shell reports a tool whose
    reader left. Standard output that cannot be written (a full disk) does not stop it either; it
    ends with one line naming that error and status 2. A stream closed from the start (``>&-``)
    reads as /dev/null."""
    _open_closed_streams()
    out, err = _ReaderMayLeave(sys.stdout), _ReaderMayLeave(sys.stderr)
    sys.stdout, sys.stderr = out, err
    ran: dict = {}
    try:
        status = _main(argv, ran)
    finally:
        out.flush()  # what is still buffered meets a closed pipe here, not in Python's flush at exit
        err.flush()
        sys.stdout, sys.stderr = out.stream, err.stream
    if out.error is not None and not status:
        print(f"pyoa {ran.get('command', '')}: error: cannot write standard output: {out.error.strerror or out.error}"
              " (the command ran to its end; only what it printed is lost)", file=sys.stderr)
        return 2
    return 128 + 13 if out.gone and not status else status  # 13: SIGPIPE


def _main(argv: list[str] | None, ran: dict) -> int:
    ap = build_parser()
    args, unknown = ap.parse_known_args(argv)
    if unknown:  # the command's parser says it, naming the command (the top-level one would say "pyoa")
        args.commands[args.command].error(f"unrecognized arguments: {' '.join(unknown)}")
    ran["command"] = args.command
    args.argv = list(sys.argv[1:] if argv is None else argv)  # what made an image goes into its header
    try:
        with warnings.catch_warnings():
            warnings.showwarning = _show_warning
            return args.func(args)
    except (ValueError, TypeError, OSError, BackendUnavailable, TasksLost) as exc:  # ClusterUnavailable: ValueError
        # OSError: an output that cannot be written (pyoa.util.atomic names the
        # user's path), a missing input file; a one-line message, not a traceback
        ap.exit(2, f"pyoa {args.command}: error: {exc}\n")
    except MemoryError as exc:
        # the memory plans refuse a job over $PYOA_MAX_BYTES before it starts, but they are estimates, and
        # the process may be allowed less than the limit (ulimit -v, a container)
        first = (str(exc).strip().splitlines() or [""])[0]
        ap.exit(2, f"pyoa {args.command}: error: out of memory{f' ({first})' if first else ''}: this job needs more "
                   "memory than the process may use; render a smaller scene, image or sample count, or set "
                   f"${ENV_MAX_BYTES} to the memory available so that such a job is refused before it "
                   "starts\n")
    except KeyboardInterrupt:
        # Ctrl-C, or SIGINT from a job manager: every output is written atomically (pyoa.util.atomic), so none is
        # left half-written; a command's ``interrupted(args)`` says what it kept. 130 = 128 + SIGINT, as a shell
        # reports a process that SIGINT ended.
        kept = getattr(args, "interrupted", None)
        note = kept(args) if kept else "no output is left half-written (each is replaced only by a complete one)"
        ap.exit(130, f"pyoa {args.command}: interrupted; {note}\n")
