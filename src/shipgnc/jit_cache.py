"""Generated numba modules on disk: where they are written, how they are named, when they are pruned.

numba caches a compiled function on disk only when it is defined in an importable file (not a
closure, not ``exec``-ed text). The code shipgnc generates — the composed loop of a combination of
components (:mod:`shipgnc.sim.compose`) and the batch over ships derived from a component's scalar
kernel (:mod:`shipgnc.derive`) — is therefore written as a small module into :func:`cache_dir`,
named by a hash of its text and of the sources it calls (:func:`source_files`: the package's
modules it imports, and theirs, transitively — editing an unrelated module recompiles nothing),
imported by name and compiled with numba's cache: a later process loads it in well under a second.
The written module is plain Python: it is exactly what runs, and a user may read it; code compiled
in memory (kernels defined in a notebook) is written there too, as ``shipgnc_memory_*.py``.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib
import inspect
import os
import re
import sys
from pathlib import Path

import numba

#: the package's source folder: a generated module is keyed on the files of it that it imports
PACKAGE = Path(__file__).resolve().parent
#: a generated module of another release of the package (other sources or numba) unused this long
#: is deleted with its compiled files when a new module is written [s]
STALE_AFTER = 7 * 24 * 3600.0
_PRUNED: list[bool] = []
#: each package file's imports and its bytes, by its (modification time, size): read again when
#: the file changes (a module edited and reloaded in a running session)
_FILE_IMPORTS: dict[Path, tuple[tuple[int, int], list[str]]] = {}
_SOURCES: dict[Path, tuple[tuple[int, int], bytes]] = {}
#: a writer killed between creating its temporary file and renaming it leaves it: one older than
#: this is deleted (once per process and folder, when a file is written there) [s]
TEMPORARY_STALE_AFTER = 3600.0
_SWEPT: set[Path] = set()


def cache_root() -> Path:
    """The folder of shipgnc's caches (generated loops, derived results, the coastline):
    ``$SHIPGNC_CACHE_DIR``, else ``$XDG_CACHE_HOME/shipgnc`` or ``~/.cache/shipgnc``."""
    return Path(os.environ.get("SHIPGNC_CACHE_DIR") or Path(
        os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "shipgnc")


def cache_dir() -> Path:
    """Where generated modules are written: :func:`cache_root`'s subfolder ``loops``."""
    return cache_root() / "loops"


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
    by :func:`module_key` (an edited kernel, or a helper it imports, gets a new file); written
    once, atomically (concurrent processes may race to write the same file). None if not
    writable."""
    release = release_tag()
    path = cache_dir() / f"{prefix}_{release}_{module_key(source, functions)}.py"
    try:
        if not path.exists():
            path.parent.mkdir(parents=True, exist_ok=True)
            prune_stale_loops(path.parent, release)
            write_atomic(path, source)
    except OSError:
        return None
    return path


def module_key(source: str, functions) -> str:
    """16 hex digits naming a generated module: a hash of its text, of the package's files it
    imports transitively (:func:`source_files`, with the modules that define ``functions``: the
    kernels it calls), of a user's kernel files outside the package, and of numba's version."""
    digest = hashlib.sha256(source.encode())
    files = {inspect.getsourcefile(getattr(fn, "py_func", fn)) for fn in functions}
    own = sorted(Path(f).resolve() for f in files if f and not _in_package(Path(f).resolve()))
    modules = {getattr(getattr(fn, "py_func", fn), "__module__", "") for fn in functions}
    hash_files(digest, sorted(source_files(source, modules)) + own)
    digest.update(numba.__version__.encode())
    return digest.hexdigest()[:16]


def hash_files(digest, paths) -> None:
    """Feed each file of ``paths`` (in order) into the hash ``digest``: its name (relative to the
    package for the package's files) and its bytes."""
    for path in paths:
        digest.update(str(path.relative_to(PACKAGE) if _in_package(path) else path).encode())
        digest.update(read_source(path))


def read_source(path: Path) -> bytes:
    """The bytes of the file ``path``, read again only when its modification time or size
    changed."""
    stamp = _stamp(path)
    kept = _SOURCES.get(path)
    if kept is None or kept[0] != stamp:
        kept = _SOURCES[path] = (stamp, path.read_bytes())
    return kept[1]


def _stamp(path: Path) -> tuple[int, int]:
    info = path.stat()
    return info.st_mtime_ns, info.st_size


def write_atomic(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` atomically: into a uniquely named temporary file of the same
    folder (:func:`tempfile.mkstemp`: no clash between threads, processes or hosts sharing the
    folder), then renamed over ``path``. Temporary files of killed writers older than
    :data:`TEMPORARY_STALE_AFTER` are deleted. Raises OSError (a read-only folder)."""
    import tempfile

    _sweep_temporary(path.parent)
    handle, name = tempfile.mkstemp(prefix=f"{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(handle, "w", encoding="utf-8") as f:
            f.write(text)
        os.chmod(name, 0o666 & ~_umask())  # as an ordinary file (mkstemp's is private)
        os.replace(name, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(name)
        raise


def _umask() -> int:
    if not _UMASK:
        mask = os.umask(0o022)
        os.umask(mask)
        _UMASK.append(mask)
    return _UMASK[0]


_UMASK: list[int] = []


def _sweep_temporary(folder: Path, *, now: float | None = None) -> None:
    """Delete the ``*.tmp`` files in ``folder`` older than :data:`TEMPORARY_STALE_AFTER`, once per
    process and folder."""
    if folder in _SWEPT:
        return
    _SWEPT.add(folder)
    import time

    now = time.time() if now is None else now
    for tmp in folder.glob("*.tmp"):
        with contextlib.suppress(OSError):  # another process deleted or renamed it first
            if now - tmp.stat().st_mtime > TEMPORARY_STALE_AFTER:
                tmp.unlink()


def source_files(source: str, modules=()) -> set[Path]:
    """The package's source files that ``source`` imports (``import shipgnc.x``, ``from shipgnc.x
    import y``, ``from shipgnc import x``), with the files of the package's ``modules`` named, and
    everything those files import within the package, transitively: what a generated module's
    compiled code may come from. (Not a package's ``__init__`` merely passed through on the way
    to a submodule: importing it runs, but compiles nothing into the kernel.)"""
    todo = [f for f in map(_module_path, [*_imports(source, ""), *modules]) if f is not None]
    seen: set[Path] = set()
    while todo:
        path = todo.pop()
        if path in seen:
            continue
        seen.add(path)
        package = ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if path.name != "__init__.py":
            package = package.rpartition(".")[0]
        stamp = _stamp(path)
        if _FILE_IMPORTS.get(path, (None,))[0] != stamp:
            _FILE_IMPORTS[path] = (stamp, _imports(read_source(path).decode(), package))
        for name in _FILE_IMPORTS[path][1]:
            found = _module_path(name)
            if found is not None and found not in seen:
                todo.append(found)
    return seen


_FROM = re.compile(r"^[ \t]*from[ \t]+([.\w]+)[ \t]+import[ \t]+(\([^)]*\)|[^\n]*)", re.M)
_IMPORT = re.compile(r"^[ \t]*import[ \t]+([^\n]*)", re.M)


def _imports(text: str, package: str) -> list[str]:
    """Module names imported by ``text`` (a module of ``package``), absolute; each ``from m
    import a`` also as ``m.a`` (a submodule, if it is one). Read by pattern, not parsed (a
    line of a docstring that reads like an import only adds a file to the key)."""
    names = []
    for line in _IMPORT.findall(text):
        names += [part.split()[0] for part in line.split("#")[0].split(",") if part.strip()]
    for base, what in _FROM.findall(text):
        if base.startswith("."):
            level = len(base) - len(base.lstrip("."))
            parts = package.split(".")
            parent = ".".join(parts[:len(parts) - level + 1])
            base = f"{parent}.{base.lstrip('.')}" if base.strip(".") else parent
        names.append(base)
        items = re.sub(r"#[^\n]*", "", what).strip("()")
        names += [f"{base}.{item.split()[0]}" for item in items.split(",") if item.strip()]
    return names


def _module_path(name: str) -> Path | None:
    """The file of the package's module ``name`` (None: not one of the package's modules)."""
    if name != PACKAGE.name and not name.startswith(PACKAGE.name + "."):
        return None
    base = PACKAGE.parent.joinpath(*name.split("."))
    for path in (base.with_suffix(".py"), base / "__init__.py"):
        if path.is_file():
            return path
    return None


def _in_package(path: Path) -> bool:
    return path.is_relative_to(PACKAGE)


def import_file(path: Path):
    """Import a module written by :func:`module_file` (its folder joins ``sys.path`` once)."""
    if str(path.parent) not in sys.path:
        sys.path.append(str(path.parent))
    return importlib.import_module(path.stem)


def release_tag() -> str:
    """8 hex digits naming the package's release and numba's version (a generated module's file
    name carries them, so that the modules of an older release are known)."""
    from shipgnc import __version__

    return hashlib.sha256(f"{__version__} {numba.__version__}".encode()).hexdigest()[:8]


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
