"""Atomic output directories: a run's files appear together, or not at all.

Every command that writes (``run``, ``sweep``, ``route --out``) writes into a temporary directory
beside ``--out`` (``.<name>.tmp-XXXX``) and moves it into place only once every file is complete.
The finished directory holds a marker file, :data:`MARKER` (``.shipgnc-run``, a small JSON object:
the tool, its version, the command, the run's status and the files written), by which a later
command recognises "a directory holding an earlier shipgnc run" (as does a directory holding
nothing but files shipgnc writes, :data:`OUTPUT_FILES`: a run from before the marker): such a
directory is replaced whole, never mixed with the new files.

Nothing shipgnc did not write is ever deleted. A directory holding anything else (a file or
folder the marker does not list: the scenario file, the user's notes) is refused, unless
``overwrite`` (``--overwrite``) is given: the new files are then moved in beside that content,
replacing only the files the earlier run listed in its marker, and a file of the same name as one
shipgnc writes that shipgnc did not write is refused still. An input of the command inside
``--out`` is always refused (``check_out(..., inputs=...)``).

A temporary directory is named after its owner (``.<name>.tmp-<host>-<pid>-<random>``): one left
behind by a run that was killed (``kill -9``, SIGTERM, a power cut) is removed by the next
command writing beside it once that process is gone (:func:`remove_stale`).

:func:`check_out` checks ``--out`` before any work (a file, an unwritable parent, a foreign
directory: a :class:`~shipgnc.errors.ConfigError`, exit 2). :func:`atomic_dir` turns a failing
write into one line: a read-only or unwritable target is a ConfigError (exit 2), a disk that fills
during the write an :class:`OutputError` (exit 1); the temporary directory is removed, and an
earlier run in ``--out`` stays untouched.
"""

from __future__ import annotations

import errno
import fnmatch
import glob
import hashlib
import json
import os
import re
import secrets
import shutil
import signal
import socket
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from shipgnc.errors import ConfigError, ShipGNCError
from shipgnc.interrupts import held, held_now, keeping, latched, on_hard_exit

#: the marker file written with every run's outputs
MARKER = ".shipgnc-run"
#: errno values of a target that cannot be written (exit 2)
UNWRITABLE = {errno.EACCES, errno.EPERM, errno.EROFS}
#: errno values of a disk that filled during the write (exit 1)
FULL = {errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC), errno.EFBIG}


class OutputError(ShipGNCError):
    """Writing the outputs failed midway (e.g. the disk filled): nothing was left half-written."""

    exit_code = 1


#: the files shipgnc writes: a directory holding only these (a run written before the marker
#: existed) counts as an earlier shipgnc run too
OUTPUT_FILES = ("result.nc", "metrics.json", "table.csv", "table.md", "sweep.nc", "sweep.zarr",
                "summary.csv", "summary.md", "route.json", "*.png")


def is_shipgnc_run(path: Path) -> bool:
    """Whether ``path`` is a directory holding an earlier shipgnc run: it has :data:`MARKER`, or
    it holds nothing but files shipgnc writes (:data:`OUTPUT_FILES`, one of them not a figure)."""
    path = Path(path)
    if (path / MARKER).is_file():
        return True
    entries = list(path.iterdir())
    return (bool(entries) and all(p.is_file() and _output_name(p.name) for p in entries)
            and any(not p.name.endswith(".png") for p in entries))


def _output_name(name: str) -> bool:
    return any(fnmatch.fnmatch(name, pattern) for pattern in OUTPUT_FILES)


def _written_by_us(path: Path) -> set[str] | None:
    """The entries of ``path`` an earlier shipgnc run wrote (its marker's list, and the marker),
    or None when it is not a shipgnc run."""
    if (path / MARKER).is_file():
        try:
            files = json.loads((path / MARKER).read_text(encoding="utf-8")).get("files")
        except (OSError, ValueError, AttributeError):
            files = None
        if not (isinstance(files, list) and all(isinstance(f, str) for f in files)):
            files = [p.name for p in path.iterdir() if _output_name(p.name)]  # an unreadable list
        return {*files, MARKER}
    if is_shipgnc_run(path):
        return {p.name for p in path.iterdir()}
    return None


def foreign_entries(path: Path) -> list[str]:
    """The entries of the directory ``path`` that shipgnc did not write (sorted): everything but
    the files its marker lists (or, before the marker, the files shipgnc writes)."""
    ours = _written_by_us(Path(path)) or set()
    return sorted(p.name for p in Path(path).iterdir() if p.name not in ours)


def check_out(out: Path, *, overwrite: bool = False, option: str = "--out",
              inputs: tuple = ()) -> Path:
    """Check an output directory before any work; return it. A ConfigError (exit 2) when it is a
    file, the current directory (or holds it), holds one of ``inputs`` (files the command reads),
    holds entries shipgnc did not write (unless ``overwrite``: they are then kept, see the module
    docstring), or when its parent cannot be written."""
    out = Path(out)
    if str(out) == "":
        raise ConfigError(f"{option} '': name a directory")
    shown = str(out)
    if out.exists() and not out.is_dir():
        raise ConfigError(f"{option} {shown!r}: is a file, not a directory")
    resolved = out.resolve()
    if Path.cwd().resolve().is_relative_to(resolved):
        raise ConfigError(f"{option} {shown!r}: is the current directory (or holds it): name a "
                          "directory for the outputs")
    for item in inputs:
        if item is not None and Path(item).exists() and Path(item).resolve().is_relative_to(resolved):
            raise ConfigError(f"{option} {shown!r}: holds the input {str(item)!r}, which a run there "
                              "could replace; name another directory for the outputs")
    if out.is_dir():
        try:
            foreign = foreign_entries(out)
        except OSError as exc:
            raise ConfigError(f"{option} {shown!r}: cannot read the directory ({_reason(exc)})") from None
        if foreign and not overwrite:
            listed = ", ".join(foreign[:3]) + (", ..." if len(foreign) > 3 else "")
            raise ConfigError(f"{option} {shown!r}: holds files that are not a shipgnc run ({listed}); "
                              "name another directory, or pass --overwrite to write beside them "
                              "(nothing shipgnc did not write is deleted)")
        clash = [name for name in foreign if _output_name(name)]
        if clash:
            raise ConfigError(f"{option} {shown!r}: holds {clash[0]!r}, which shipgnc did not write "
                              "and a run would replace; move it, or name another directory")
    parent = _existing_ancestor(resolved.parent)
    if not parent.is_dir():
        raise ConfigError(f"{option} {shown!r}: {str(parent)!r} is not a directory")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise ConfigError(f"{option} {shown!r}: cannot write in {str(parent)!r} (permission denied)")
    return out


def check_out_file(path: Path, option: str) -> Path:
    """Check an output file's place before any work; return it. A ConfigError (exit 2) naming
    ``option`` when it is a directory, or its directory does not exist or cannot be written."""
    path = Path(path)
    shown = str(path)
    if shown == "" or path.is_dir():
        raise ConfigError(f"{option} {shown!r}: name a file to write, not a directory")
    parent = path.resolve().parent
    if not parent.is_dir():
        raise ConfigError(f"{option} {shown!r}: its directory {str(parent)!r} does not exist")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise ConfigError(f"{option} {shown!r}: cannot write in {str(parent)!r} (permission denied)")
    return path


def _existing_ancestor(path: Path) -> Path:
    while not path.exists() and path != path.parent:
        path = path.parent
    return path


def _reason(exc: OSError) -> str:
    return exc.strerror or str(exc) or type(exc).__name__


def _errno(exc: BaseException) -> int | None:
    """The errno of an OSError, also when a library (h5py) only names it in its message."""
    if isinstance(exc, OSError) and exc.errno is not None:
        return exc.errno
    text = str(exc)
    if "No space left" in text or "errno = 28" in text:
        return errno.ENOSPC
    if "Read-only file system" in text or "errno = 30" in text:
        return errno.EROFS
    if "Permission denied" in text or "errno = 13" in text:
        return errno.EACCES
    return None


def output_error(out: Path, exc: BaseException, option: str = "--out") -> ShipGNCError:
    """The one-line error of a failed write into ``out``."""
    code = _errno(exc)
    reason = _reason(exc) if isinstance(exc, OSError) else os.strerror(code) if code is not None else str(exc)
    if code in UNWRITABLE:
        return ConfigError(f"{option} {str(out)!r}: cannot write ({reason}); nothing was written")
    if code in FULL:
        return OutputError(f"{option} {str(out)!r}: the disk filled while writing ({reason}); "
                           "nothing was written, an earlier run there is untouched")
    return OutputError(f"{option} {str(out)!r}: writing failed ({reason}); nothing was written")


@contextmanager
def atomic_dir(out: Path, *, overwrite: bool = False, command: str = "run", status: str = "complete",
               option: str = "--out") -> Iterator[Path]:
    """Yield a temporary directory beside ``out``; when the block ends normally, write the marker
    and move the directory into place (replacing an earlier shipgnc run whole, or with
    ``overwrite`` moving the files in beside what shipgnc did not write). On any error or Ctrl-C
    the temporary directory is removed and ``out`` is left as it was; an OSError becomes one line
    (see :func:`output_error`). Temporary directories of dead runs beside ``out`` are removed
    first (:func:`remove_stale`)."""
    out = check_out(Path(out), overwrite=overwrite, option=option)
    parent = out.resolve().parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
        remove_stale(parent, out.name)
        tmp = _new_dir(parent, f".{out.name}.tmp-")
    except OSError as exc:
        raise output_error(out, exc, option) from None
    on_hard_exit(id(tmp), lambda: shutil.rmtree(tmp, ignore_errors=True))  # Ctrl-C's deadline
    try:
        yield tmp
        if status == "complete" and latched() and not held():  # a Ctrl-C a callback swallowed
            raise KeyboardInterrupt
        marker = {"tool": "shipgnc", "version": _version(), "command": command, "status": status,
                  "files": sorted(p.name for p in tmp.iterdir())}
        (tmp / MARKER).write_text(json.dumps(marker, indent=2) + "\n", encoding="utf-8")
        with keeping(), _sigint_deferred():  # the swap is never cut in half by Ctrl-C's deadline
            _replace(tmp, out.resolve())
    except OSError as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        raise output_error(out, exc, option) from None
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    finally:
        on_hard_exit(id(tmp), None)


#: a temporary directory's name: ``.<out>.tmp-<host>-<pid>-<random>`` (or ``.old-``)
_OWNED = re.compile(r"\.(?P<out>.+)\.(?:tmp|old)-(?P<host>[0-9a-f]{8})-(?P<pid>[0-9]+)-[0-9a-f]{8}")


def _host() -> str:
    """This machine, in 8 hex digits (a directory shared by several machines keeps each one's)."""
    return hashlib.sha1(socket.gethostname().encode()).hexdigest()[:8]


def process_alive(pid: int) -> bool:
    """A process of this number runs on this machine (ours or, unsignalable, another user's)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):  # someone else's process (or no such number)
        return pid < 2**31
    return True


def remove_stale(parent: Path, name: str) -> list[Path]:
    """Remove the temporary directories of ``parent/name`` (``.name.tmp-*``, ``.name.old-*``)
    whose owner, a process on this machine, is gone; return them. A live owner's, another
    machine's and an unnamed one's are left alone."""
    removed = []
    host = _host()
    try:
        candidates = list(Path(parent).glob(f".{glob.escape(name)}.*-*"))
    except OSError:
        return removed
    for path in candidates:
        match = _OWNED.fullmatch(path.name)
        if (match is None or match["out"] != name or match["host"] != host
                or int(match["pid"]) == os.getpid() or process_alive(int(match["pid"]))):
            continue
        shutil.rmtree(path, ignore_errors=True)
        removed.append(path)
    return removed


def _new_dir(parent: Path, prefix: str) -> Path:
    """A new directory ``parent/<prefix><host>-<pid>-<random>`` with the usual permissions (the
    umask's; ``tempfile.mkdtemp`` would make it private, and the run's directory keeps its mode)."""
    for _ in range(100):
        path = parent / f"{prefix}{_host()}-{os.getpid()}-{secrets.token_hex(4)}"
        try:
            path.mkdir()
        except FileExistsError:
            continue
        return path
    raise FileExistsError(errno.EEXIST, "no free temporary name", str(parent))


def _replace(tmp: Path, out: Path) -> None:
    """Move ``tmp`` to ``out``. An existing ``out`` holding only an earlier run is set aside
    first and removed after; one holding anything else gets the new files moved in
    (:func:`_merge`)."""
    if not out.exists():
        os.rename(tmp, out)
        return
    if foreign_entries(out):
        _merge(tmp, out)
        return
    old = _new_dir(out.parent, f".{out.name}.old-")
    os.rmdir(old)
    os.rename(out, old)
    try:
        os.rename(tmp, out)
    except OSError:
        os.rename(old, out)  # put the earlier run back
        raise
    shutil.rmtree(old, ignore_errors=True)


def _merge(tmp: Path, out: Path) -> None:
    """Move the files of ``tmp`` into ``out`` beside what shipgnc did not write there: the files
    of the earlier run (its marker's list) are set aside first and removed after; on a failure
    they are put back. A name clash with a file shipgnc did not write is refused."""
    ours = _written_by_us(out) or set()
    new = sorted(p.name for p in tmp.iterdir())
    clash = [n for n in new if (out / n).exists() and n not in ours]
    if clash:
        raise ConfigError(f"--out {str(out)!r}: holds {clash[0]!r}, which shipgnc did not write; "
                          "nothing was written")
    old = _new_dir(out.parent, f".{out.name}.old-")
    moved_old, moved_new = [], []
    try:
        for n in sorted(ours):
            if (out / n).exists() or (out / n).is_symlink():
                os.rename(out / n, old / n)
                moved_old.append(n)
        for n in [n for n in new if n != MARKER] + [MARKER]:  # the marker last
            os.rename(tmp / n, out / n)
            moved_new.append(n)
    except OSError:
        for n in moved_new:
            os.rename(out / n, tmp / n)
        for n in moved_old:
            os.rename(old / n, out / n)
        shutil.rmtree(old, ignore_errors=True)
        raise
    shutil.rmtree(old, ignore_errors=True)
    os.rmdir(tmp)


@contextmanager
def _sigint_deferred():
    """Hold a Ctrl-C that arrives inside the block (the directories' swap, h5py's encoding) until
    the block is done, then raise it."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught = []
    previous = signal.signal(signal.SIGINT, lambda *args: caught.append(args))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
    if caught and not held_now():  # held: a complete result kept (--keep-partial) is not undone
        raise KeyboardInterrupt


#: a NetCDF file up to this size is encoded in memory and written with plain file I/O
IN_MEMORY_MAX_BYTES = 512 * 1024**2


def write_netcdf(ds, path: Path) -> Path:
    """Write the Dataset ``ds`` as NetCDF-4 (h5netcdf engine) so that a write that fails midway
    is one plain :class:`OSError` (which :func:`atomic_dir` turns into one line).

    HDF5 does not survive a write that fails: on a full disk h5py prints a traceback for every
    open object and the process segfaults at exit. So the file is encoded in memory and written
    by ordinary file I/O; a file larger than :data:`IN_MEMORY_MAX_BYTES` is left to HDF5 only
    after the free space has been checked against its size (data + 5 % + 4 MiB). A Ctrl-C that
    arrives while h5py works is held until it is done, then raised: delivered inside one of
    h5py's deallocation callbacks it would be printed and ignored, and the run would go on.
    The write takes a thread lock, whatever dask scheduler the session has (:func:`_local_write_lock`)."""
    path = Path(path)
    if ds.nbytes <= IN_MEMORY_MAX_BYTES:
        try:
            with _sigint_deferred(), _local_write_lock():
                encoded = ds.to_netcdf(engine="h5netcdf")
        except ValueError:  # an xarray that encodes in memory with the scipy engine only
            encoded = None
        if encoded is not None:
            with open(path, "wb") as handle:
                handle.write(encoded)
            return path
    need = int(ds.nbytes * 1.05) + 4 * 1024**2
    free = shutil.disk_usage(path.parent).free
    if free < need:
        raise OSError(errno.ENOSPC, f"No space left on device: {path.name} needs about "
                      f"{need / 1024**2:.0f} MiB, {free / 1024**2:.0f} MiB are free", str(path))
    with _sigint_deferred(), _local_write_lock():
        ds.to_netcdf(path, engine="h5netcdf")
    return path


@contextmanager
def _local_write_lock():
    """xarray locks a NetCDF write with the lock of dask's current scheduler: with a
    ``distributed.Client`` open in the session (a notebook's, a sweep's) that is a cluster-wide
    lock named after the target, which an in-memory target cannot be ("Semaphore or Lock
    <BytesIO> not known"). The data written here is in memory already: a thread lock will do."""
    try:
        import dask
    except ImportError:  # dask is optional (the dist extra): without it xarray locks by thread
        dask = None
    if dask is None:
        yield
        return
    with dask.config.set(scheduler="synchronous"):
        yield


def moved(paths: list[Path], tmp: Path, out: Path) -> list[Path]:
    """``paths`` written under ``tmp`` as their final paths under ``out``."""
    out = Path(out)
    result = []
    for p in paths:
        try:
            result.append(out / Path(p).relative_to(tmp))
        except ValueError:
            result.append(Path(p))
    return result


def _version() -> str:
    from shipgnc import __version__

    return __version__
