#!/usr/bin/env python3
"""Alba's OPC UA server against the asyncua client (written elsewhere).

Usage: opcua_client.py ALBA_BINARY PROJECT_DIR

Starts `alba run PROJECT --opcua 127.0.0.1:0` and checks: the tag folder
Objects/Alba/<project>/Tags browses to every tag, typed (a TIMER is an
object of its members); reads agree with the HTTP API; a write to an
internal tag reaches the engine; a write to an input is refused
(BadNotWritable) and changes nothing; a subscription receives the changes
of a tag the program changes every scan.
"""

import asyncio
import json
import re
import subprocess
import sys
import threading
import time
import urllib.request

from asyncua import Client, ua

failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print(f"  FAIL: {what}", flush=True)


def start(binary, project):
    p = subprocess.Popen([binary, "run", project, "--http", "127.0.0.1:0", "--opcua", "127.0.0.1:0", "--no-native"],
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    opc = http = None
    deadline = time.time() + 60
    while time.time() < deadline and not (opc and http):
        line = p.stdout.readline()
        if not line:
            raise SystemExit(f"alba run ended: exit {p.wait()}")
        m = re.search(r"OPC UA server: (opc\.tcp://[\d.]+:\d+/)", line)
        if m:
            opc = m.group(1)
        m = re.search(r"http://([\d.]+:\d+)/", line)
        if m:
            http = "http://" + m.group(1)
    if not (opc and http):
        raise SystemExit("alba run did not report its addresses")
    threading.Thread(target=p.stdout.read, daemon=True).start()
    return p, opc, http


def api(http, path):
    with urllib.request.urlopen(http + path, timeout=10) as r:
        return json.loads(r.read())


async def main():
    binary, project = sys.argv[1], sys.argv[2]
    proc, url, http = start(binary, project)
    try:
        async with Client(url=url, timeout=10) as client:
            ns = await client.get_namespace_index("urn:alba:modbus-plant")
            print("asyncua: browse", flush=True)
            objects = client.nodes.objects
            alba = await objects.get_child([f"{ns}:Alba"])
            folder = await alba.get_child([f"{ns}:modbus-plant", f"{ns}:Tags"])
            system = await alba.get_child([f"{ns}:modbus-plant", f"{ns}:System"])
            names = sorted([(await c.read_browse_name()).Name for c in await folder.get_children()])
            sys_names = sorted([(await c.read_browse_name()).Name for c in await system.get_children()])
            want = sorted(t["name"] for t in api(http, "/api/tags"))
            check(sorted(names + sys_names) == want, f"Tags {names} + System {sys_names} != /api/tags {want}")
            # A TIMER is an object of its members; status members are read-only.
            delay = await folder.get_child([f"{ns}:Delay"])
            members = sorted([(await c.read_browse_name()).Name for c in await delay.get_children()])
            check(members == ["ACC", "DN", "EN", "PRE", "TT"], f"Delay's members: {members}")
            pre = client.get_node(f"ns={ns};s=Delay.PRE")
            await pre.write_value(ua.DataValue(ua.Variant(2500, ua.VariantType.Int32)))
            check(api(http, "/api/tags/Delay.PRE")["value"] == 2500, "Delay.PRE written")
            try:
                await client.get_node(f"ns={ns};s=Delay.DN").write_value(
                    ua.DataValue(ua.Variant(True, ua.VariantType.Boolean)))
                check(False, "a write to Delay.DN was accepted")
            except ua.UaStatusCodeError:
                pass
            speed = client.get_node(f"ns={ns};s=Speed")
            check(await speed.read_data_type_as_variant_type() == ua.VariantType.Int32, "Speed is Int32")
            temp = client.get_node(f"ns={ns};s=Temp")
            check(await temp.read_data_type_as_variant_type() == ua.VariantType.Float, "Temp is Float")
            print("asyncua: read and write", flush=True)
            await speed.write_value(ua.DataValue(ua.Variant(4242, ua.VariantType.Int32)))
            check(api(http, "/api/tags/Speed")["value"] == 4242, "the write reached the engine")
            check(await speed.read_value() == 4242, "read back")
            await temp.write_value(ua.DataValue(ua.Variant(-1.5, ua.VariantType.Float)))
            check(api(http, "/api/tags/Temp")["value"] == -1.5, "REAL write")
            start_btn = client.get_node(f"ns={ns};s=Start")
            before = api(http, "/api/tags/Start")["value"]
            try:
                await start_btn.write_value(ua.DataValue(ua.Variant(not before, ua.VariantType.Boolean)))
                check(False, "a write to the input Start was accepted")
            except ua.UaStatusCodeError as e:
                check(e.code in (ua.StatusCodes.BadNotWritable, ua.StatusCodes.BadUserAccessDenied),
                      f"input write refused with {e}")
            check(api(http, "/api/tags/Start")["value"] == before, "the input is unchanged")
            try:
                await speed.write_value(ua.DataValue(ua.Variant("fast", ua.VariantType.String)))
                check(False, "a string was accepted for a DINT")
            except ua.UaStatusCodeError:
                pass
            print("asyncua: subscription", flush=True)
            scans = client.get_node(f"ns={ns};s=Scans")
            got = []

            class Handler:
                def datachange_notification(self, node, val, data):
                    got.append(val)

            sub = await client.create_subscription(100, Handler())
            await sub.subscribe_data_change(scans)
            await asyncio.sleep(2.0)
            await sub.delete()
            check(len(got) >= 5 and got == sorted(got) and got[-1] > got[0],
                  f"subscription: {len(got)} changes {got[:3]}...")
            print(f"  {len(got)} changes of Scans in 2 s", flush=True)
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
    if failures:
        print(f"{len(failures)} check(s) failed", flush=True)
        sys.exit(1)
    print("OPC UA client tests passed", flush=True)


if __name__ == "__main__":
    asyncio.run(main())
