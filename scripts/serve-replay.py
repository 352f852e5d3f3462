#!/usr/bin/env python3
"""Replays a recorded drive's telemetry to a frenetic server and times every reply.

Usage: serve-replay.py RECORD [--port PORT] [--interval S] [--over MS] [--json]

RECORD is a `frenetic drive --record` file (.jsonl or .jsonl.gz). Every exchange's telemetry is
sent in order, one every --interval s (default 0.02, the simulator's tick), exactly as recorded:
its previous paths are the recording planner's, whatever the server answers, so from the first
reply on the server plans from a path it did not send (a simulator restarted under it, or a
client that drove with another planner). The reply time is the client's, from sending a frame
to reading its answer. Prints p50 / p99 / max over the replies after the first (a session's
first reply builds its planner) and every exchange over --over ms (default 5); --json prints one
JSON object instead. Exit 0; 1 when the server did not answer every frame with a control.
Needs python3-websockets (scripts/test.sh installs it).
"""
import argparse
import asyncio
import gzip
import json
import os
import sys
import time

try:
    import websockets
except ImportError:
    # Debian's python3-websockets is installed for the system interpreter; another python3 first
    # on PATH (pyenv, a venv) does not see it: run under the system one instead.
    if os.path.realpath(sys.executable) != os.path.realpath("/usr/bin/python3") and \
            os.path.exists("/usr/bin/python3"):
        os.execv("/usr/bin/python3", ["/usr/bin/python3", *sys.argv])
    sys.exit("serve-replay.py: the python3 websockets module is missing "
             "(apt-get install python3-websockets)")


def exchanges(path):
    # gzip by its magic bytes, not the name (an older build wrote plain text to a .gz name).
    with open(path, "rb") as f:
        gzipped = f.read(2) == b"\x1f\x8b"
    opener = gzip.open if gzipped else open
    with opener(path, "rt") as f:
        for n, line in enumerate(f, 1):
            try:
                row = json.loads(line)
            except ValueError as e:
                raise SystemExit("serve-replay: %s:%d: not a JSON line (%s)" % (path, n, e))
            if isinstance(row, dict) and row.get("type") == "exchange" and isinstance(
                    row.get("telemetry"), dict):
                yield row["telemetry"]


def percentile(values, q):
    v = sorted(values)
    return v[min(len(v) - 1, int(q * (len(v) - 1) + 0.5))] if v else 0.0


async def replay(args, frames):
    url = "ws://127.0.0.1:%d/socket.io/?EIO=4&transport=websocket" % args.port
    times = []
    async with websockets.connect(url, open_timeout=10, close_timeout=10, max_size=None) as ws:
        start = time.monotonic()
        for i, telemetry in enumerate(frames):
            due = start + i * args.interval
            now = time.monotonic()
            if due > now:
                await asyncio.sleep(due - now)
            frame = '42["telemetry",' + json.dumps(telemetry, separators=(",", ":")) + "]"
            t0 = time.perf_counter()
            await ws.send(frame)
            reply = await asyncio.wait_for(ws.recv(), 10)
            times.append((time.perf_counter() - t0) * 1e3)
            if not isinstance(reply, str) or not reply.startswith('42["control"'):
                return times, "exchange %d: no control reply: %r" % (i, str(reply)[:80])
    return times, None


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("record", help="a frenetic drive --record file (.jsonl or .jsonl.gz)")
    p.add_argument("--port", type=int, default=4567, help="the server's port (default 4567)")
    p.add_argument("--interval", type=float, default=0.02,
                   help="s between frames (default 0.02, one simulator tick)")
    p.add_argument("--over", type=float, default=5.0,
                   help="ms: list the exchanges whose reply took longer (default 5)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    args = p.parse_args()
    frames = list(exchanges(args.record))
    if not frames:
        print("serve-replay: %s: no exchange with telemetry" % args.record, file=sys.stderr)
        return 1
    times, error = asyncio.run(replay(args, frames))
    rest = times[1:]
    over = [(i, round(t, 2)) for i, t in enumerate(times) if i > 0 and t > args.over]
    out = {"record": args.record, "frames": len(frames), "replies": len(times),
           "first_ms": round(times[0], 3) if times else None,
           "p50_ms": round(percentile(rest, 0.5), 3), "p99_ms": round(percentile(rest, 0.99), 3),
           "max_ms": round(max(rest), 3) if rest else 0.0, "over": over, "error": error}
    if args.json:
        print(json.dumps(out))
    else:
        print("%d frames, %d replies: first %.2f ms; after it p50 %.2f ms, p99 %.2f ms, max %.2f ms"
              % (out["frames"], out["replies"], out["first_ms"] or 0, out["p50_ms"], out["p99_ms"],
                 out["max_ms"]))
        print("over %.1f ms: %s" % (args.over, ", ".join("#%d %.1f" % o for o in over) or "none"))
        if error:
            print("serve-replay: " + error, file=sys.stderr)
    return 1 if error else 0


if __name__ == "__main__":
    sys.exit(main())
