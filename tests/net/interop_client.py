#!/usr/bin/env python3
"""Plays the simulator's first exchanges against a frenetic server with Python's `websockets`
(a WebSocket implementation frenetic did not write).

Usage: interop_client.py PORT
Sends the engine.io ping "2", the real first telemetry message (udacity-sim.md §3.3) and a null
telemetry; checks the replies (control with equal, finite arrays; manual). Prints one OK line and
exits 0, or prints what was wrong and exits 1. Gives up after 10 s per step.
"""
import asyncio
import json
import math
import sys

import websockets

FIRST = (
    '42["telemetry",{"x":909.48,"y":1128.67,"yaw":0,"speed":0,"s":124.8336,"d":6.164833,'
    '"previous_path_x":[],"previous_path_y":[],"end_path_s":0,"end_path_d":0,'
    '"sensor_fusion":[[0,1056.788,1164.296,37.39919,15.43803,275.7777,5.999895],'
    '[1,775.8,1425.2,0,0,6719.219,-280.1494],[2,775.8,1429,0,0,6716.599,-282.9019],'
    '[3,775.8,1432.9,0,0,6713.911,-285.7268],[4,775.8,1436.3,0,0,6711.566,-288.1896],'
    '[5,775.8,1441.7,0,0,6661.772,-291.7797],[6,762.1,1421.6,0,0,6711.778,-268.0965],'
    '[7,762.1,1425.2,0,0,6709.296,-270.7039],[8,762.1,1429,0,0,6663.543,-273.1828],'
    '[9,762.1,1432.9,0,0,6660.444,-275.5511],[10,762.1,1436.3,0,0,6657.743,-277.6157],'
    '[11,762.1,1441.7,0,0,6653.453,-280.8947]]}]'
)
TIMEOUT = 10.0


def fail(message):
    print("FAIL " + message)
    sys.exit(1)


async def run(port):
    url = "ws://127.0.0.1:%d/socket.io/?EIO=4&transport=websocket" % port
    async with websockets.connect(url, open_timeout=TIMEOUT, close_timeout=TIMEOUT) as ws:
        await ws.send("2")
        await ws.send(FIRST)
        reply = await asyncio.wait_for(ws.recv(), TIMEOUT)
        if not isinstance(reply, str) or not reply.startswith("42"):
            fail("expected a 42 text frame, got %r" % (reply[:80],))
        event, payload = json.loads(reply[2:])
        if event != "control":
            fail("expected control, got %r" % event)
        xs, ys = payload["next_x"], payload["next_y"]
        if len(xs) != len(ys) or not xs:
            fail("next_x has %d points, next_y %d" % (len(xs), len(ys)))
        if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in xs + ys):
            fail("non-finite or non-number in the path")
        await ws.send('42["telemetry",null]')
        manual = await asyncio.wait_for(ws.recv(), TIMEOUT)
        if manual != '42["manual",{}]':
            fail("expected manual after null telemetry, got %r" % manual[:80])
        print("OK control %d points from x %g" % (len(xs), xs[0]))


def main():
    if len(sys.argv) != 2:
        print("usage: interop_client.py PORT", file=sys.stderr)
        sys.exit(2)
    asyncio.run(run(int(sys.argv[1])))


if __name__ == "__main__":
    main()
