"""Progress bars of the cube writer: tqdm if installed, else a one-line stderr counter."""

from __future__ import annotations

import sys
import time
from typing import Any

__all__ = ["NoProgress", "TextProgress", "progress_bar"]


class TextProgress:
    """A one-line stderr counter, used when tqdm is not installed.

    It shows ``initial`` at once, then at most twice a second, and always the last block.

    Examples
    --------
    >>> import contextlib
    >>> import io
    >>> from sbrdf_xr.store.progress import TextProgress
    >>> err = io.StringIO()
    >>> with contextlib.redirect_stderr(err):
    ...     bar = TextProgress(total=4, initial=1, desc="cube.nc")  # 1 block from a resumed run
    ...     bar.update(3)
    ...     bar.close()
    >>> err.getvalue().endswith("\\n")  # close ends the line
    True
    >>> err.getvalue().rstrip().split("\\r")[1:]  # each redraw starts with a carriage return
    ['cube.nc: 1/4 blocks', 'cube.nc: 4/4 blocks', 'cube.nc: 4/4 blocks']
    """

    def __init__(self, total: int, initial: int, desc: str) -> None:
        self.n, self.total, self.desc = initial, total, desc
        self.last = 0.0
        self._show(force=True)

    def _show(self, force: bool = False) -> None:
        now = time.monotonic()
        if force or now - self.last >= 0.5:
            self.last = now
            sys.stderr.write(f"\r{self.desc}: {self.n}/{self.total} blocks")
            sys.stderr.flush()

    def update(self, n: int = 1) -> None:
        self.n += n
        self._show(force=self.n == self.total)

    def close(self) -> None:
        self._show(force=True)
        sys.stderr.write("\n")
        sys.stderr.flush()


class NoProgress:
    """The progress bar of a write that shows none: :meth:`update` and :meth:`close` do nothing.

    Examples
    --------
    >>> import contextlib
    >>> import io
    >>> from sbrdf_xr.store.progress import NoProgress
    >>> err = io.StringIO()
    >>> with contextlib.redirect_stderr(err):
    ...     bar = NoProgress()
    ...     bar.update(3)
    ...     bar.close()
    >>> err.getvalue()
    ''
    """

    def update(self, n: int = 1) -> None:
        pass

    def close(self) -> None:
        pass


def progress_bar(enabled: bool, total: int, initial: int, desc: str) -> Any:
    """A progress bar of ``total`` blocks on stderr, starting at ``initial``.

    Parameters
    ----------
    enabled : bool
        False gives a :class:`NoProgress`, which shows nothing.
    total, initial : int
        Blocks in the cube, and blocks already written (by a resumed run).
    desc : str
        Label in front of the count (the cube's file name).

    Returns
    -------
    tqdm.tqdm or TextProgress or NoProgress
        A tqdm bar counting in ``block`` units if tqdm is installed, else a
        :class:`TextProgress`; each has ``update(n)`` and ``close()``.

    Examples
    --------
    >>> import contextlib
    >>> import io
    >>> from sbrdf_xr.store.progress import progress_bar
    >>> type(progress_bar(False, total=4, initial=0, desc="cube.nc")).__name__
    'NoProgress'
    >>> err = io.StringIO()
    >>> with contextlib.redirect_stderr(err):
    ...     bar = progress_bar(True, total=4, initial=1, desc="cube.nc")
    ...     bar.update(3)
    ...     print(bar.n, bar.total)
    ...     bar.close()
    4 4
    >>> "cube.nc: " in err.getvalue()
    True
    """
    if not enabled:
        return NoProgress()
    try:
        from tqdm import tqdm
    except ImportError:
        return TextProgress(total, initial, desc)
    return tqdm(total=total, initial=initial, desc=desc, unit="block", file=sys.stderr)
