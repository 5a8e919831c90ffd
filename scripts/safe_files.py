"""Reading and writing a report's files safely, whatever sits at their paths: the scripts run in
folders a user (or another process) can also write to, so a symbolic link, FIFO or device planted
at a report's name must neither redirect a write outside the folder, nor hang a read, nor be read
without bound. Writes are atomic (a temporary beside the target, fsync, one rename), as the C++
side's writes are: a reader never sees half a file, and the rename replaces a name, never follows
it. A path that is there and is not a regular file is refused: OutputRefused, one line on
stderr and exit status 2 (bad input), whichever script meets it.
"""
import os
import stat
import sys
import tempfile

MAX_READ_BYTES = 256 << 20  # far above any report, CSV or summary these scripts read


class OutputRefused(SystemExit):
    """Ends the script with one line and status 2 (a SystemExit: no `except Exception` swallows it)."""

    def __init__(self, message):
        print(message.replace("\n", " ")[:500], file=sys.stderr)
        super().__init__(2)


def _refuse_unless_regular(path):
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return
    if not stat.S_ISREG(st.st_mode):
        raise OutputRefused(f"{path}: not a regular file (a link, FIFO, device or directory); refused")


def open_regular(path, newline=None):
    """A text file object for a regular file (no link, FIFO or device), checked before reading."""
    fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise OutputRefused(f"{path}: not a regular file; refused")
        if st.st_size > MAX_READ_BYTES:
            raise OutputRefused(f"{path}: larger than {MAX_READ_BYTES >> 20} MiB; refused")
        os.set_blocking(fd, True)
        return os.fdopen(fd, encoding="utf-8", newline=newline)
    except BaseException:
        os.close(fd)
        raise


def read_text(path):
    with open_regular(path) as f:
        return f.read(MAX_READ_BYTES + 1)


def _atomic(path, write):
    _refuse_unless_regular(path)
    directory = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", suffix=".tmp", dir=directory)
    try:
        with os.fdopen(fd, "wb") as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, 0o644)
        _refuse_unless_regular(path)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


def write_text(path, text):
    _atomic(path, lambda f: f.write(text.encode("utf-8")))


def save_figure(fig, path, **kwargs):
    """fig.savefig(path), atomically; the format from the path's extension."""
    fmt = os.path.splitext(path)[1].lstrip(".") or "png"
    _atomic(path, lambda f: fig.savefig(f, format=fmt, **kwargs))
