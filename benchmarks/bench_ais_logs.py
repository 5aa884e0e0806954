"""Speed of reading AIS logs: ``shipgnc.ais.logs.read_reports`` and ``read_log``, lines per CPU-second.

    python benchmarks/bench_ais_logs.py [--lines 20000] [--pyais-sample PATH]

Reads, each timed with the process's CPU time (the machine is shared):

(a) the vendored real sample ``tests/data/ais/kystverket-2024-12-09.nmea`` (223 lines of the
    Norwegian Coastal Administration's live feed, tag blocks on most lines): ``read_reports``
    with ``untimed="previous"`` and ``skip_unknown`` (it holds aid-to-navigation and base-station
    messages, and ships heard only by their static data, which ``read_log`` refuses);
(b) pyais alone (``FileReaderStream`` and ``decode``) on the same real file: the decoder the reader
    wraps, for the ratio; with ``--pyais-sample PATH`` also a sample file of a pyais checkout
    (https://github.com/M0r13n/pyais, MIT; ``tests/nmea_data_sample.txt``: 898 real lines without
    times, which ``read_reports`` refuses at its first line), decoded by pyais line by line;
(c) a log of ``--lines`` lines written by ``shipgnc.ais.write.write_log`` (an own ship and 20
    targets at their reporting intervals, tag blocks): ``read_log`` whole.

Writes ``benchmarks/results/bench_ais_logs.json``.
"""

from __future__ import annotations

import argparse
import datetime as dt_
import json
import math
import os
import platform
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULTS = Path(__file__).resolve().parent / "results"
REAL = ROOT / "tests" / "data" / "ais" / "kystverket-2024-12-09.nmea"


def timed(fn, repeat: int = 3):
    """(result, least CPU seconds of ``repeat`` calls)."""
    best, out = math.inf, None
    for _ in range(repeat):
        cpu = time.process_time()
        out = fn()
        best = min(best, time.process_time() - cpu)
    return out, best


def synthetic(path: Path, lines: int) -> Path:
    """An own ship and 20 crossing targets written by ``write_log`` to about ``lines`` lines."""
    import numpy as np

    from shipgnc.ais.write import write_log
    from shipgnc.colav.tracks import TargetTrack

    n_targets = 20
    t_end = lines / (n_targets + 1) * 10.0  # 10 kn: a report every 10 s each
    t = np.arange(0.0, t_end, 1.0)
    own = dict(north=5.0 * t, east=0.0 * t, sog=np.full_like(t, 5.0), cog=np.zeros_like(t))
    targets = [TargetTrack.constant(3000.0 * math.cos(a), 3000.0 * math.sin(a), a + math.pi, 5.0)
               for a in np.linspace(0.0, 2 * math.pi, n_targets, endpoint=False)]
    return write_log(path, t, own, targets, (59.9, 10.7), 100_000_000,
                     [100_000_001 + j for j in range(n_targets)])


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--lines", type=int, default=20_000)
    ap.add_argument("--pyais-sample", type=Path, default=None)
    args = ap.parse_args()
    from shipgnc.ais.logs import read_log, read_reports

    out = {"date": dt_.datetime.now(dt_.timezone.utc).isoformat(timespec="seconds"),
           "machine": platform.machine(), "cpus": os.cpu_count(), "load": os.getloadavg()[0]}
    n_real = sum(1 for ln in REAL.read_text().splitlines() if ln.strip())
    reports, cpu = timed(lambda: read_reports(REAL, skip_unknown=True, untimed="previous"))
    out["kystverket"] = {"lines": n_real, "reports": len(reports), "cpu_s": cpu,
                         "lines_per_s": n_real / cpu}
    from pyais.stream import FileReaderStream

    n_msg, cpu = timed(lambda: sum(1 for m in FileReaderStream(str(REAL)) if m.decode()))
    out["kystverket_pyais"] = {"lines": n_real, "messages": n_msg, "cpu_s": cpu,
                               "lines_per_s": n_real / cpu}
    if args.pyais_sample is not None and args.pyais_sample.exists():
        from pyais import decode

        lines = [ln for ln in args.pyais_sample.read_text().splitlines() if ln.startswith("!")]

        def pyais_only():
            n = 0
            for ln in lines:
                try:
                    decode(ln)
                    n += 1
                except Exception:  # a fragment alone or an empty payload
                    pass
            return n

        n_ok, cpu = timed(pyais_only, 1)
        out["pyais_sample"] = {"lines": len(lines), "decoded": n_ok, "cpu_s": cpu,
                               "pyais_lines_per_s": len(lines) / cpu}
    with tempfile.TemporaryDirectory() as tmp:
        path = synthetic(Path(tmp) / "synthetic.nmea", args.lines)
        n = sum(1 for _ in path.open())
        (tracks, _), cpu = timed(lambda: read_log(path), 1)
        out["synthetic"] = {"lines": n, "tracks": len(tracks), "cpu_s": cpu, "lines_per_s": n / cpu}
    for key in ("kystverket", "kystverket_pyais", "pyais_sample", "synthetic"):
        if key in out:
            rate = out[key].get("lines_per_s", out[key].get("pyais_lines_per_s"))
            print(f"{key}: {out[key]['lines']} lines, {rate:,.0f} lines per CPU-second")
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "bench_ais_logs.json").write_text(json.dumps(out, indent=2) + "\n")


if __name__ == "__main__":
    main()
