"""Generated numba modules on disk: where they are written, how they are named, when they are pruned.

numba caches a compiled function on disk only when it is defined in an importable file (not a
closure, not ``exec``-ed text). The code shipgnc generates — the composed loop of a combination of
components (:mod:`shipgnc.sim.compose`) and the batch over ships derived from a component's scalar
kernel (:mod:`shipgnc.derive`) — is therefore written as a small module into :func:`cache_dir`,
named by a hash of its text and of the sources it calls, imported by name and compiled with numba's
cache: a later process loads it in well under a second. The written module is plain Python: it is
exactly what runs, and a user may read it.
"""

from __future__ import annotations

import hashlib
import importlib
import inspect
import os
import sys
from pathlib import Path

import numba

#: the package's source folder: generated modules are keyed on every file in it
PACKAGE = Path(__file__).resolve().parent
#: a generated module of another release of the package (other sources or numba) unused this long
#: is deleted with its compiled files when a new module is written [s]
STALE_AFTER = 7 * 24 * 3600.0
_PRUNED: list[bool] = []
_DIGEST: list[bytes] = []


def cache_dir() -> Path:
    """Where generated modules are written: ``$SHIPGNC_CACHE_DIR``, else
    ``$XDG_CACHE_HOME/shipgnc`` or ``~/.cache/shipgnc`` (subfolder ``loops``)."""
    root = os.environ.get("SHIPGNC_CACHE_DIR") or Path(
        os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "shipgnc"
    return Path(root) / "loops"


def importable(fn) -> bool:
    """True when the compiled function ``fn`` is found again by its module and name (so that a
    generated module may import it, and numba's cache find it in a later process)."""
    py = getattr(fn, "py_func", fn)
    try:
        return getattr(importlib.import_module(py.__module__), py.__qualname__) is fn
    except (ImportError, AttributeError):
        return False


def module_file(source: str, functions, *, prefix: str) -> Path | None:
    """The module file of ``source`` in :func:`cache_dir`, ``<prefix>_<release>_<hash>.py``, named
    by a hash of it, of the package's sources (and of a user's kernel files among ``functions``)
    and of the numba version (an edited kernel gets a new file); written once, atomically
    (concurrent processes may race to write the same file). None if not writable."""
    digest = hashlib.sha256(source.encode())
    digest.update(sources_digest())
    files = {inspect.getsourcefile(getattr(fn, "py_func", fn)) for fn in functions}
    for name in sorted(f for f in files if f and not f.startswith(str(PACKAGE))):
        digest.update(Path(name).read_bytes())  # a user's kernels outside the package
    digest.update(numba.__version__.encode())
    release = release_tag()
    path = cache_dir() / f"{prefix}_{release}_{digest.hexdigest()[:16]}.py"
    try:
        if not path.exists():
            path.parent.mkdir(parents=True, exist_ok=True)
            prune_stale_loops(path.parent, release)
            tmp = path.with_suffix(f".{os.getpid()}.tmp")
            tmp.write_text(source)
            os.replace(tmp, path)
    except OSError:
        return None
    return path


def import_file(path: Path):
    """Import a module written by :func:`module_file` (its folder joins ``sys.path`` once)."""
    if str(path.parent) not in sys.path:
        sys.path.append(str(path.parent))
    return importlib.import_module(path.stem)


def release_tag() -> str:
    """8 hex digits naming the package's sources and numba's version (a generated module's file
    name carries them, so that the modules of an older release are known)."""
    digest = hashlib.sha256(sources_digest())
    digest.update(numba.__version__.encode())
    return digest.hexdigest()[:8]


def prune_stale_loops(folder: Path, release: str, *, now: float | None = None) -> list[Path]:
    """Delete the generated modules of other releases (an edited or upgraded package) written and
    compiled more than :data:`STALE_AFTER` seconds ago, and their numba cache files
    (``__pycache__/<name>.*.nbi|nbc``); once per process, when a new module is written. Modules of
    this release, and recent ones of another (a second environment sharing the cache: a module it
    still uses but compiled over a week ago is compiled again there once), stay. Returns the
    modules deleted."""
    if _PRUNED:
        return []
    _PRUNED.append(True)
    import time

    now = time.time() if now is None else now
    deleted = []
    for module in folder.glob("shipgnc_*_*.py"):
        try:
            stem = module.stem
            kind = stem.split("_")[1]
            if stem.startswith(f"shipgnc_{kind}_{release}_"):
                continue
            compiled = list((folder / "__pycache__").glob(f"{stem}.*.nb[ic]"))
            last_use = max([module.stat().st_mtime] + [f.stat().st_mtime for f in compiled])
            if now - last_use < STALE_AFTER:
                continue
            for f in compiled:
                f.unlink(missing_ok=True)
            module.unlink(missing_ok=True)
            deleted.append(module)
        except OSError:  # another process pruned it first, or a read-only cache
            continue
    return deleted


def sources_digest() -> bytes:
    """A hash of every source file of the package (once per process): a kernel's helper may live
    in another file than the kernel (``paths.track_leg`` in the Mariner's controllers), so any
    edit of the package gives every generated module a new name."""
    if not _DIGEST:
        digest = hashlib.sha256()
        for path in sorted(PACKAGE.rglob("*.py")):
            digest.update(str(path.relative_to(PACKAGE)).encode())
            digest.update(path.read_bytes())
        _DIGEST.append(digest.digest())
    return _DIGEST[0]
