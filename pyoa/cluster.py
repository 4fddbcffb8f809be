"""Where pyoa's long jobs run: in-process (the default) or on a Dask cluster.

A render, a reference or a study is a list of independent *tasks* (tiles of
pixels, reference passes, single renders of a study). :func:`engine` gives
the place they run:

* nothing given: :class:`InProcess`, the tasks run one after another in this
  process, exactly as a plain ``pyoa render`` always has (no cluster, no
  extra processes; each task uses every core through the renderer's threads);
* ``workers=N``: a :class:`distributed.LocalCluster` of N worker processes on
  this machine, started for the run and closed after it;
* ``scheduler=ADDRESS`` (or ``$PYOA_SCHEDULER``): an existing Dask cluster,
  e.g. ``tcp://10.0.0.5:8786`` started with ``dask scheduler`` and
  ``dask worker ADDRESS`` on several machines (``docs/distributed.md``). An
  address that is not ``SCHEME://HOST:PORT`` (:func:`check_address`) is
  refused before anything starts; one where no Dask scheduler answers
  within :data:`CONNECT_TIMEOUT` seconds (nothing listening, or something
  that is not a Dask scheduler) is a :class:`ClusterUnavailable` error
  naming it, raised within that time.

Both engines expose :meth:`InProcess.share` (a value many tasks read, sent
once per worker) and :meth:`InProcess.run`, which yields
``(index, result)`` as tasks finish. A task is a plain module-level function
and its arguments; it must not depend on where it runs, which is what makes a
cluster's results bit-identical to the in-process ones. On a cluster a task
that loses its worker is run again elsewhere (Dask reschedules it), and a task
that raises is retried :data:`RETRIES` times before the error reaches the
caller.

References
----------
.. [1] Dask Development Team, "Dask: Library for dynamic task scheduling",
   https://dask.org (``dask.distributed``: Client, LocalCluster, as_completed).
"""

from __future__ import annotations

import contextlib
import logging
import os
from collections.abc import Callable, Iterable, Iterator, Sequence

from .catalogue.entries import check_int

#: Environment variable naming a scheduler to use when ``--scheduler`` is not given.
ENV_SCHEDULER = "PYOA_SCHEDULER"
#: Seconds to wait for a scheduler to answer before giving up.
CONNECT_TIMEOUT = 10
#: Seconds past :data:`CONNECT_TIMEOUT` given to a connection that was
#: accepted to answer (see :func:`_identity`).
HANDSHAKE_GRACE = 0.5
#: The port ``dask scheduler`` listens on unless told otherwise (for suggestions).
DEFAULT_PORT = 8786
#: Times a task that raised is run again on a cluster before its error is final.
RETRIES = 2
#: Most local worker processes (``--workers``): more than this is a typo.
MAX_LOCAL_WORKERS = 1024


class ClusterUnavailable(ValueError):
    """No Dask scheduler answered at the address given (the message names it
    and the timeout, and says how to start one)."""


class TasksLost(RuntimeError):
    """A task whose workers kept dying (Dask's ``KilledWorker``: each time it
    ran, its worker process was lost, e.g. killed for using too much memory)."""


class InProcess:
    """The embedded default: tasks run here, in order, one at a time."""

    #: Human-readable description (for progress lines and reports).
    description = "in-process"
    client = None

    @property
    def slots(self) -> int:
        """Tasks that run at once (1: each uses every core through threads)."""
        return 1

    def task_threads(self) -> int | None:
        """Renderer threads per task (None: every core)."""
        return None

    def share(self, value):
        """``value`` as tasks should receive it: here, the value itself."""
        return value

    def run(self, fn: Callable, args: Sequence[tuple], *, key: str = "pyoa") -> Iterator[tuple[int, object]]:
        """Run ``fn(*args[i])`` for every i, yielding ``(i, result)`` in order.

        Callers close the generator (``contextlib.closing``) before the
        engine, so that an interrupted job's queued tasks are cancelled."""
        for i, a in enumerate(args):
            yield i, fn(*a)

    def close(self) -> None:
        pass


class DaskEngine(InProcess):
    """Tasks on a Dask cluster through a :class:`distributed.Client`."""

    def __init__(self, client, description: str, cluster=None):
        self.client = client
        self.cluster = cluster
        self.description = description
        self._threads = None

    @property
    def slots(self) -> int:
        """Task slots of the cluster: the sum of its workers' threads."""
        return max(1, sum(w.get("nthreads", 1) for w in self._workers().values()))

    def _workers(self) -> dict:
        """Every worker's entry of the scheduler's info (newer Dask lists only
        the first few unless asked for all)."""
        import inspect

        every = {"n_workers": -1} if "n_workers" in inspect.signature(self.client.scheduler_info).parameters else {}
        return self.client.scheduler_info(**every).get("workers", {})

    def task_threads(self) -> int:
        """Renderer threads per task: each host's cores shared by the task
        slots of the workers on it (the fewest over hosts), so that a host's
        tasks together use its cores without oversubscribing them."""
        if self._threads is None:
            cores = self.client.run(os.cpu_count)  # {worker address: cores of its host}
            slots: dict[str, int] = {}
            host_cores: dict[str, int] = {}
            for addr, w in self._workers().items():
                host = w.get("host", addr)
                slots[host] = slots.get(host, 0) + int(w.get("nthreads", 1))
                host_cores[host] = int(cores.get(addr) or 1)
            self._threads = max(1, min((host_cores[h] // slots[h] for h in slots), default=1))
        return self._threads

    def share(self, value):
        """``value`` sent once to every worker (a Dask future that tasks
        receive as the value): a scene or a reference image that many tasks
        read travels once per worker, not once per task."""
        return self.client.scatter([value], broadcast=True, hash=False)[0]

    def run(self, fn, args, *, key="pyoa"):
        """Submit every task at once and yield ``(i, result)`` as they finish.

        A task that raised is retried :data:`RETRIES` times; if it still
        fails, its error is raised here and the tasks not yet finished are
        cancelled."""
        from distributed import KilledWorker, as_completed

        futures = {}
        for i, a in enumerate(args):
            fut = self.client.submit(fn, *a, key=f"{key}-{i}-{_token(fn, a)}", retries=RETRIES, pure=False)
            futures[fut] = i
        try:
            for fut in as_completed(futures, loop=self.client.loop):
                try:
                    result = fut.result()
                except KilledWorker as exc:
                    raise TasksLost(f"task {futures[fut]} of {len(futures)} lost its worker every time it ran "
                                    f"({exc}); a worker process that dies on one task (memory?) is not retried "
                                    "forever: check the workers' logs") from None
                yield futures[fut], result
        finally:  # an error or an interruption: the tasks still queued stop
            if self.client.status == "running":
                self.client.cancel(list(futures))

    def close(self) -> None:
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def _token(fn, a) -> str:
    """A key for the task ``fn(*a)``: unique per call (futures are not hashed by value)."""
    import uuid

    return f"{fn.__name__}-{uuid.uuid4().hex[:12]}"


def resolve_scheduler(scheduler: str | None) -> str | None:
    """``scheduler``, else ``$PYOA_SCHEDULER``, else None (in-process); an
    address must be ``SCHEME://HOST:PORT`` such as ``tcp://host:8786``
    (:func:`check_address`)."""
    if scheduler is None:
        scheduler = os.environ.get(ENV_SCHEDULER) or None
        origin = f"${ENV_SCHEDULER}"
    else:
        origin = "--scheduler"
    if scheduler is None:
        return None
    if not isinstance(scheduler, str) or not scheduler.strip():
        raise ValueError(f"{origin} must be a scheduler address such as tcp://10.0.0.5:8786, got {scheduler!r}")
    return check_address(scheduler.strip(), origin)


def check_address(address: str, origin: str = "--scheduler") -> str:
    """``address`` checked as one distributed can connect to, with its scheme.

    ``SCHEME://HOST:PORT`` with a scheme of distributed's comm registry
    (``tcp``, ``tls``, ``ws``, ``wss``, ``ucx``; ``inproc`` addresses are
    taken as they are); ``HOST:PORT`` alone is ``tcp://HOST:PORT``
    (distributed's default scheme). Nothing is connected to: a bare host,
    an empty one or a scheme that does not exist is refused before the
    connection attempt, which would otherwise fail only after its timeout.

    Raises
    ------
    ValueError
        The address is none of those forms; the message names ``origin``
        (``--scheduler`` or ``$PYOA_SCHEDULER``) and, for a bare host, the
        address with dask's default port.
    """
    from distributed.comm import registry
    from distributed.comm.addressing import parse_address, parse_host_port, unparse_address

    form = (f"a scheduler address is SCHEME://HOST:PORT such as tcp://10.0.0.5:{DEFAULT_PORT}, SCHEME one of "
            f"{', '.join(sorted(registry.backends))}")
    scheme, loc = parse_address(address)
    if scheme not in registry.backends:
        raise ValueError(f"{origin} {address!r} has an unknown scheme {scheme!r}; {form}")
    if scheme != "inproc":
        try:
            host, port = parse_host_port(loc, default_port=-1)  # -1: no port given
        except ValueError as exc:
            raise ValueError(f"{origin} {address!r} is not HOST:PORT ({exc}); {form}") from None
        if not host:
            raise ValueError(f"{origin} {address!r} has no host; {form}")
        if port == -1:
            raise ValueError(f"{origin} {address!r} has no port; a scheduler listens on {DEFAULT_PORT} unless told "
                             f"otherwise: {scheme}://{loc}:{DEFAULT_PORT}")
        if not 1 <= port <= 65535:
            raise ValueError(f"{origin} {address!r} has port {port}, outside [1, 65535]; {form}")
    elif not loc:
        raise ValueError(f"{origin} {address!r} has no location; {form}")
    return unparse_address(scheme, loc)


def check_engine(workers: int | None = None, scheduler: str | None = None) -> tuple[int | None, str | None]:
    """Validate ``workers`` and ``scheduler`` (one at most) without starting anything."""
    if workers is not None:
        workers = check_int("--workers", workers, 1, MAX_LOCAL_WORKERS, " (local worker processes)")
    if workers is not None and scheduler is not None:
        raise ValueError("give --workers (a local cluster started for this run) or --scheduler (an existing "
                         "cluster), not both")
    scheduler = None if workers is not None else resolve_scheduler(scheduler)
    return workers, scheduler


def _identity(address: str, timeout: float) -> dict:
    """What the Dask server at ``address`` says it is (its ``identity``:
    ``{"type": "Scheduler", ...}``), asked within ``timeout`` seconds.

    A probe before any :class:`distributed.Client` exists: a Client whose
    connection fails is left half-built, and its ``__del__`` later waited 20
    s and printed a traceback; and the connection's handshake has no
    timeout of its own (a port where something else listens held a Client
    for a minute). Run in a thread of its own, so that it works whether or
    not the caller runs an event loop.

    Raises
    ------
    ClusterUnavailable
        Nothing accepted a connection within ``timeout`` seconds, or what
        did gave no Dask identity within :data:`HANDSHAKE_GRACE` more (the
        message says which).
    """
    import asyncio
    from concurrent.futures import ThreadPoolExecutor

    from distributed.comm import connect
    from distributed.security import Security

    async def ask():
        # connect() retries until `timeout` and then raises OSError (nothing
        # accepted a connection); its handshake that follows has no bound
        comm = await connect(address, timeout=timeout, **Security().get_connection_args("client"))
        try:
            await comm.write({"op": "identity", "reply": True})
            return await comm.read()
        finally:
            await comm.close()

    def run():
        # HANDSHAKE_GRACE more than connect's own limit: an OSError of
        # connect() reaches us as such, a hung handshake as the timeout
        return asyncio.run(asyncio.wait_for(ask(), timeout + HANDSHAKE_GRACE))

    refused = _refused(address, timeout)
    if refused:
        raise ClusterUnavailable(f"no Dask scheduler answered at {address!r}: {refused}; "
                                 + _START_ONE.replace("ADDRESS", address))
    try:
        with ThreadPoolExecutor(1) as pool:
            info = pool.submit(run).result()
    except (asyncio.TimeoutError, TimeoutError):
        raise _unavailable(address, timeout + HANDSHAKE_GRACE, "something accepted the connection but did not "
                           "answer as a Dask scheduler does: is it the scheduler's port?") from None
    except OSError as exc:  # refused, unreachable, unknown host, closed: distributed's reason
        raise _unavailable(address, timeout, (str(exc).strip().splitlines() or [type(exc).__name__])[0]) from None
    except Exception as exc:  # noqa: BLE001 - whatever a decoder raises on bytes that are not Dask's messages
        raise _unavailable(address, timeout, f"what answered does not speak Dask's protocol: it sent bytes that "
                                             f"are not Dask messages ({type(exc).__name__})") from None
    return info if isinstance(info, dict) else {}


def _refused(address: str, timeout: float) -> str | None:
    """Why nothing can answer at the TCP (``tcp``, ``tls``) ``address``, known at once: the connection
    is refused (nothing listens on its port). None when something accepts it, or for another reason
    (unreachable, unknown host, timed out, another scheme), which distributed's own attempt then says.

    distributed retries a refused connection until its timeout (a scheduler may be starting), which
    held a mistyped port for the whole :data:`CONNECT_TIMEOUT`; a scheduler that starts after pyoa
    asked is not waited for."""
    import socket

    from distributed.comm.addressing import parse_address, parse_host_port

    scheme, loc = parse_address(address)
    if scheme not in ("tcp", "tls"):
        return None
    host, port = parse_host_port(loc)
    try:
        socket.create_connection((host, port), timeout=timeout).close()
    except ConnectionRefusedError:
        return f"connection refused: nothing listens on port {port} of {host}"
    except OSError:
        return None
    return None


#: How to get a scheduler, the end of every :class:`ClusterUnavailable` message.
_START_ONE = ("start one with `dask scheduler` and workers with `dask worker ADDRESS`, or run in-process without "
              f"--scheduler (and unset ${ENV_SCHEDULER})")


def _unavailable(address: str, timeout: float, reason: str) -> ClusterUnavailable:
    return ClusterUnavailable(f"no Dask scheduler answered at {address!r} within {timeout:g} s ({reason}); "
                              + _START_ONE.replace("ADDRESS", address))


def _connect(address: str, timeout: float):
    """A Client of the scheduler at ``address``, once :func:`_identity` has
    found one there (see it for why)."""
    try:
        import dask
        from distributed import Client
    except ImportError as exc:  # pragma: no cover - dask is a dependency
        raise ImportError('running on a cluster needs Dask: pip install "dask[distributed]"') from exc
    kind = _identity(address, timeout).get("type")
    if kind != "Scheduler":
        raise ClusterUnavailable(
            f"{address!r} is a Dask {kind or 'server'}, not a scheduler; give the address that `dask scheduler` "
            f"prints (port {DEFAULT_PORT} unless told otherwise), or run in-process without --scheduler (and "
            f"unset ${ENV_SCHEDULER})")
    try:
        with dask.config.set({"distributed.comm.timeouts.connect": timeout}):
            return Client(address, timeout=timeout, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:  # the scheduler went away since it answered
        raise _unavailable(address, timeout, (str(exc).strip().splitlines() or [type(exc).__name__])[0]) from None


@contextlib.contextmanager
def engine(workers: int | None = None, scheduler: str | None = None, *,
           timeout: float | None = None) -> Iterator[InProcess]:
    """The engine for a job (see the module docstring), closed on exit.

    Parameters
    ----------
    workers : int, optional
        Start a local cluster of this many worker processes (one thread each).
    scheduler : str, optional
        Address of an existing scheduler (default ``$PYOA_SCHEDULER``).
    timeout : float, optional
        Seconds to wait for the scheduler (default :data:`CONNECT_TIMEOUT`).

    Raises
    ------
    ValueError
        Both given, or a count out of range.
    ClusterUnavailable
        Nothing answers at ``scheduler`` within ``timeout`` seconds.
    """
    workers, scheduler = check_engine(workers, scheduler)
    if workers is None and scheduler is None:
        eng = InProcess()
    elif workers is not None:
        from distributed import Client

        cluster = _local_cluster(workers)
        eng = DaskEngine(Client(cluster, set_as_default=False),
                         f"a local cluster of {workers} worker process{'es' * (workers != 1)}", cluster)
    else:
        client = _connect(scheduler, CONNECT_TIMEOUT if timeout is None else timeout)
        eng = DaskEngine(client, f"the cluster at {scheduler}")
        n = len(eng._workers())
        eng.description += f" ({n} worker{'s' * (n != 1)})"
    try:
        yield eng
    except BaseException:
        # an interruption or an error: what the cluster logs as it stops the tasks pyoa cancelled (a
        # worker still busy is killed after a few seconds) is no news; pyoa's own line says what happened
        from distributed.utils import silence_logging_cmgr

        with silence_logging_cmgr(logging.CRITICAL + 1):
            eng.close()
        raise
    eng.close()


def _local_cluster(workers: int):
    """A :class:`distributed.LocalCluster` of ``workers`` processes that Ctrl-C does not reach.

    A terminal's Ctrl-C signals every process of the foreground job, the worker processes too: each
    would print a traceback of its own. SIGINT is blocked in this thread while the cluster starts, so
    that the thread running its event loop and the processes it spawns inherit the blocked signal
    (the mask survives fork and exec); this process gets a Ctrl-C of that time once it is unblocked.
    The workers import this module as their preload (:func:`dask_setup`)."""
    import signal
    import threading

    from distributed import LocalCluster

    hold = threading.current_thread() is threading.main_thread() and hasattr(signal, "pthread_sigmask")
    if hold:
        from multiprocessing import resource_tracker

        # multiprocessing's resource tracker unblocks SIGINT in the thread that starts it, which would be the
        # cluster's event loop as it spawns the first worker: started here, before the block, it is running then
        resource_tracker.ensure_running()
    cluster = None
    try:
        previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT}) if hold else None
        try:
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                                   preload=[__name__])
        finally:
            if hold:
                signal.pthread_sigmask(signal.SIG_SETMASK, previous)  # a Ctrl-C held meanwhile is raised now
    except BaseException:
        if cluster is not None:
            cluster.close()
        raise
    return cluster


def dask_setup(worker) -> None:
    """Run by distributed in each worker process of :func:`_local_cluster` as it starts (a preload):
    a task that pyoa cancels (Ctrl-C, an error) is the client's decision, not news for the user, so
    the workers' state machine, whose only warning is that one, logs errors only."""
    logging.getLogger("distributed.worker.state_machine").setLevel(logging.ERROR)


def add_arguments(parser) -> None:
    """``--workers`` and ``--scheduler`` on a command's parser."""
    g = parser.add_mutually_exclusive_group()
    g.add_argument("--workers", type=int, default=None, metavar="N",
                   help="run on a local Dask cluster of N worker processes started for this run")
    g.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help=f"run on an existing Dask cluster, e.g. tcp://10.0.0.5:8786 (default ${ENV_SCHEDULER}; "
                        "neither: in-process)")


def progress_over(results: Iterable, total: int, desc: str, quiet: bool, unit: str = "task"):
    """``results`` with a progress bar of ``total`` steps (:func:`pyoa.util.progress.bar`; none when ``quiet``)."""
    from .util.progress import bar as progress_bar

    with progress_bar(total=total, desc=desc, unit=unit, disable=quiet) as bar:
        for r in results:
            yield r
            bar.update(1)
