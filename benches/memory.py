#!/usr/bin/env python3
"""Peak memory and output sizes of hdw's long runs and large studies (issue #18).

Every case runs the hdw binary as its own process under a wall-time limit (--timeout) and an
address-space cap (--cap-gib, RLIMIT_AS as `ulimit -v` sets it), so a case that would take
the shared 24 GB machine down stops and is recorded as "exceeded". Peak RSS is the child's
own (wait4 rusage). Cases:

- `hdw simulate --t-end 40` and `--t-end 400`: peak RSS, response.svg size, trace rows against
  t_end/dt_out + 1 (dt_out automatic: 200 per 50 Hz cycle, 1e-4 s);
- a 2 000 000-sample hysteresis record (`hdw synth hysteresis --samples 2000000`) fitted with
  `hdw fit hysteresis`: the largest plot;
- a linear-variant study of tiny runs (24 V step, t_end 3 ms) on a K̄ × Jz grid with
  --no-report at 100 000, 400 000 and 1 000 000 runs: peak RSS, runs per second, file sizes;
- `hdw report` of the 1000 × 1000 study: the largest plot;
- a 10⁶ × 10⁶ grid: time to fail, exit code, and whether stderr is one sentence naming the
  run count, with no stack trace;
- `--shard 1/100000` of a 10⁴ × 10⁴ (10⁸-run) grid: time until hdw announces the shard's runs
  (its "N to run" line) and until the shard's 1000 runs are written.

It prints PASS/FAIL against the issue's targets and always exits 0: it is a measurement
script, not a test. Needs pyarrow for trace row counts (benches/setup-peers.sh installs it).

    python3 benches/memory.py                 # all cases, about 10 min on a quiet machine
    python3 benches/memory.py --only simulate,fit --hdw path/to/hdw
"""

from __future__ import annotations

import argparse
import glob
import os
import shutil
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "peers"))

import memcases as mc  # noqa: E402
from capped import GIB, MIB  # noqa: E402
from common import hdw_path, verdict  # noqa: E402

CASES = ("simulate", "fit", "study", "report", "huge", "shard")


def within(a: float, b: float, frac: float) -> bool:
    return abs(a - b) <= frac * min(a, b)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--hdw", help="hdw binary (default target/release/hdw)")
    ap.add_argument("--only", default=",".join(CASES), help=f"comma list of {', '.join(CASES)}")
    ap.add_argument("--cap-gib", type=float, default=8.0, help="address-space cap per case")
    ap.add_argument("--timeout", type=float, default=420.0, help="wall-time cap per case [s]")
    ap.add_argument("--sizes", default="100000,400000,1000000", help="study run counts")
    ap.add_argument("--keep", help="keep the outputs in this folder instead of a temp dir")
    a = ap.parse_args()
    hdw = hdw_path(a.hdw)
    only = set(a.only.split(","))
    cap, T = int(a.cap_gib * GIB), a.timeout
    tmp = a.keep or tempfile.mkdtemp(prefix="hdw-memory-")
    os.makedirs(tmp, exist_ok=True)
    rows = []  # (verdict or "", check, measured)

    def add(ok, check, got):
        rows.append(("" if ok is None else verdict(ok), check, got))
        print(f"  {rows[-1][0]:4s} {check}: {got}", flush=True)

    print(f"{hdw}; cap {a.cap_gib:g} GiB address space and {T:g} s per case; outputs in {tmp}")
    try:
        if "simulate" in only:
            print("\n== hdw simulate, default outputs ==")
            sims = {t: mc.simulate(hdw, tmp, t, T, cap) for t in (40.0, 400.0)}
            for t, r in sims.items():
                o = r["outcome"]
                got = o.describe()
                if o.status == "ok":
                    got += (f"; response.svg {r['svg'] / mc.MB:.2f} MB; trace {r['rows']} rows "
                            f"(expected {r['expected_rows']}), {r['trace_bytes'] / mc.MB:.1f} MB")
                add(None, f"simulate --t-end {t:g}", got)
            r4, r40 = sims[400.0], sims[40.0]
            o4 = r4["outcome"]
            add(o4.status == "ok" and o4.peak_rss < 200 * MIB, "t-end 400 peak RSS < 200 MiB",
                f"{o4.peak_mib:.0f} MiB ({o4.status})")
            add(o4.status == "ok" and r4.get("svg", 1e18) < 2 * mc.MB,
                "t-end 400 response.svg < 2 MB",
                f"{r4['svg'] / mc.MB:.2f} MB" if r4.get("svg") else o4.status)
            add(o4.status == "ok" and r4.get("rows") == r4["expected_rows"],
                "t-end 400 trace holds every sample", f"{r4.get('rows')} of {r4['expected_rows']}")
            o40 = r40["outcome"]
            add(o4.status == o40.status == "ok" and within(o4.peak_rss, o40.peak_rss, 0.2),
                "peak RSS at 40 s and 400 s within 20 %",
                f"{o40.peak_mib:.0f} vs {o4.peak_mib:.0f} MiB")
        if "fit" in only:
            print("\n== 2 000 000-sample hysteresis fit ==")
            r = mc.hysteresis_fit(hdw, tmp, 2_000_000, T, cap)
            o = r["outcome"]
            add(None, f"hdw {r['stage']} hysteresis", o.describe())
            plots = r.get("plots") or []
            big = plots[0] if plots else None
            add(o.status == "ok" and big is not None and big[0] <= 2 * mc.MB,
                "no plot of the 2 000 000-sample fit over 2 MB",
                ", ".join(f"{p} {s / mc.MB:.2f} MB" for s, p in plots[:3]) or o.status)
        studies = {}
        if "study" in only or "report" in only:
            print("\n== tiny linear study, --no-report ==")
            sizes = [int(x) for x in a.sizes.split(",")] if "study" in only else [1_000_000]
            shapes = {100_000: (400, 250), 400_000: (800, 500), 1_000_000: (1000, 1000)}
            for n in sizes:
                n1, n2 = shapes.get(n, (n // 1000, 1000))
                r = mc.study(hdw, tmp, n1, n2, T, cap)
                studies[n] = r
                o = r["outcome"]
                got = o.describe()
                if o.status == "ok":
                    s = r["sizes"]
                    got += (f"; {r['runs_per_s']:.0f} runs/s; runs.parquet "
                            f"{s.get('runs.parquet', 0) / mc.MB:.1f} MB, study.json "
                            f"{s.get('study.json', 0) / mc.MB:.1f} MB")
                add(None, f"{n} runs ({n1} × {n2})", got)
            if 1_000_000 in studies:
                o = studies[1_000_000]["outcome"]
                add(o.status == "ok" and o.peak_rss < 500 * MIB,
                    "1 000 000-run study peaks below 500 MiB", f"{o.peak_mib:.0f} MiB ({o.status})")
            if 100_000 in studies and 400_000 in studies:
                o1, o4 = studies[100_000]["outcome"], studies[400_000]["outcome"]
                add(o1.status == o4.status == "ok" and within(o1.peak_rss, o4.peak_rss, 0.2),
                    "peak RSS at 100 000 and 400 000 runs within 20 %",
                    f"{o1.peak_mib:.0f} vs {o4.peak_mib:.0f} MiB")
            for n in sizes:  # the 1000 × 1000 study stays for the report case
                if n != 1_000_000:
                    shutil.rmtree(studies[n]["out"], ignore_errors=True)
        if "report" in only:
            print("\n== hdw report of the 1000 × 1000 study ==")
            st = studies.get(1_000_000)
            if st and st["outcome"].status == "ok":
                r = mc.report(hdw, st["out"], T, cap)
                o = r["outcome"]
                big = r["plots"][0] if r["plots"] else None
                add(None, "hdw report (1 000 000 runs)", o.describe())
                add(o.status == "ok" and big is not None and big[0] <= 2 * mc.MB,
                    "report of a 1000 × 1000 grid writes no plot over 2 MB",
                    (f"largest {big[1]} {big[0] / mc.MB:.2f} MB of {len(r['plots'])} plots"
                     if big else o.status))
            else:
                add(False, "report of a 1000 × 1000 grid writes no plot over 2 MB",
                    "not run: the 1 000 000-run study did not finish")
        if "huge" in only:
            print("\n== a 10⁶ × 10⁶ grid ==")
            r = mc.study(hdw, tmp, 1_000_000, 1_000_000, 60.0, cap)
            o = r["outcome"]
            sentence = mc.one_sentence(o.stderr)
            count = mc.names_count(o.stderr, 10**12)
            add(None, "10⁶ × 10⁶ grid", f"exit {o.rc} after {o.wall:.2f} s, peak RSS "
                f"{o.peak_mib:.0f} MiB; stderr: {o.stderr.strip()[:240]!r}")
            add(o.rc == 1 and o.wall <= 1.0 and sentence and count,
                "fails within 1 s, exit 1, one sentence with the run count, no stack trace",
                f"{o.wall:.2f} s, exit {o.rc}, one sentence: {sentence}, names 10¹²: {count}")
        if "shard" in only:
            print("\n== --shard 1/100000 of a 10⁸-run grid ==")

            def watch(out):
                return {"announced": lambda err: "to run" in err,
                        "rows": lambda err: bool(glob.glob(os.path.join(out, "**", "*.parquet"),
                                                           recursive=True))}

            r = mc.study(hdw, tmp, 10_000, 10_000, 60.0, cap, extra=("--shard", "1/100000"),
                         watch=watch)
            o = r["outcome"]
            ev = o.events
            first = min([v for v in (ev.get("announced"), ev.get("rows")) if v is not None]
                        + ([o.wall] if o.status == "ok" else []), default=None)
            add(None, "shard 1/100000 of 10⁸ runs",
                f"{o.describe()}; runs announced at "
                f"{ev.get('announced', float('nan')):.2f} s, first rows on disk at "
                f"{ev.get('rows', float('nan')):.2f} s; {mc.capped.last_line(o.stderr)!r}")
            add(first is not None and first <= 1.0 and o.status == "ok",
                "shard's first run starts within 1 s (and the shard finishes)",
                f"{first:.2f} s ({o.status})" if first is not None else o.status)
    finally:
        if not a.keep:
            shutil.rmtree(tmp, ignore_errors=True)
    print("\n== issue #18 memory targets ==")
    for v, check, got in rows:
        if v:
            print(f"{v}  {check}: {got}")


if __name__ == "__main__":
    main()
