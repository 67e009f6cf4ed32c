# Copyright 2026 The hyst_id authors
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""Seeds in worker processes that end when asked, and with their parent.

:func:`map_in_processes` runs a function over argument tuples in a process
pool and hands back the results in input order. It looks at ``should_stop``
every :data:`POLL_S` and, when it holds (or anything goes wrong), ends the
workers at once instead of waiting for the running tasks. Each worker
ignores SIGINT (Ctrl-C is the parent's to handle) and, on Linux, is sent
SIGTERM by the kernel when its parent dies (``PR_SET_PDEATHSIG``), so a
parent killed outright leaves no worker behind. In the parent, when called
from the main thread with Python's default Ctrl-C handler, a SIGINT is only
noted while the pool runs and raised as :class:`KeyboardInterrupt` at the
next poll: raised asynchronously it can land while the executor holds one of
its locks, and ending the pool then deadlocks (seen once in 100 stops under
load by ``bench/stop_stress.py``). :func:`forked_pool` defers Ctrl-C the
same way: its :meth:`ForkedPool.result` waits in polls and raises it there.
"""

from __future__ import annotations

from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
import ctypes
import multiprocessing
import os
import signal
import sys
import threading
from typing import Any, Callable, Iterable, Iterator, Sequence

from threadpoolctl import threadpool_limits

from hyst_id.errors import IdentificationError

__all__ = ['POLL_S', 'ForkedPool', 'WorkersStopped', 'forked_pool', 'map_in_processes',
           'mp_context', 'n_processes']

#: How often a stop request is looked at while workers run [s].
POLL_S = 0.2
_PR_SET_PDEATHSIG = 1


class WorkersStopped(IdentificationError):
    """The workers were ended because ``should_stop`` held."""


def mp_context() -> Any:
    """Fork where it is safe (no other threads, POSIX), spawn otherwise.

    Fork needs no ``if __name__ == '__main__'`` guard in user scripts and
    reuses the compiled numba kernels; with threads running (a ROS
    executor) only spawn is safe.
    """
    if 'fork' in multiprocessing.get_all_start_methods() and threading.active_count() == 1:
        return multiprocessing.get_context('fork')
    return multiprocessing.get_context('spawn')


def n_processes(workers: int, n_tasks: int) -> int:
    """Processes for ``n_tasks`` tasks: ``workers`` (0: one per core), at most one per task.

    At least one (the calling process), also for no task.
    """
    return max(1, min(workers or (os.cpu_count() or 1), n_tasks))


def _worker_init(parent_pid: int) -> None:
    """Leave Ctrl-C to the parent; die with it (Linux)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if sys.platform.startswith('linux'):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, signal.SIGTERM, 0, 0, 0)
        except (OSError, AttributeError):  # pragma: no cover - exotic libc
            pass
    if os.getppid() != parent_pid:      # the parent died before prctl took effect
        os._exit(1)


def _end(pool: ProcessPoolExecutor) -> None:
    """Stop ``pool`` now: drop queued tasks and terminate the running workers.

    The executor's task queue is fed by a thread that is usually blocked
    writing the next task into the pipe to the busy workers (seen in every
    thread dump of a running pool); once they are gone nobody reads it, and
    on Linux CPython 3.11 closes that pipe only when it notices a broken pool
    first (``terminate_broken``), not on the shutdown path. So the queue's
    thread is not waited for and the pipe's read end is closed here: a write
    then fails instead of being able to hold up the interpreter's exit.
    """
    processes = list(getattr(pool, '_processes', {}).values())
    call_queue = getattr(pool, '_call_queue', None)
    if call_queue is not None:
        call_queue.cancel_join_thread()
    pool.shutdown(wait=False, cancel_futures=True)
    for proc in processes:
        if proc.is_alive():
            proc.terminate()
    for proc in processes:
        proc.join(2.0)
        if proc.is_alive():
            proc.kill()
    reader = getattr(call_queue, '_reader', None)
    if reader is not None:
        try:
            reader.close()
        except OSError:  # pragma: no cover - already closed by the executor
            pass


@contextmanager
def _sigint_deferred() -> Iterator[Callable[[], bool]]:
    """Note Ctrl-C instead of raising it where it lands (main thread, default handler only)."""
    if (threading.current_thread() is not threading.main_thread()
            or signal.getsignal(signal.SIGINT) is not signal.default_int_handler):
        yield lambda: False
        return
    hits: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: hits.append(signum))
    try:
        yield lambda: bool(hits)
    finally:
        signal.signal(signal.SIGINT, previous)


def map_in_processes(fn: Callable[..., Any], arg_tuples: Sequence[tuple], n_workers: int, *,
                     on_result: Callable[[Any], None] | None = None,
                     should_stop: Callable[[], bool] | None = None) -> list[Any]:
    """``[fn(*args) for args in arg_tuples]`` in ``n_workers`` processes, in input order.

    Parameters
    ----------
    fn : callable
        A module-level function (picklable).
    arg_tuples : sequence of tuple
        Its arguments, one tuple per task.
    n_workers : int
        Worker processes.
    on_result : callable, optional
        Called with each result as it completes (in completion order); an
        exception it raises ends the workers and propagates.
    should_stop : callable, optional
        Looked at every :data:`POLL_S`; when it returns true the workers are
        ended and :class:`WorkersStopped` is raised.

    Raises
    ------
    IdentificationError
        A worker process died.
    """
    # Limit BLAS threads in the parent too: forked children inherit its pools.
    with threadpool_limits(limits=1), _sigint_deferred() as interrupted:
        pool = ProcessPoolExecutor(max_workers=n_workers, mp_context=mp_context(),
                                   initializer=_worker_init, initargs=(os.getpid(),))
        with _ended_on_error(pool):
            futures: list[Future] = [pool.submit(fn, *args) for args in arg_tuples]
            pending = set(futures)
            while pending:
                if interrupted():
                    raise KeyboardInterrupt
                finished, pending = wait(pending, timeout=POLL_S, return_when=FIRST_COMPLETED)
                for fut in finished:
                    if on_result is not None:
                        on_result(fut.result())
                if should_stop is not None and should_stop():
                    raise WorkersStopped('stopped on request; worker processes ended')
            if interrupted():
                raise KeyboardInterrupt
            results = [f.result() for f in futures]
        pool.shutdown(wait=True)
        return results


@contextmanager
def _ended_on_error(pool: ProcessPoolExecutor) -> Iterator[ProcessPoolExecutor]:
    """End ``pool``'s workers at once when the block raises; a dead worker is reported."""
    try:
        yield pool
    except BrokenProcessPool as exc:
        _end(pool)
        raise IdentificationError(f'a worker process died: {exc}') from None
    except BaseException:
        _end(pool)
        raise


class ForkedPool(ProcessPoolExecutor):
    """A process pool whose :meth:`result` raises a deferred Ctrl-C at its next poll.

    What :func:`forked_pool` yields. Wait for a task with ``pool.result(future)``,
    not ``future.result()``: while the pool is open a Ctrl-C is only noted
    (as in :func:`map_in_processes`), so that it cannot land while the
    executor holds a lock, and :meth:`result` raises it.
    """

    def __init__(self, *args: Any, interrupted: Callable[[], bool], **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._interrupted = interrupted
        self._futures: list[Future] = []

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Future:
        """:meth:`ProcessPoolExecutor.submit`, the future kept for :meth:`drain`."""
        future = super().submit(fn, *args, **kwargs)
        self._futures.append(future)
        return future

    def drain(self) -> None:
        """Drop the queued tasks and wait for the running ones in polls (Ctrl-C raised)."""
        for future in self._futures:
            future.cancel()
        self._wait_all(self._futures)

    def result(self, future: Future) -> Any:
        """``future.result()``, raising a noted Ctrl-C as :class:`KeyboardInterrupt` first."""
        self._wait_all([future])
        return future.result()

    def _wait_all(self, futures: Iterable[Future]) -> None:
        """Wait for ``futures`` in polls of :data:`POLL_S`; a noted Ctrl-C is raised."""
        left = {f for f in futures if not f.done()}
        while left:
            if self._interrupted():
                raise KeyboardInterrupt
            _, left = wait(left, timeout=POLL_S)
        if self._interrupted():
            raise KeyboardInterrupt


@contextmanager
def forked_pool(n_workers: int) -> Iterator[ForkedPool | None]:
    """A pool of ``n_workers`` forked processes for a loop that submits as it goes.

    Yields ``None`` when a pool would not pay: one worker, or no safe fork
    (threads running: spawning would cost seconds of imports per pool). On
    leaving, queued tasks are dropped; on an error (also Ctrl-C or a stop
    request raised by the loop) the workers are ended at once. Submitted
    functions run with one BLAS thread, as the seeds' do. While the pool is
    open a Ctrl-C in the main thread is noted and raised by
    :meth:`ForkedPool.result`, or on leaving the block.
    """
    ctx = mp_context()
    if n_workers < 2 or ctx.get_start_method() != 'fork':
        yield None
        return
    with threadpool_limits(limits=1), _sigint_deferred() as interrupted:
        pool = ForkedPool(max_workers=n_workers, mp_context=ctx, initializer=_worker_init,
                          initargs=(os.getpid(),), interrupted=interrupted)
        with _ended_on_error(pool):
            yield pool
            pool.drain()    # the running tasks end unread, a Ctrl-C meanwhile ends them
        pool.shutdown(wait=True)
