#!/usr/bin/env python3
"""OPC UA throughput of `alba run --opcua`, measured with asyncua (numbers
printed, never asserted; docs/performance.md).

Usage: opcua_bench.py ALBA_BINARY [SECONDS]

Writes a project of 1000 generated rungs (the `alba bench` rung, each
counting into its own DINT V_i every scan at 10 ms), runs it, and measures:
reads of 10 variables per Read request with 1 and 4 concurrent sessions
(req/s, p50/p99 latency), then a subscription to all 1000 V_i at a 100 ms
sampling/publishing interval (values received per second).
"""

import asyncio
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time

from asyncua import Client, ua

N = 1000


def project(dir):
    with open(os.path.join(dir, "alba.toml"), "w") as f:
        f.write('name = "opcua-bench"\nscan_ms = 10\nprograms = ["main.lad"]\n[history]\nenabled = false\n')
    tags = ["name,type,address,initial,retain,description"]
    lad = []
    for i in range(N):
        a = 1 if i % 11 == 0 else 0
        tags += [f"A_{i},BOOL,,{a},,", f"T_{i},TIMER,,,,", f"C_{i},COUNTER,,,,", f"L_{i},DINT,,{i % 5},,",
                 f"V_{i},DINT,,,,", f"Q_{i},BOOL,,,,"]
        lad.append(f"[XIO(T_{i}.DN),XIC(A_{i})]TON(T_{i},{5 + i % 7},0)CTU(C_{i},1000000,0)GRT(C_{i}.ACC,L_{i})"
                   f"ADD(V_{i},1,V_{i})OTE(Q_{i});")
    with open(os.path.join(dir, "tags.csv"), "w") as f:
        f.write("\n".join(tags) + "\n")
    with open(os.path.join(dir, "main.lad"), "w") as f:
        f.write("\n".join(lad) + "\n")


def pct(xs, p):
    return xs[min(len(xs) - 1, round((len(xs) - 1) * p))] if xs else float("nan")


async def reader(url, ns, secs, lat):
    async with Client(url=url, timeout=10) as c:
        nodes = [ua.ReadValueId() for _ in range(10)]
        for k, r in enumerate(nodes):
            r.NodeId = ua.NodeId(f"V_{k * 97}", ns)
            r.AttributeId = ua.AttributeIds.Value
        params = ua.ReadParameters()
        params.NodesToRead = nodes
        stop = time.perf_counter() + secs
        while time.perf_counter() < stop:
            t0 = time.perf_counter()
            res = await c.uaclient.read(params)
            lat.append((time.perf_counter() - t0) * 1e6)
            assert len(res) == 10 and all(v.StatusCode.is_good() for v in res)


async def main():
    binary = sys.argv[1]
    secs = float(sys.argv[2]) if len(sys.argv) > 2 else 5.0
    dir = tempfile.mkdtemp(prefix="alba-opcua-bench-")
    project(dir)
    p = subprocess.Popen([binary, "run", dir, "--http", "127.0.0.1:0", "--opcua", "127.0.0.1:0"],
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    url = None
    while url is None:
        line = p.stdout.readline()
        if not line:
            raise SystemExit("alba run ended")
        m = re.search(r"OPC UA server: (opc\.tcp://[\d.]+:\d+/)", line)
        url = m and m.group(1)
    threading.Thread(target=p.stdout.read, daemon=True).start()
    try:
        async with Client(url=url, timeout=10) as c:
            ns = await c.get_namespace_index("urn:alba:opcua-bench")
        print(f"OPC UA (asyncua {getattr(ua, '__version__', '')} client, same 2 cores): {N} rungs at 10 ms; {secs} s per row")
        print(f"{'sessions':>8} {'Read(10)/s':>11} {'p50 µs':>9} {'p99 µs':>9}")
        for n in (1, 4):
            lats = [[] for _ in range(n)]
            t0 = time.perf_counter()
            await asyncio.gather(*(reader(url, ns, secs, lats[k]) for k in range(n)))
            el = time.perf_counter() - t0
            all_l = sorted(x for l in lats for x in l)
            print(f"{n:>8} {len(all_l) / el:>11.0f} {pct(all_l, 0.5):>9.0f} {pct(all_l, 0.99):>9.0f}")
        got = [0]

        class H:
            def datachange_notification(self, node, val, data):
                got[0] += 1

        async with Client(url=url, timeout=30) as c:
            sub = await c.create_subscription(100, H())
            nodes = [c.get_node(ua.NodeId(f"V_{i}", ns)) for i in range(N)]
            await sub.subscribe_data_change(nodes, sampling_interval=100)
            await asyncio.sleep(1.0)
            got[0] = 0
            t0 = time.perf_counter()
            await asyncio.sleep(secs)
            rate = got[0] / (time.perf_counter() - t0)
            await sub.delete()
        print(f"subscription to {N} variables changing every scan, 100 ms: {rate:.0f} values/s "
              f"(the most a 100 ms sampler can report is {N * 10} values/s)")
    finally:
        p.terminate()
        p.wait(timeout=20)
        shutil.rmtree(dir, ignore_errors=True)


asyncio.run(main())
