#!/usr/bin/env python3
"""Alba as a Sparkplug B edge node (`[mqtt.sparkplug]`) against Mosquitto,
decoded and commanded with pysparkplug (a third-party Sparkplug B library)
and paho-mqtt.

Usage: sparkplug_client.py ALBA_BINARY PROJECT_DIR

Checks (docs/scale-out.md "Sparkplug B"): NBIRTH with seq 0, bdSeq and
`Node Control/Rebirth`; DBIRTH with every tag as a metric with its name,
alias, Sparkplug data type and value; DDATA by alias, decoded with the
birth, with `seq` counting on from the DBIRTH and wrapping 255 -> 0; a DCMD
write reaches the engine (the HTTP API reads it), a DCMD to an input is
refused and changes nothing; an NCMD `Node Control/Rebirth` gives a new
NBIRTH (seq 0) and DBIRTH; `kill -9` gives the NDEATH the broker held as the
will, with the NBIRTH's bdSeq.
"""

import os
import shutil
import sys
import tempfile
import threading
import time

import pysparkplug as sp

sys.path.insert(0, os.path.dirname(__file__))
from mqtt_client import api, check, client, failures, free_port, start_alba, start_broker  # noqa: E402

GROUP, NODE, DEVICE = "plant", "line1", "plc"
BASE = f"spBv1.0/{GROUP}"


class Recorder:
    def __init__(self, port):
        self.msgs = []
        self.lock = threading.Lock()
        self.c = client(f"host-{time.time_ns()}")
        self.c.on_message = lambda _c, _u, m: self.add(m)
        self.c.connect("127.0.0.1", port)
        self.c.subscribe(f"{BASE}/#", qos=1)
        self.c.loop_start()

    def add(self, m):
        with self.lock:
            self.msgs.append((m.topic, bytes(m.payload)))

    def wait(self, kind, after=0, timeout=10, pred=lambda p: True):
        deadline = time.time() + timeout
        while time.time() < deadline:
            with self.lock:
                for k, (t, p) in enumerate(self.msgs[after:], start=after):
                    if t.split("/")[2] == kind and pred(p):
                        return k, p
            time.sleep(0.02)
        return None, None

    def publish(self, topic, payload):
        self.c.publish(topic, payload, qos=1).wait_for_publish(5)


def metrics_by_name(payload):
    return {m.name: m for m in payload.metrics}


def main():
    binary, project = sys.argv[1], sys.argv[2]
    tmp = tempfile.mkdtemp(prefix="alba-spb-")
    proj = os.path.join(tmp, "project")
    shutil.copytree(project, proj)
    with open(os.path.join(proj, "alba.toml"), "a") as f:
        f.write(f'\n[mqtt]\nkeep_alive_s = 5\n[mqtt.sparkplug]\ngroup_id = "{GROUP}"\nedge_node_id = "{NODE}"\n')
    port = free_port()
    broker = start_broker(port, tmp)
    host = Recorder(port)
    alba, http = start_alba(binary, proj, f"127.0.0.1:{port}")
    try:
        k, raw = host.wait("NBIRTH")
        check(raw is not None, "NBIRTH")
        nbirth = sp.NBirth.decode(raw)
        nm = metrics_by_name(nbirth)
        check(nbirth.seq == 0, f"NBIRTH seq 0 ({nbirth.seq})")
        check("bdSeq" in nm and nm["bdSeq"].datatype == sp.DataType.INT64, "NBIRTH has bdSeq (Int64)")
        check(nm.get("Node Control/Rebirth") is not None and nm["Node Control/Rebirth"].value is False,
              "NBIRTH has Node Control/Rebirth = false")
        k, raw = host.wait("DBIRTH", k)
        dbirth = sp.DBirth.decode(raw)
        dm = metrics_by_name(dbirth)
        check(dbirth.seq == 1, f"DBIRTH seq 1 ({dbirth.seq})")
        for name, dtype in [("Start", sp.DataType.BOOLEAN), ("Setp", sp.DataType.INT16), ("Total", sp.DataType.INT32),
                            ("Delay/ACC", sp.DataType.INT32), ("Delay/DN", sp.DataType.BOOLEAN)]:
            m = dm.get(name)
            check(m is not None and m.datatype == dtype and m.alias is not None,
                  f"DBIRTH metric {name}: {dtype.name} with an alias ({m and m.datatype}, {m and m.alias})")
        aliases = [m.alias for m in dbirth.metrics]
        check(len(set(aliases)) == len(aliases), "aliases are unique")
        # DDATA: by alias, decoded with the birth; seq continues and wraps.
        seqs = [dbirth.seq]
        idx = k
        scans_alias = dm["Scans"].alias
        scans_seen = []
        deadline = time.time() + 30
        while time.time() < deadline and len(seqs) < 300:
            idx2, raw = host.wait("DDATA", idx + 1, timeout=5)
            if raw is None:
                break
            idx = idx2
            d = sp.DData.decode(raw, birth=dbirth)
            seqs.append(d.seq)
            scans_seen += [m.value for m in d.metrics if m.alias == scans_alias]
        check(len(seqs) >= 300, f"300 DDATA ({len(seqs)})")
        check(all((b - a) % 256 == 1 for a, b in zip(seqs, seqs[1:])), "seq counts up by one, wrapping 255 -> 0")
        check(255 in seqs and 0 in seqs[1:], "seq wrapped")
        check(scans_seen and all(b > a for a, b in zip(scans_seen, scans_seen[1:])), "DDATA carries Scans, rising")
        # DCMD: a write by name, with the HTTP API's rules.
        cmd = sp.DCmd(timestamp=sp.get_current_timestamp(),
                      metrics=(sp.Metric(timestamp=None, name="Setp", datatype=sp.DataType.INT16, value=321),))
        host.publish(f"{BASE}/DCMD/{NODE}/{DEVICE}", cmd.encode())
        deadline = time.time() + 5
        while time.time() < deadline and api(http, "/api/tags/Setp")["value"] != 321:
            time.sleep(0.05)
        check(api(http, "/api/tags/Setp")["value"] == 321, "a DCMD write reaches the engine")
        k, raw = host.wait("DDATA", idx, pred=lambda p: any(
            m.alias == dm["Setp"].alias and m.value == 321 for m in sp.DData.decode(p, birth=dbirth).metrics))
        check(raw is not None, "and comes back in a DDATA")
        cmd = sp.DCmd(timestamp=sp.get_current_timestamp(),
                      metrics=(sp.Metric(timestamp=None, name="Start", datatype=sp.DataType.BOOLEAN, value=True),))
        host.publish(f"{BASE}/DCMD/{NODE}/{DEVICE}", cmd.encode())
        time.sleep(0.5)
        check(api(http, "/api/tags/Start")["value"] is False, "a DCMD to an input is refused")
        # NCMD rebirth.
        mark = len(host.msgs)
        ncmd = sp.NCmd(timestamp=sp.get_current_timestamp(),
                       metrics=(sp.Metric(timestamp=None, name="Node Control/Rebirth", datatype=sp.DataType.BOOLEAN,
                                          value=True),))
        host.publish(f"{BASE}/NCMD/{NODE}", ncmd.encode())
        k, raw = host.wait("NBIRTH", mark)
        check(raw is not None and sp.NBirth.decode(raw).seq == 0, "NCMD Rebirth: a new NBIRTH with seq 0")
        k, raw = host.wait("DBIRTH", mark)
        check(raw is not None and metrics_by_name(sp.DBirth.decode(raw))["Setp"].value == 321,
              "and a DBIRTH with the current values")
        # kill -9: NDEATH with the NBIRTH's bdSeq.
        mark = len(host.msgs)
        alba.kill()
        alba.wait()
        k, raw = host.wait("NDEATH", mark, timeout=30)
        check(raw is not None, "NDEATH after kill -9 (the will)")
        if raw is not None:
            death = sp.NDeath.decode(raw).bd_seq_metric
            check(death.name == "bdSeq" and death.value == nm["bdSeq"].value, "NDEATH carries the NBIRTH's bdSeq")
    finally:
        if alba.poll() is None:
            alba.kill()
        broker.kill()
    if failures:
        print(f"{len(failures)} Sparkplug check(s) failed", flush=True)
        sys.exit(1)
    print("Sparkplug B: all checks passed", flush=True)


if __name__ == "__main__":
    main()
