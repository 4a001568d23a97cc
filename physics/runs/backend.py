"""Where batches of drops run: in this process (``local``) or on a Ray cluster (``ray``).

A batch (a study, a sweep) is cut into chunks of :class:`physics.runs.sweep.Run` s; each chunk is
simulated by :func:`physics.runs.sweep.run_chunk` in one process, the only function a backend calls:

* ``local`` runs the chunks one after the other in this process (``run_chunk`` spreads a chunk
  over ``--jobs`` threads);
* ``ray`` sends one Ray task per chunk (``num_cpus=1``, one thread; spread over the nodes) to
  the cluster at ``--address`` (default: a Ray started on this machine for the run), collects
  the chunks as they finish (``ray.wait``) and re-runs a chunk whose worker or node died
  (``max_retries``).

A task carries only picklable values: the chunk's runs (scene name, overrides, labels), the
``evaluate`` function by reference and the thread count; only the per-drop metrics come back.
Every finished drop goes to a :class:`physics.runs.store.DropStore` at once, so a killed worker
(Ray re-runs its chunk) or a killed driver (``--resume``) loses nothing. Ray is imported only
here and only for ``--backend ray``: the package works without the ``cluster`` extra.
"""
from __future__ import annotations

import ipaddress
import math
import os
import socket
import statistics
import sys
import tempfile
from collections import Counter
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any, Callable, Iterator, Sequence

from . import UsageError
from .sweep import Evaluate, Outcome, Run, _bar, _tick, run_chunk

BACKENDS = ("local", "ray")
INSTALL = 'python3 -m pip install -e ".[cluster]"'
CONNECT_TIMEOUT_S = 3.0          # an address that does not answer within this fails at once
#: while joining a cluster at an address: a cluster that refuses us (a wrong token) fails after a
#: few seconds (ray.init retries ~20 s)
CONNECT_ENV = {"RAY_gcs_server_port_wait_time_s": "3"}
TASK_CPUS = 1                    # CPUs (and threads) of one Ray task
TASKS_PER_CPU = 4                # chunks per cluster CPU: load balance vs per-task overhead
MAX_RETRIES = 3                  # re-runs of a chunk whose worker or node died


class BackendError(UsageError):
    """The backend cannot be used or a task failed beyond its retries (one line, exit 2)."""


@dataclass(frozen=True)
class Backend:
    """``local`` or ``ray`` (with the cluster ``address``; None: ``RAY_ADDRESS`` or a Ray
    started on this machine for the run)."""
    name: str = "local"
    address: str | None = None

    def __post_init__(self):
        if self.name not in BACKENDS:
            raise UsageError(f"--backend must be one of {', '.join(BACKENDS)}, got {self.name!r}")
        if self.address is not None and self.name != "ray":
            raise UsageError(f"--address {self.address} needs --backend ray")

    @classmethod
    def from_args(cls, args) -> "Backend":
        return cls(getattr(args, "backend", "local"), getattr(args, "address", None))

    def session(self) -> "Session":
        return RaySession(self.address) if self.name == "ray" else Session()


def add_backend_args(p, resume: bool = True, jobs: bool = False) -> None:
    """``--backend``, ``--address`` (and ``--resume``) for a command that runs batches
    (``jobs``: the command has ``--jobs``, the local backend's threads)."""
    local = "this process, --jobs threads" if jobs else "this process, one after the other"
    p.add_argument("--backend", choices=BACKENDS, default="local",
                   help=f"where the drops run: local ({local}) or ray (a Ray cluster: one task "
                        "per chunk of drops; needs the cluster extra)")
    p.add_argument("--address", default=None, metavar="HOST:PORT",
                   help="Ray cluster to connect to (with --backend ray; default: RAY_ADDRESS, or "
                        "a Ray started on this machine for the run)")
    if resume:
        p.add_argument("--resume", action="store_true",
                       help="keep the drops already finished in --out (an interrupted run of the "
                            "same command) and run only the missing ones")


# ------------------------------------------------------------------------------ sessions --
class Session:
    """Runs tasks in this process, one after the other (the ``local`` backend)."""
    name = "local"

    def __enter__(self) -> "Session":
        return self

    def __exit__(self, *exc) -> None:
        pass

    def cpus(self) -> int:
        from .sweep import available_cores
        return available_cores()

    def imap(self, fn: Callable, tasks: Sequence[tuple], num_cpus: int = TASK_CPUS
             ) -> Iterator[tuple[int, Any]]:
        """``(i, fn(*tasks[i]))`` for every task, as each finishes."""
        for i, args in enumerate(tasks):
            yield i, fn(*args)

    def describe(self) -> dict:
        return dict(backend=self.name)


class RaySession(Session):
    """One Ray task per call of ``fn``; results as they finish (``ray.wait``)."""
    name = "ray"

    def __init__(self, address: str | None):
        self.address = address or os.environ.get("RAY_ADDRESS") or None
        self.started = False
        self.sent: list[int] = []                      # pickled bytes of each task's arguments
        self.ran_on: dict[int, str] = {}               # task index -> node that finished it

    def __enter__(self) -> "RaySession":
        quiet = {} if self.address in (None, "local", "auto") else CONNECT_ENV
        saved = {k: os.environ.get(k) for k in quiet}
        os.environ.update(quiet)
        try:
            try:
                import ray
            except ImportError:
                raise BackendError(f"--backend ray needs Ray, which is not installed: {INSTALL}") from None
            if ray.is_initialized():                       # inside a Ray program: use its Ray
                self.address = self.address or "the running Ray"
            else:
                self._connect(ray, hint=bool(quiet))
                self.started = True
        finally:
            for k, v in saved.items():
                if v is None:
                    os.environ.pop(k, None)
                else:
                    os.environ[k] = v
        self.at_start = dict(nodes=sum(1 for n in ray.nodes() if n.get("Alive")), cpus=self.cpus())
        return self

    def _connect(self, ray, hint: bool) -> None:
        kwargs: dict[str, Any] = dict(logging_level="ERROR", configure_logging=True)
        if self.address in (None, "local"):
            kwargs.update(include_dashboard=False)
        elif self.address != "auto":
            host = probe(self.address)
            if not self.address.startswith("ray://") and _is_loopback(host):
                kwargs["_node_ip_address"] = host         # a node of this machine: its address
        try:
            with _quiet_stderr(hint):       # Ray's C++ client warns once per retry
                ray.init(address=self.address, **kwargs)
        except Exception as exc:                          # ConnectionError, AuthenticationError...
            where = f"the Ray cluster at {self.address}" if self.address else "a local Ray"
            raise BackendError(f"--backend ray: cannot connect to {where}: {first_line(exc)}"
                               + (_token_hint() if hint else "")) from None

    def __exit__(self, *exc) -> None:
        if self.started:                                  # only a Ray this session started
            import ray
            ray.shutdown()

    def cpus(self) -> int:
        import ray
        return max(1, int(ray.cluster_resources().get("CPU", 1)))

    def imap(self, fn: Callable, tasks: Sequence[tuple], num_cpus: int = TASK_CPUS
             ) -> Iterator[tuple[int, Any]]:
        import ray
        from ray import cloudpickle
        remote = ray.remote(num_cpus=num_cpus, max_retries=MAX_RETRIES,
                            scheduling_strategy="SPREAD")(on_node)
        pending = {}
        for i, args in enumerate(tasks):
            self.sent.append(len(cloudpickle.dumps(args)))
            pending[remote.remote(fn, *args)] = i
        while pending:
            done, _ = ray.wait(list(pending), num_returns=1)
            for ref in done:
                i = pending.pop(ref)
                try:
                    node, result = ray.get(ref)
                except ray.exceptions.RayError as exc:
                    for other in pending:
                        ray.cancel(other, force=True)
                    cause = getattr(exc, "cause", None)
                    if isinstance(exc, ray.exceptions.RayTaskError) and isinstance(cause, Exception):
                        raise cause from None             # the task's own error, as if local
                    raise BackendError(f"--backend ray: task {i} failed (retried up to "
                                       f"{MAX_RETRIES} times): {first_line(exc)}") from None
                self.ran_on[i] = node
                yield i, result

    def describe(self) -> dict:
        """Backend, address, nodes and CPUs at the start, tasks (per node that finished them)
        and the pickled bytes of a task's arguments."""
        return dict(backend=self.name, address=self.address, **self.at_start, tasks=len(self.sent),
                    tasks_per_node=dict(sorted(Counter(self.ran_on.values()).items())),
                    bytes_per_task=dict(median=statistics.median(self.sent), max=max(self.sent))
                    if self.sent else None)


def on_node(fn: Callable, *args) -> tuple[str, Any]:
    """A Ray task: ``fn(*args)`` and the address of the node that ran it."""
    import ray
    return ray.util.get_node_ip_address(), fn(*args)


def probe(address: str, timeout: float = CONNECT_TIMEOUT_S) -> str:
    """The host of ``address`` (``HOST:PORT`` or ``ray://HOST:PORT``) once something answers
    there; a one-line BackendError when nothing does within ``timeout`` (``ray.init`` itself
    would retry for minutes)."""
    hostport = address.removeprefix("ray://")
    host, _, port = hostport.rpartition(":")
    if not host or not port.isdigit():
        raise BackendError(f"--address must be HOST:PORT or ray://HOST:PORT, got {address!r}")
    try:
        with socket.create_connection((host.strip("[]"), int(port)), timeout=timeout):
            pass
    except OSError as exc:
        reason = "no answer" if isinstance(exc, TimeoutError) else (exc.strerror or str(exc))
        raise BackendError(f"--address {address}: no Ray cluster reachable there ({reason} "
                           f"within {timeout:g} s)") from None
    return host.strip("[]")


def _is_loopback(host: str) -> bool:
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return host == "localhost"


@contextmanager
def _quiet_stderr(enabled: bool):
    """File descriptor 2 to a scratch file while ``enabled`` (the error is reported instead)."""
    if not enabled:
        yield
        return
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile() as sink:
        os.dup2(sink.fileno(), 2)
        try:
            yield
        finally:
            os.dup2(saved, 2)
            os.close(saved)


def _token_hint() -> str:
    """Something answers at the address but Ray does not let us in: most often the token."""
    if os.environ.get("RAY_AUTH_MODE", "").lower() == "token" and os.environ.get("RAY_AUTH_TOKEN"):
        return " (is RAY_AUTH_TOKEN the cluster's token?)"
    return (" (a cluster with token authentication needs RAY_AUTH_MODE=token and its token in "
            "RAY_AUTH_TOKEN here too)")


def first_line(exc: BaseException) -> str:
    lines = [l.strip() for l in str(exc).splitlines() if l.strip()]
    return f"{type(exc).__name__}: {lines[0] if lines else ''}"


# ------------------------------------------------------------------------------- batches --
@dataclass
class Dispatch:
    """How a batch ran: the backend's description (:meth:`Session.describe`: tasks, nodes,
    bytes sent per task) and the drops resumed from disk."""
    backend: dict = field(default_factory=dict)
    drops: int = 0
    resumed: int = 0

    def note(self) -> str:
        """One line for the command's output ("" for a plain local run)."""
        parts = []
        if self.resumed:
            parts.append(f"{self.resumed} of {self.drops} drops resumed from disk")
        b = self.backend
        if b.get("backend") == "ray":
            sent = b.get("bytes_per_task")
            parts.append(f"ray: {b['tasks']} task(s) on {b['nodes']} node(s), {b['cpus']} CPU(s)"
                         + (f", {sent['median'] / 1e3:.1f} kB sent per task (median)" if sent else ""))
        return "note: " + "; ".join(parts) if parts else ""


def chunk_task(runs: list[Run], evaluate: Evaluate | None, threads: int) -> list[dict]:
    """The body of one Ray task: a chunk of drops in one process, as JSON-ready records."""
    return [record(o) for o in run_chunk(runs, evaluate, threads=threads)]


def record(o: Outcome) -> dict:
    """What is kept of a drop (its run is known from the plan): ok, metrics, extra, error."""
    return dict(ok=o.ok, metrics=o.metrics, extra=o.extra, error=o.error)


def plan_threads(backend: Backend, jobs: int | None, runs: int) -> tuple[int | None, str]:
    """Threads of the local backend (:func:`physics.runs.sweep.plan_jobs`) and its note; on Ray every
    task takes one CPU and the cluster's CPUs set the parallelism, so ``--jobs`` is refused."""
    if backend.name == "local":
        from .sweep import plan_jobs
        return plan_jobs(jobs, runs)
    if jobs is not None:
        raise UsageError("--jobs sets the threads of --backend local; with --backend ray every "
                         "task takes one CPU and the cluster's CPUs set the parallelism")
    return None, ""


def run_drops(runs: Sequence[Run], evaluate: Evaluate | None = None, backend: Backend = Backend(),
              jobs: int | None = None, out=None, resume: bool = False, desc: str = "drops",
              progress: bool = True) -> tuple[list[Outcome], Dispatch]:
    """Simulate ``runs`` on ``backend``; outcomes in input order and how they ran.

    With ``out`` every drop is written to ``out/drops`` as it finishes
    (:class:`physics.runs.store.DropStore`); with ``resume`` the drops already there are kept and
    only the missing ones run. Each outcome is read back from its JSON record, so both backends
    (and a resumed run) return identical numbers.
    """
    from .store import DropStore
    runs = list(runs)
    store = (DropStore.open(out, runs, evaluate, desc, resume) if out is not None
             else DropStore.memory(runs))
    todo = store.missing()
    info = Dispatch(drops=len(runs), resumed=len(runs) - len(todo))
    bar = None
    try:
        if todo:
            with backend.session() as session:
                store.begin()
                bar = _bar(progress, len(runs), desc)
                if bar is not None:
                    bar.update(info.resumed)
                if session.name == "local":
                    _run_local(runs, todo, evaluate, jobs, store, bar)
                else:
                    _run_remote(session, runs, todo, evaluate, store, bar)
                info.backend = session.describe()
        else:
            info.backend = dict(backend=backend.name)
    finally:
        if bar is not None:
            bar.close()
        store.close()
    return [Outcome(run, **rec) for run, rec in zip(runs, store.records())], info


def _run_local(runs, todo: list[int], evaluate, jobs, store, bar) -> None:
    def done(i: int, outcome: Outcome) -> None:
        store.add(todo[i], record(outcome))
        _tick(bar, outcome)
    run_chunk([runs[i] for i in todo], evaluate, threads=jobs, on_outcome=done)


def _run_remote(session: "RaySession", runs, todo: list[int], evaluate, store, bar) -> None:
    size = max(1, math.ceil(len(todo) / (TASKS_PER_CPU * session.cpus())))
    chunks = [todo[k:k + size] for k in range(0, len(todo), size)]
    tasks = [([runs[i] for i in c], evaluate, TASK_CPUS) for c in chunks]
    for k, records in session.imap(chunk_task, tasks):
        for i, rec in zip(chunks[k], records):
            store.add(i, rec, node=session.ran_on.get(k))
            _tick(bar, Outcome(runs[i], **rec))
        store.sync()
