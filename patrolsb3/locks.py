"""Locks on files shared between processes: a run folder, a zoo entry being exported (``filelock``,
which releases a lock when its process ends, however it ends)."""
from __future__ import annotations


def hold(lock_file, busy: str):
    """Take a ``filelock`` lock on ``lock_file`` for this process, or refuse at once.

    Args:
        lock_file: the lock's file (its folder must exist).
        busy: the one-line message when another process holds it.

    Returns:
        The held lock (``.release()`` it, or use it as a context manager).

    Raises:
        ValueError: ``busy``, when another process holds the lock.
    """
    from filelock import FileLock, Timeout
    lock = FileLock(lock_file)
    try:
        lock.acquire(timeout=0)
    except Timeout:
        raise ValueError(busy) from None
    return lock
