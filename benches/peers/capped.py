"""Run one process under a wall-time limit and an address-space cap, and measure it.

Used by benches/memory.py, whose "before" cases can ask for more memory than the shared
machine has. The cap is RLIMIT_AS (as `ulimit -v` sets it) on the child only; a Rust
process that hits it aborts with "memory allocation of N bytes failed", which is recorded
as `exceeded` rather than as a crash. Peak RSS comes from the child's own rusage (wait4).
"""

from __future__ import annotations

import os
import resource
import signal
import subprocess
import tempfile
import time
from dataclasses import dataclass, field

GIB = 1 << 30
MIB = 1 << 20


@dataclass
class Outcome:
    cmd: list[str]
    wall: float  # [s]
    rc: int | None  # exit code; negative for a signal; None when killed at the timeout
    peak_rss: int  # [bytes]
    stdout: str
    stderr: str
    status: str  # ok | failed | exceeded (memory cap) | timeout
    events: dict = field(default_factory=dict)  # name → seconds after start

    @property
    def peak_mib(self) -> float:
        return self.peak_rss / MIB

    def describe(self) -> str:
        if self.status == "ok":
            return f"{self.wall:.2f} s, peak RSS {self.peak_mib:.0f} MiB"
        if self.status == "exceeded":
            return (f"exceeded the memory cap after {self.wall:.1f} s (peak RSS "
                    f"{self.peak_mib:.0f} MiB when it stopped)")
        if self.status == "timeout":
            return f"timeout after {self.wall:.0f} s (peak RSS {self.peak_mib:.0f} MiB)"
        return f"failed, exit {self.rc} after {self.wall:.2f} s: {last_line(self.stderr)}"


def last_line(text: str) -> str:
    lines = [ln for ln in text.strip().splitlines() if ln.strip()]
    return lines[-1][:300] if lines else "(no stderr)"


def _limit(cap: int):
    def set_cap():
        resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
    return set_cap


def run(cmd: list[str], timeout: float, cap: int, cwd: str | None = None,
        watch: dict | None = None, env: dict | None = None) -> Outcome:
    """Run `cmd` with at most `timeout` s and `cap` bytes of address space.

    `watch` maps an event name to a function of the stderr printed so far, polled every 10 ms
    while the process runs; the first time it returns true, the elapsed time is recorded
    under that name in `Outcome.events`.
    """
    watch = dict(watch or {})
    with tempfile.TemporaryDirectory(prefix="capped-") as tmp:
        out_path, err_path = os.path.join(tmp, "stdout"), os.path.join(tmp, "stderr")
        with open(out_path, "ab") as out, open(err_path, "ab") as err:
            t0 = time.perf_counter()
            p = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=out, stderr=err,
                                 preexec_fn=_limit(cap), start_new_session=True)
        events, status = {}, None
        while True:
            pid, st, ru = os.wait4(p.pid, os.WNOHANG)
            now = time.perf_counter() - t0
            if watch:
                with open(err_path, errors="replace") as f:
                    so_far = f.read()
                for name, fn in list(watch.items()):
                    if fn(so_far):
                        events[name] = now
                        del watch[name]
            if pid:
                rc = os.waitstatus_to_exitcode(st)
                break
            if now > timeout:
                os.killpg(p.pid, signal.SIGKILL)
                _, st, ru = os.wait4(p.pid, 0)
                rc, status = None, "timeout"
                break
            time.sleep(0.01)
        wall = time.perf_counter() - t0
        p.returncode = rc if rc is not None else -9
        with open(out_path, errors="replace") as f:
            so = f.read()
        with open(err_path, errors="replace") as f:
            se = f.read()
    if status is None:
        if rc == 0:
            status = "ok"
        elif "memory allocation of" in se or "out of memory" in se.lower() or rc == -6:
            status = "exceeded"
        else:
            status = "failed"
    return Outcome(cmd, wall, rc, ru.ru_maxrss * 1024, so, se, status, events)
