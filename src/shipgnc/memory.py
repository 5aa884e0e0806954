"""Memory this process may still use: checked before a run, a study or a route is started, so
that one too large for the machine is refused in one line (naming its estimate and what to
change) instead of dying of a MemoryError midway, or of the kernel's out-of-memory killer."""

from __future__ import annotations

import os


def available_memory() -> int:
    """Bytes this process can allocate now: the machine's ``MemAvailable`` (else its physical
    memory), and no more than what an address-space limit (``ulimit -v``) leaves."""
    machine = _proc_kib("/proc/meminfo", "MemAvailable:")
    if machine is None:
        try:
            machine = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
        except (ValueError, OSError, AttributeError):
            machine = 1 << 62
    try:
        import resource

        soft, unlimited = resource.getrlimit(resource.RLIMIT_AS)[0], resource.RLIM_INFINITY
    except (ImportError, OSError, ValueError):  # no address-space limits here (Windows)
        return machine
    used = _proc_kib("/proc/self/status", "VmSize:")
    if soft != unlimited and used is not None:
        machine = min(machine, max(0, soft - used))
    return machine


def _proc_kib(path: str, key: str) -> int | None:
    """A ``key: N kB`` line of a /proc file, in bytes (None where there is no /proc)."""
    try:
        with open(path, encoding="ascii") as handle:
            for line in handle:
                if line.startswith(key):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError):
        pass
    return None
