#!/usr/bin/env python3
"""Alba as a Sparkplug B edge node (`[mqtt.sparkplug]`) against Mosquitto,
decoded and commanded with pysparkplug (a third-party Sparkplug B library)
and paho-mqtt.

Usage: sparkplug_client.py ALBA_BINARY PROJECT_DIR

Checks (docs/scale-out.md "Sparkplug B"): NBIRTH with seq 0, bdSeq and
`Node Control/Rebirth`; DBIRTH with every tag as a metric with its name,
alias, Sparkplug data type and value; DDATA by alias, decoded with the
birth, with `seq` counting on from the DBIRTH and wrapping 255 -> 0; a
device of its own (`[mqtt.sparkplug.devices]`) with its DBIRTH, DDATA and
DCMD (a DCMD for its metric on another device refused); a DCMD write
reaches the engine (the HTTP API reads it), a DCMD to an input is refused
and changes nothing; an NCMD `Node Control/Rebirth` gives a new
NBIRTH (seq 0) and DBIRTH; `kill -9` gives the NDEATH the broker held as the
will, with the NBIRTH's bdSeq, and the next run's NBIRTH the next bdSeq.

Then with a primary host (`primary_host_id`, Sparkplug 3.0 STATE): no birth
while the host's retained `spBv1.0/STATE/<host>` says offline; births once
it says online; an offline STATE gives an NDEATH and no more data, a stale
one (older timestamp) is ignored; the values written while the host is
offline come back after its online STATE, after the new births, as DDATA
flagged historical with their own timestamps, oldest first, none missing,
and live data after them; the same across a `kill -9` and restart of Alba
(the buffer is on disk).
"""

import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time

import pysparkplug as sp

sys.path.insert(0, os.path.dirname(__file__))
from mqtt_client import api, check, client, failures, free_port, link, put, start_alba, start_broker  # noqa: E402

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

    def wait(self, kind, after=0, timeout=10, pred=lambda p: True, device=None):
        deadline = time.time() + timeout
        while time.time() < deadline:
            with self.lock:
                for k, (t, p) in enumerate(self.msgs[after:], start=after):
                    parts = t.split("/")
                    if parts[2] == kind and (device is None or parts[4:] == [device]) and pred(p):
                        return k, p
            time.sleep(0.02)
        return None, None

    def publish(self, topic, payload, retain=False):
        self.c.publish(topic, payload, qos=1, retain=retain).wait_for_publish(5)

    def since(self, k, kind=None):
        """Messages from index k on (of one kind), as (index, topic, payload)."""
        with self.lock:
            return [(i, t, p) for i, (t, p) in enumerate(self.msgs[k:], start=k)
                    if kind is None or t.split("/")[2] == kind]

    def mark(self):
        with self.lock:
            return len(self.msgs)


def metrics_by_name(payload):
    return {m.name: m for m in payload.metrics}


def main():
    binary, project = sys.argv[1], sys.argv[2]
    tmp = tempfile.mkdtemp(prefix="alba-spb-")
    proj = os.path.join(tmp, "project")
    shutil.copytree(project, proj)
    with open(os.path.join(proj, "alba.toml"), "a") as f:
        f.write(f'\n[mqtt]\nkeep_alive_s = 5\n[mqtt.sparkplug]\ngroup_id = "{GROUP}"\nedge_node_id = "{NODE}"\n'
                f'[mqtt.sparkplug.devices]\nmotion = ["Motor", "Speed"]\n')
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
        check(nm["bdSeq"].value == 0, "bdSeq 0 on a project's first run")
        # [mqtt.sparkplug.devices]: motion has Motor and Speed, the default device the rest.
        km, raw = host.wait("DBIRTH", k, device="motion")
        mbirth = sp.DBirth.decode(raw)
        mm = metrics_by_name(mbirth)
        check(mbirth.seq == 1 and set(mm) == {"Motor", "Speed"}, f"DBIRTH of device motion, seq 1: {sorted(mm)}")
        k, raw = host.wait("DBIRTH", k, device=DEVICE)
        dbirth = sp.DBirth.decode(raw)
        dm = metrics_by_name(dbirth)
        check(dbirth.seq == 2, f"then DBIRTH of device {DEVICE}, seq 2 ({dbirth.seq})")
        check(not set(mm) & set(dm), "a metric is in one device only")
        for name, dtype in [("Start", sp.DataType.BOOLEAN), ("Setp", sp.DataType.INT16), ("Total", sp.DataType.INT32),
                            ("Delay/ACC", sp.DataType.INT32), ("Delay/DN", sp.DataType.BOOLEAN)]:
            m = dm.get(name)
            check(m is not None and m.datatype == dtype and m.alias is not None,
                  f"DBIRTH metric {name}: {dtype.name} with an alias ({m and m.datatype}, {m and m.alias})")
        aliases = [m.alias for m in dbirth.metrics + mbirth.metrics]
        check(len(set(aliases)) == len(aliases), "aliases are unique in the node")
        # DDATA: by alias, decoded with the birth; seq continues and wraps.
        seqs = [dbirth.seq]
        idx = k
        scans_alias = dm["Scans"].alias
        scans_seen = []
        deadline = time.time() + 30
        while time.time() < deadline and len(seqs) < 300:
            idx2, raw = host.wait("DDATA", idx + 1, timeout=5, device=DEVICE)
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
        k, raw = host.wait("DDATA", idx, device=DEVICE, pred=lambda p: any(
            m.alias == dm["Setp"].alias and m.value == 321 for m in sp.DData.decode(p, birth=dbirth).metrics))
        check(raw is not None, "and comes back in a DDATA")
        # A device's own DCMD and DDATA.
        cmd = sp.DCmd(timestamp=sp.get_current_timestamp(),
                      metrics=(sp.Metric(timestamp=None, name="Speed", datatype=sp.DataType.INT32, value=77),))
        host.publish(f"{BASE}/DCMD/{NODE}/motion", cmd.encode())
        k, raw = host.wait("DDATA", idx, device="motion", pred=lambda p: any(
            m.alias == mm["Speed"].alias and m.value == 77 for m in sp.DData.decode(p, birth=mbirth).metrics))
        check(raw is not None and api(http, "/api/tags/Speed")["value"] == 77,
              "a DCMD to device motion writes Speed; its DDATA comes on motion's topic")
        cmd = sp.DCmd(timestamp=sp.get_current_timestamp(),
                      metrics=(sp.Metric(timestamp=None, name="Speed", datatype=sp.DataType.INT32, value=5),))
        host.publish(f"{BASE}/DCMD/{NODE}/{DEVICE}", cmd.encode())
        time.sleep(0.5)
        check(api(http, "/api/tags/Speed")["value"] == 77, f"a DCMD to {DEVICE} for motion's Speed is refused")
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
        k, raw = host.wait("DBIRTH", mark, device=DEVICE)
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
        # bdSeq is kept across restarts (.alba/sparkplug.json): the next run's NBIRTH has the next one.
        mark = len(host.msgs)
        alba, http = start_alba(binary, proj, f"127.0.0.1:{port}")
        k, raw = host.wait("NBIRTH", mark)
        check(raw is not None and metrics_by_name(sp.NBirth.decode(raw))["bdSeq"].value == nm["bdSeq"].value + 1,
              "after a restart, the NBIRTH's bdSeq is the last one's + 1")
    finally:
        if alba.poll() is None:
            alba.kill()
        broker.kill()
    bad_devices(binary, project)
    big_birth_check(binary)
    v5_check(binary, project)
    state_checks(binary, project)
    if failures:
        print(f"{len(failures)} Sparkplug check(s) failed", flush=True)
        sys.exit(1)
    print("Sparkplug B: all checks passed", flush=True)


def bad_devices(binary, project):
    """A tag in two devices, or a name no tag has: `alba run` says so and stops."""
    for devices, want in [('a = ["Speed"]\nb = ["Speed"]', "`Speed` is in both a and b"),
                          ('a = ["Nope"]', "`Nope` is not a published tag")]:
        proj = os.path.join(tempfile.mkdtemp(prefix="alba-spb-bad-"), "project")
        shutil.copytree(project, proj)
        with open(os.path.join(proj, "alba.toml"), "a") as f:
            f.write(f'\n[mqtt]\nbroker = "127.0.0.1:{free_port()}"\n[mqtt.sparkplug]\n[mqtt.sparkplug.devices]\n{devices}\n')
        r = subprocess.run([binary, "run", proj, "--http", "127.0.0.1:0", "--no-native"], capture_output=True,
                           text=True, timeout=60)
        check(r.returncode != 0 and want in r.stderr, f"{want}: alba run stops ({r.returncode}, {r.stderr.strip()})")


def big_birth_check(binary):
    """A project of 1 500 tags: a DBIRTH of tens of kilobytes (rumqttc's default packet limit is 10 KiB)."""
    n = 1500
    proj = os.path.join(tempfile.mkdtemp(prefix="alba-spb-big-"), "project")
    os.makedirs(proj)
    with open(os.path.join(proj, "alba.toml"), "w") as f:
        f.write(f'name = "big"\nscan_ms = 10\nprograms = ["main.lad"]\n[history]\nenabled = false\n'
                f'[mqtt]\n[mqtt.sparkplug]\ngroup_id = "{GROUP}"\nedge_node_id = "big"\n')
    with open(os.path.join(proj, "tags.csv"), "w") as f:
        f.write("name,type,address,initial,retain,description\n" + "".join(f"V_{i},DINT,,,,\n" for i in range(n)))
    with open(os.path.join(proj, "main.lad"), "w") as f:
        f.write("".join(f"ADD(V_{i},1,V_{i});\n" for i in range(0, n, 10)))
    port = free_port()
    broker = start_broker(port, os.path.dirname(proj))
    host = Recorder(port)
    alba, http = start_alba(binary, proj, f"127.0.0.1:{port}")
    try:
        k, raw = host.wait("DBIRTH", timeout=20)
        birth = sp.DBirth.decode(raw) if raw else None
        names = {m.name for m in birth.metrics} if birth else set()
        check(birth is not None and {f"V_{i}" for i in range(n)} <= names,
              f"a DBIRTH of {len(raw or b'')} bytes with all {n} tags")
        k, raw = host.wait("DDATA", k or 0)
        check(raw is not None and len(sp.DData.decode(raw, birth=birth).metrics) >= n // 10,
              "and DDATA with every changing tag")
    finally:
        alba.kill()
        broker.kill()


def v5_check(binary, project):
    """The same edge node over MQTT 5 (`[mqtt] version = 5`)."""
    tmp = tempfile.mkdtemp(prefix="alba-spb5-")
    proj = os.path.join(tmp, "project")
    shutil.copytree(project, proj)
    with open(os.path.join(proj, "alba.toml"), "a") as f:
        f.write(f'\n[mqtt]\nversion = 5\nkeep_alive_s = 5\n[mqtt.sparkplug]\ngroup_id = "{GROUP}"\nedge_node_id = "{NODE}"\n')
    port = free_port()
    broker = start_broker(port, tmp)
    host = Recorder(port)
    alba, http = start_alba(binary, proj, f"127.0.0.1:{port}")
    try:
        k, raw = host.wait("NBIRTH")
        k, raw = host.wait("DBIRTH", k)
        dbirth = sp.DBirth.decode(raw) if raw else None
        k, raw = host.wait("DDATA", k) if raw else (None, None)
        check(raw is not None and sp.DData.decode(raw, birth=dbirth).seq == 2,
              "MQTT 5: NBIRTH, DBIRTH and DDATA decoded")
        cmd = sp.DCmd(timestamp=sp.get_current_timestamp(),
                      metrics=(sp.Metric(timestamp=None, name="Setp", datatype=sp.DataType.INT16, value=99),))
        host.publish(f"{BASE}/DCMD/{NODE}/{DEVICE}", cmd.encode())
        deadline = time.time() + 5
        while time.time() < deadline and api(http, "/api/tags/Setp")["value"] != 99:
            time.sleep(0.05)
        check(api(http, "/api/tags/Setp")["value"] == 99, "MQTT 5: a DCMD write")
        mark = host.mark()
        alba.kill()
        alba.wait()
        check(host.wait("NDEATH", mark, timeout=60)[1] is not None, "MQTT 5: the NDEATH will after kill -9")
    finally:
        if alba.poll() is None:
            alba.kill()
        broker.kill()


HOST = "scada"
STATE = f"spBv1.0/STATE/{HOST}"


def host_state(host, online, ts):
    host.publish(STATE, json.dumps({"online": online, "timestamp": ts}), retain=True)


def write_setp(http, values):
    """Writes each value, one per scan or more (each its own snapshot)."""
    for v in values:
        put(http, "/api/tags/Setp", v)
        time.sleep(0.03)


def replayed(host, k, dbirth, setp, scans):
    """The DDATA after index k until a live one: each (seq, Setp values,
    Scans values, timestamps, all historical) of the historical ones, and
    the first live one."""
    hist, live = [], None
    deadline = time.time() + 30
    idx = k
    while time.time() < deadline and live is None:
        i, raw = host.wait("DDATA", idx + 1, timeout=5)
        if raw is None:
            break
        idx = i
        d = sp.DData.decode(raw, birth=dbirth)
        flags = {m.is_historical for m in d.metrics}
        if flags == {True}:
            hist.append(d)
        elif flags == {False}:
            live = d
        else:
            check(False, f"a DDATA mixes historical and live metrics (seq {d.seq})")
            break
    return hist, live


def state_checks(binary, project):
    tmp = tempfile.mkdtemp(prefix="alba-spb-state-")
    proj = os.path.join(tmp, "project")
    shutil.copytree(project, proj)
    with open(os.path.join(proj, "alba.toml"), "a") as f:
        f.write(f'\n[mqtt]\nkeep_alive_s = 5\n[mqtt.sparkplug]\ngroup_id = "{GROUP}"\nedge_node_id = "{NODE}"\n'
                f'primary_host_id = "{HOST}"\n')
    port = free_port()
    broker = start_broker(port, tmp)
    host = Recorder(port)
    t0 = int(time.time() * 1000)
    host_state(host, False, t0)
    alba, http = start_alba(binary, proj, f"127.0.0.1:{port}")
    try:
        print("primary host STATE:", flush=True)
        time.sleep(1.5)
        check(not host.since(0, "NBIRTH"), "no NBIRTH while the primary host's STATE says offline")
        mark = host.mark()
        t1 = t0 + 1000
        host_state(host, True, t1)
        k, raw = host.wait("NBIRTH", mark)
        check(raw is not None, "NBIRTH once the STATE says online")
        k, raw = host.wait("DBIRTH", mark)
        dbirth = sp.DBirth.decode(raw)
        dm = metrics_by_name(dbirth)
        setp, scans = dm["Setp"].alias, dm["Scans"].alias
        # What was buffered before the first birth comes now, historical.
        hist, live = replayed(host, k, dbirth, setp, scans)
        check(live is not None, "then live DDATA")
        # Offline: an NDEATH, then nothing.
        mark = host.mark()
        host_state(host, False, t1)
        k, raw = host.wait("NDEATH", mark)
        check(raw is not None, "an offline STATE: NDEATH")
        time.sleep(0.3)
        write_setp(http, range(1, 41))
        time.sleep(0.5)
        lk = link(http)
        check(lk["protocol"] == "sparkplug" and lk["connected"] and not lk["ok"]
              and "primary host scada is offline" in (lk["last_error"] or "") and lk["queue"]["buffered"] > 40,
              f"/api/status: connected, holding data for the primary host, records buffered ({lk})")
        check(not [m for m in host.since(k + 1) if m[1].split("/")[2] in ("DDATA", "NBIRTH", "DBIRTH")],
              "nothing published while the primary host is offline")
        # A stale online STATE (older than the offline one that counted) changes nothing.
        host_state(host, True, t1 - 500)
        time.sleep(0.8)
        check(not host.since(k + 1, "NBIRTH"), "a stale online STATE is ignored")
        # Online again: births, the buffered values in order, then live.
        mark = host.mark()
        t2 = t1 + 1000
        host_state(host, True, t2)
        k, raw = host.wait("NBIRTH", mark)
        check(raw is not None, "online again: NBIRTH")
        k, raw = host.wait("DBIRTH", mark)
        dbirth = sp.DBirth.decode(raw)
        check(metrics_by_name(dbirth)["Setp"].value == 40, "the DBIRTH has the current value")
        hist, live = replayed(host, k, dbirth, setp, scans)
        check(len(hist) > 10, f"the buffered data is replayed ({len(hist)} DDATA)")
        seqs = [dbirth.seq] + [d.seq for d in hist] + ([live.seq] if live else [])
        check(all((b - a) % 256 == 1 for a, b in zip(seqs, seqs[1:])), "seq goes on through the replay")
        values = [m.value for d in hist for m in d.metrics if m.alias == setp]
        check(values == list(range(1, 41)), f"every value written while offline, in order ({values})")
        stamps = [m.timestamp for d in hist for m in d.metrics]
        check(stamps == sorted(stamps) and stamps and stamps[0] < dbirth.timestamp,
              "with their own timestamps, oldest first, older than the birth")
        counts = [m.value for d in hist for m in d.metrics if m.alias == scans]
        check(counts == sorted(counts) and len(set(counts)) == len(counts), "Scans rises through the replay")
        check(live is not None and all(not m.is_historical for m in live.metrics), "then live data")
        lk = link(http)
        check(lk["ok"] and lk["queue"]["buffered"] == 0 and lk["queue"]["replayed"] >= len(hist)
              and lk["queue"]["dropped"] == 0, f"/api/status: ok, the buffer empty, nothing dropped ({lk['queue']})")
        # A stale offline STATE (older than the online one) is ignored.
        mark = host.mark()
        host_state(host, False, t1)
        time.sleep(0.8)
        check(not host.since(mark, "NDEATH"), "a stale offline STATE is ignored")
        # Across a restart: buffered on disk by one process, sent by the next.
        t3 = t2 + 1000
        host_state(host, False, t3)
        k, raw = host.wait("NDEATH", mark)
        check(raw is not None, "offline again: NDEATH")
        time.sleep(0.3)
        write_setp(http, range(100, 121))
        time.sleep(0.3)
        alba.send_signal(signal.SIGKILL)
        alba.wait()
        alba, http = start_alba(binary, proj, f"127.0.0.1:{port}")
        time.sleep(0.5)
        write_setp(http, range(121, 131))
        mark = host.mark()
        host_state(host, True, t3 + 1000)
        k, raw = host.wait("NBIRTH", mark)
        check(raw is not None, "after kill -9 and a restart: NBIRTH once online")
        k, raw = host.wait("DBIRTH", mark)
        dbirth = sp.DBirth.decode(raw)
        dm = metrics_by_name(dbirth)
        hist, live = replayed(host, k, dbirth, dm["Setp"].alias, dm["Scans"].alias)
        values = [m.value for d in hist for m in d.metrics if m.alias == dm["Setp"].alias]
        # Setp is not retentive: the new process starts it at 0.
        check(values == list(range(100, 121)) + [0] + list(range(121, 131)),
              f"both processes' values, in order ({values})")
        stamps = [m.timestamp for d in hist for m in d.metrics]
        check(stamps == sorted(stamps), "oldest first")
        # A bound of 10 records: the oldest are dropped, counted; the newest 10 replayed.
        alba.kill()
        alba.wait()
        with open(os.path.join(proj, "alba.toml"), "a") as f:
            f.write("buffer_max = 10\n")
        host_state(host, False, t3 + 2000)
        alba, http = start_alba(binary, proj, f"127.0.0.1:{port}")
        write_setp(http, range(200, 230))
        time.sleep(0.3)
        before = link(http)["queue"]
        check(before["buffered"] == 10 and before["dropped"] > 20,
              f"buffer_max = 10: 10 records kept, the oldest dropped and counted ({before})")
        mark = host.mark()
        host_state(host, True, t3 + 3000)
        k, raw = host.wait("DBIRTH", mark)
        dbirth = sp.DBirth.decode(raw)
        dm = metrics_by_name(dbirth)
        hist, live = replayed(host, k, dbirth, dm["Setp"].alias, dm["Scans"].alias)
        counts = [m.value for d in hist for m in d.metrics if m.alias == dm["Scans"].alias]
        check(len(hist) == 10 and counts == sorted(counts) and counts[-1] <= dm["Scans"].value,
              f"the 10 newest records replayed, in order ({len(hist)}: {counts}, birth {dm['Scans'].value})")
    finally:
        if alba.poll() is None:
            alba.kill()
        broker.kill()


if __name__ == "__main__":
    main()
