#!/usr/bin/env python3
"""Alba's MQTT client (`alba run --mqtt`) against Mosquitto and paho-mqtt
(both written elsewhere).

Usage: mqtt_client.py ALBA_BINARY PROJECT_DIR

Starts a Mosquitto broker on a free loopback port (a temporary config, no
persistence), `alba run PROJECT --mqtt 127.0.0.1:PORT`, and checks with a
paho-mqtt client (SPEC §10.5, docs/scale-out.md):
- `alba/<project>/status` is `online`, retained;
- every tag is published on `alba/<project>/tags/<Tag>` (members as
  `<Tag>.<MEMBER>`) as {"value", "ts"}, retained (a late subscriber gets
  them), and again on change;
- a write on `alba/<project>/set/<Tag>` reaches the engine (the HTTP API reads
  it) and is audited (user `mqtt`); writes to an input, to a read-only
  member, to an unknown tag, with a bad payload are refused on
  `alba/<project>/error` and change nothing;
- `/api/status` shows the broker link (`connections`, name `mqtt`): connected,
  its queue's counters (published rising); after the broker restarted,
  one more connection and the loss counted;
- the broker restarted: Alba reconnects and publishes everything again;
- `kill -9` of Alba: the broker sends its last will, status `offline`;
- a "broker" that accepts the connection and never answers: Alba keeps
  scanning (the scan count rises);
- `[mqtt] deadband = 0.5`: a REAL moving less than 0.5 from the value last
  published is not published, one moving more is; `publish_interval_ms =
  200`: a tag changing every scan is published at most every 200 ms (by the
  messages' own timestamps);
- a broker that requires a password (Mosquitto's password_file): `[mqtt]
  user` names a user of the project's users.toml, its broker password in
  `password_file`; a wrong one is refused by the broker (said in
  /api/status, the password never in Alba's output or status), the file
  corrected is used at the next attempt without a restart; writes are
  audited as that user, and refused for a viewer; an unknown user stops
  `alba run`;
- MQTT 5 (`[mqtt] version = 5`) against a paho MQTT 5 client: status and
  tags retained, JSON messages flagged UTF-8 `application/json` (payload
  format indicator, content type), writes and refusals, a write with a
  response topic answered there with its correlation data, the last will
  on `kill -9`;
- TLS with a client certificate (`[mqtt] ca_file`, `client_cert`,
  `client_key`) against a Mosquitto listener that requires one (certificates
  made with openssl): tags arrive; a client certificate from another CA is
  refused by the broker, and Alba says so and keeps scanning.
"""

import json
import os
import shutil
import re
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request

import paho.mqtt.client as mqtt

failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print(f"  FAIL: {what}", flush=True)
    else:
        print(f"  ok: {what}", flush=True)


def client(cid):
    """A paho client (paho-mqtt 1.6, which pysparkplug requires, or 2.x)."""
    if hasattr(mqtt, "CallbackAPIVersion"):
        return mqtt.Client(mqtt.CallbackAPIVersion.VERSION2, client_id=cid)
    return mqtt.Client(client_id=cid)


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def start_broker(port, tmp, extra="", anonymous=True):
    conf = os.path.join(tmp, "mosquitto.conf")
    with open(conf, "w") as f:
        f.write(f"listener {port} 127.0.0.1\nallow_anonymous {str(anonymous).lower()}\npersistence false\n{extra}")
    p = subprocess.Popen(["mosquitto", "-c", conf], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 10
    while time.time() < deadline:
        try:
            socket.create_connection(("127.0.0.1", port), timeout=0.2).close()
            return p
        except OSError:
            time.sleep(0.05)
    raise SystemExit("mosquitto did not start")


def start_alba(binary, project, broker):
    p = subprocess.Popen([binary, "run", project, "--http", "127.0.0.1:0", "--mqtt", broker, "--no-native"],
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    deadline = time.time() + 60
    http = None
    while time.time() < deadline and not http:
        line = p.stdout.readline()
        if not line:
            raise SystemExit(f"alba run ended: exit {p.wait()}")
        m = re.search(r"http://([\d.]+:\d+)/", line)
        if m:
            http = "http://" + m.group(1)
    p.output = []
    threading.Thread(target=lambda: p.output.extend(p.stdout), daemon=True).start()
    return p, http


def api(http, path):
    with urllib.request.urlopen(http + path, timeout=10) as r:
        return json.loads(r.read())


def put(http, path, value):
    req = urllib.request.Request(http + path, data=json.dumps({"value": value}).encode(), method="PUT",
                                 headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=10) as r:
        return json.loads(r.read())


class Watcher:
    """A paho client that records every message under a prefix."""

    def __init__(self, port, topic):
        self.msgs = []
        self.lock = threading.Lock()
        self.c = client(f"watch-{time.time_ns()}")
        self.c.on_message = self.on_message
        self.c.connect("127.0.0.1", port)
        self.c.subscribe(topic, qos=1)
        self.c.loop_start()

    def on_message(self, _c, _u, m):
        with self.lock:
            self.msgs.append((m.topic, m.payload.decode(errors="replace"), m.retain))

    def wait(self, what, pred, timeout=10):
        deadline = time.time() + timeout
        while time.time() < deadline:
            with self.lock:
                for t in self.msgs:
                    if pred(*t):
                        return t
            time.sleep(0.02)
        return None

    def clear(self):
        with self.lock:
            self.msgs.clear()

    def close(self):
        self.c.loop_stop()
        self.c.disconnect()


def publish(port, topic, payload):
    c = client(f"pub-{time.time_ns()}")
    c.connect("127.0.0.1", port)
    c.loop_start()
    c.publish(topic, payload, qos=1).wait_for_publish(5)
    c.loop_stop()
    c.disconnect()


def link(http):
    """The broker link in /api/status."""
    return next((c for c in api(http, "/api/status")["connections"] if c["name"] == "mqtt"), None)


def main():
    binary, project = sys.argv[1], sys.argv[2]
    name = re.search(r'^name\s*=\s*"([^"]+)"', open(os.path.join(project, "alba.toml")).read(), re.M).group(1)
    prefix = f"alba/{name}"
    # A short keep-alive, so that the broker notices the kill -9 within seconds.
    with open(os.path.join(project, "alba.toml"), "a") as f:
        f.write("\n[mqtt]\nkeep_alive_s = 5\n")
    tmp = tempfile.mkdtemp(prefix="alba-mqtt-")
    port = free_port()
    broker = start_broker(port, tmp)
    alba, http = start_alba(binary, project, f"127.0.0.1:{port}")
    try:
        w = Watcher(port, f"{prefix}/#")
        check(w.wait("online", lambda t, p, r: t == f"{prefix}/status" and p == "online") is not None, "status online")
        m = w.wait("a tag", lambda t, p, r: t == f"{prefix}/tags/Setp")
        check(m is not None, "Setp published")
        if m:
            j = json.loads(m[1])
            check(set(j) == {"value", "ts"} and isinstance(j["ts"], int) and j["ts"] > 1.6e12, f"payload {m[1]}")
        lk = link(http)
        check(lk is not None and lk["protocol"] == "mqtt" and lk["connected"] and lk["ok"]
              and lk["endpoint"] == f"127.0.0.1:{port}" and lk["connects"] == 1, f"/api/status: the broker link {lk}")
        if lk:
            q = lk["queue"]
            check(q["published"] > 0 and q["dropped"] == 0 and q["capacity"] == 10000, f"its queue counters {q}")
        # A late subscriber gets the retained values (and the status).
        late = Watcher(port, f"{prefix}/#")
        r = late.wait("retained", lambda t, p, r: t == f"{prefix}/tags/Setp" and r)
        check(r is not None, "tags are retained")
        check(late.wait("retained status", lambda t, p, r: t == f"{prefix}/status" and r and p == "online") is not None,
              "status retained")
        late.close()
        # A write through set/.
        w.clear()
        publish(port, f"{prefix}/set/Setp", json.dumps({"value": 1234}))
        m = w.wait("Setp 1234", lambda t, p, r: t == f"{prefix}/tags/Setp" and json.loads(p)["value"] == 1234)
        check(m is not None, "a write on set/Setp is published back")
        check(api(http, "/api/tags/Setp")["value"] == 1234, "the engine holds the written value")
        audit = api(http, "/api/audit?action=write&target=Setp")
        rows = audit.get("rows", audit) if isinstance(audit, dict) else audit
        check(any(r.get("user") == "mqtt" and r.get("new") == 1234 for r in rows), f"the write is audited: {rows[:2]}")
        # Refused writes.
        for tag, payload, want in [
            ("Start", json.dumps({"value": True}), "input"),
            ("Nope", json.dumps({"value": 1}), "Nope"),
            ("Setp", "not json", "not JSON"),
            ("Setp", json.dumps({"v": 1}), "value"),
            ("Setp", json.dumps({"value": 99999}), "Setp"),
        ]:
            w.clear()
            publish(port, f"{prefix}/set/{tag}", payload)
            e = w.wait("error", lambda t, p, r: t == f"{prefix}/error")
            check(e is not None and want in e[1] and json.loads(e[1])["tag"] == tag, f"set/{tag} {payload!r} refused: {e}")
        check(api(http, "/api/tags/Setp")["value"] == 1234, "refused writes changed nothing")
        check(api(http, "/api/tags/Start")["value"] is False, "the input was not written")
        # The broker restarts: Alba reconnects and republishes everything.
        w.close()
        broker.send_signal(signal.SIGKILL)
        broker.wait()
        time.sleep(0.5)
        broker = start_broker(port, tmp)
        w = Watcher(port, f"{prefix}/#")
        check(w.wait("online again", lambda t, p, r: t == f"{prefix}/status" and p == "online", timeout=40) is not None,
              "online again after a broker restart")
        check(w.wait("republished", lambda t, p, r: t == f"{prefix}/tags/Setp" and json.loads(p)["value"] == 1234,
                     timeout=20) is not None, "every tag republished after the restart")
        lk2 = link(http)
        check(lk2["connected"] and lk2["connects"] == 2 and lk2["errors"] >= 1
              and lk2["queue"]["published"] > lk["queue"]["published"],
              f"/api/status: a reconnection, the loss counted ({lk2['connects']} connects, {lk2['errors']} errors)")
        # kill -9: the last will.
        w.clear()
        alba.send_signal(signal.SIGKILL)
        alba.wait()
        check(w.wait("offline", lambda t, p, r: t == f"{prefix}/status" and p == "offline", timeout=60) is not None,
              "last will: offline after kill -9")
        w.close()
    finally:
        if alba.poll() is None:
            alba.kill()
        broker.kill()
    # A broker that accepts and never answers does not stall the scan.
    silent = socket.socket()
    silent.bind(("127.0.0.1", 0))
    silent.listen(8)
    held = []
    threading.Thread(target=lambda: [held.append(silent.accept()) for _ in range(8)], daemon=True).start()
    alba, http = start_alba(binary, project, f"127.0.0.1:{silent.getsockname()[1]}")
    try:
        s1 = api(http, "/api/status")["scans"]
        time.sleep(1.0)
        s2 = api(http, "/api/status")["scans"]
        check(s2 > s1 + 20, f"a silent broker does not stall the scan ({s1} -> {s2})")
        lk = link(http)
        check(lk is not None and not lk["connected"] and not lk["ok"], f"/api/status: not connected ({lk})")
    finally:
        alba.kill()
    tls_checks(binary, project)
    deadband_and_interval_checks(binary, project)
    auth_checks(binary, project)
    v5_checks(binary, project)
    if failures:
        print(f"{len(failures)} MQTT check(s) failed", flush=True)
        sys.exit(1)
    print("MQTT: all checks passed", flush=True)


def openssl(*args, cwd):
    subprocess.run(["openssl", *args], cwd=cwd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def make_ca(d, name):
    openssl("req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "2", "-subj", f"/CN={name}",
            "-keyout", f"{name}.key", "-out", f"{name}.pem", cwd=d)


def make_cert(d, ca, name, san):
    openssl("req", "-newkey", "rsa:2048", "-nodes", "-subj", f"/CN={name}", "-keyout", f"{name}.key",
            "-out", f"{name}.csr", cwd=d)
    with open(os.path.join(d, f"{name}.ext"), "w") as f:
        f.write(f"subjectAltName={san}\n")
    openssl("x509", "-req", "-in", f"{name}.csr", "-CA", f"{ca}.pem", "-CAkey", f"{ca}.key", "-CAcreateserial",
            "-days", "2", "-extfile", f"{name}.ext", "-out", f"{name}.pem", cwd=d)


def tls_checks(binary, project):
    tmp = tempfile.mkdtemp(prefix="alba-mqtts-")
    make_ca(tmp, "ca")
    make_ca(tmp, "rogue")
    make_cert(tmp, "ca", "broker", "IP:127.0.0.1,DNS:localhost")
    make_cert(tmp, "ca", "alba", "DNS:alba")
    make_cert(tmp, "rogue", "intruder", "DNS:alba")
    # Mosquitto started as root reads its files as the user `mosquitto`.
    os.chmod(tmp, 0o755)
    for f in os.listdir(tmp):
        os.chmod(os.path.join(tmp, f), 0o644)
    port = free_port()
    broker = start_broker(port, tmp, f"cafile {tmp}/ca.pem\ncertfile {tmp}/broker.pem\nkeyfile {tmp}/broker.key\n"
                          "require_certificate true\n")
    alba = None
    try:
        for who, want in [("alba", True), ("intruder", False)]:
            proj = os.path.join(tmp, f"project-{who}")
            shutil.copytree(project, proj)
            for f in ["ca.pem", f"{who}.pem", f"{who}.key"]:
                shutil.copy(os.path.join(tmp, f), proj)
            with open(os.path.join(proj, "alba.toml"), "a") as f:
                f.write(f'ca_file = "ca.pem"\nclient_cert = "{who}.pem"\nclient_key = "{who}.key"\n'
                        f'topic_prefix = "tls/{who}"\n')
            alba, http = start_alba(binary, proj, f"127.0.0.1:{port}")
            w = client(f"tls-watch-{who}")
            w.tls_set(ca_certs=f"{tmp}/ca.pem", certfile=f"{tmp}/alba.pem", keyfile=f"{tmp}/alba.key")
            got = []
            w.on_message = lambda _c, _u, m: got.append(m.topic)
            w.connect("127.0.0.1", port)
            w.subscribe(f"tls/{who}/tags/#")
            w.loop_start()
            deadline = time.time() + (10 if want else 3)
            while time.time() < deadline and not got:
                time.sleep(0.05)
            w.loop_stop()
            w.disconnect()
            if want:
                check(bool(got), f"TLS with a client certificate: tags arrive ({len(got)})")
            else:
                check(not got, "a client certificate from another CA is refused by the broker")
                s1 = api(http, "/api/status")["scans"]
                time.sleep(0.5)
                check(api(http, "/api/status")["scans"] > s1, "and Alba keeps scanning")
            alba.kill()
            alba.wait()
    finally:
        if alba and alba.poll() is None:
            alba.kill()
        broker.kill()


def deadband_and_interval_checks(binary, project):
    tmp = tempfile.mkdtemp(prefix="alba-mqtt-db-")
    proj = os.path.join(tmp, "project")
    shutil.copytree(project, proj)
    with open(os.path.join(proj, "alba.toml"), "a") as f:
        f.write("publish_interval_ms = 200\ndeadband = 0.5\n")
    name = re.search(r'^name\s*=\s*"([^"]+)"', open(os.path.join(proj, "alba.toml")).read(), re.M).group(1)
    prefix = f"alba/{name}/tags"
    port = free_port()
    broker = start_broker(port, tmp)
    alba, http = start_alba(binary, proj, f"127.0.0.1:{port}")
    w = Watcher(port, f"{prefix}/#")

    def temps():
        with w.lock:
            return [json.loads(p)["value"] for t, p, _ in w.msgs if t == f"{prefix}/Temp"]

    try:
        print("deadband and publish interval:", flush=True)
        put(http, "/api/tags/Temp", 10.0)
        check(w.wait("Temp 10", lambda t, p, r: t == f"{prefix}/Temp" and json.loads(p)["value"] == 10.0)
              is not None, "Temp 10.0 published")
        for v in (10.3, 9.7, 10.45):
            put(http, "/api/tags/Temp", v)
            time.sleep(0.5)
        check(temps()[temps().index(10.0):] == [10.0], f"moves within the deadband are not published {temps()}")
        put(http, "/api/tags/Temp", 10.6)
        check(w.wait("Temp 10.6", lambda t, p, r: t == f"{prefix}/Temp" and abs(json.loads(p)["value"] - 10.6) < 1e-4)
              is not None, "a move of more than the deadband is")
        put(http, "/api/tags/Temp", 10.2)
        time.sleep(0.5)
        check(abs(temps()[-1] - 10.6) < 1e-4, "measured from the value last published (10.6 -> 10.2: not published)")
        w.clear()
        time.sleep(2.0)
        with w.lock:
            ts = [json.loads(p)["ts"] for t, p, _ in w.msgs if t == f"{prefix}/Scans"]
        gaps = [b - a for a, b in zip(ts, ts[1:])]
        check(2 <= len(ts) <= 12 and gaps and min(gaps) >= 150,
              f"Scans (changing every scan) published at most every 200 ms: {len(ts)} in 2 s, gaps {gaps}")
        w.close()
    finally:
        alba.kill()
        broker.kill()


ALBA_PW = "correct horse battery staple"


def session(http, user):
    body = json.dumps({"user": user, "password": ALBA_PW}).encode()
    req = urllib.request.Request(http + "/api/login", data=body, method="POST",
                                 headers={"Content-Type": "application/json", "Origin": http})
    with urllib.request.urlopen(req, timeout=10) as r:
        token = json.loads(r.read())["token"]

    def get(path):
        req = urllib.request.Request(http + path, headers={"Authorization": f"Bearer {token}"})
        with urllib.request.urlopen(req, timeout=10) as r:
            return json.loads(r.read())
    return get


def auth_checks(binary, project):
    print("broker accounts:", flush=True)
    tmp = tempfile.mkdtemp(prefix="alba-mqtt-auth-")
    os.chmod(tmp, 0o755)
    pwfile = os.path.join(tmp, "broker.passwd")
    broker_pw = {"line1": "line1-broker-secret", "watcher": "watcher-broker-secret"}
    for k, (user, pw) in enumerate(broker_pw.items()):
        subprocess.run(["mosquitto_passwd", "-b"] + (["-c"] if k == 0 else []) + [pwfile, user, pw], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.chmod(pwfile, 0o644)
    port = free_port()
    broker = start_broker(port, tmp, f"password_file {pwfile}\n", anonymous=False)
    proj = os.path.join(tmp, "project")
    shutil.copytree(project, proj)
    for user, role in [("line1", "operator"), ("watcher", "viewer"), ("tech", "engineer")]:
        subprocess.run([binary, "user", "add", "--role", role, proj, user], input=ALBA_PW + "\n", text=True,
                       check=True, capture_output=True)
    secret = os.path.join(proj, "mqtt.secret")
    with open(secret, "w") as f:
        f.write("not-the-password\n")
    os.chmod(secret, 0o600)
    toml = open(os.path.join(proj, "alba.toml")).read()
    name = re.search(r'^name\s*=\s*"([^"]+)"', toml, re.M).group(1)
    prefix = f"alba/{name}"

    def run_as(user):
        with open(os.path.join(proj, "alba.toml"), "w") as f:
            f.write(toml + f'user = "{user}"\npassword_file = "mqtt.secret"\n')
        return start_alba(binary, proj, f"127.0.0.1:{port}")

    def watcher():
        w = client(f"auth-watch-{time.time_ns()}")
        w.username_pw_set("watcher", broker_pw["watcher"])
        got = []
        w.on_message = lambda _c, _u, m: got.append((m.topic, m.payload.decode()))
        w.connect("127.0.0.1", port)
        w.subscribe(f"{prefix}/#", qos=1)
        w.loop_start()
        return w, got

    alba = None
    try:
        alba, http = run_as("line1")
        get = session(http, "tech")
        time.sleep(1.5)
        lk = next(c for c in get("/api/status")["connections"] if c["name"] == "mqtt")
        check(not lk["connected"] and lk["errors"] >= 1 and lk["last_error"],
              f"a wrong broker password: refused by the broker, said in /api/status ({lk['last_error']})")
        check("not-the-password" not in json.dumps(lk) and not any("not-the-password" in l for l in alba.output),
              "the password is never in Alba's output or status")
        with open(secret, "w") as f:
            f.write(broker_pw["line1"] + "\n")
        w, got = watcher()
        deadline = time.time() + 40
        while time.time() < deadline and (f"{prefix}/status", "online") not in got:
            time.sleep(0.1)
        check((f"{prefix}/status", "online") in got, "the corrected password file is used at the next attempt")
        publish_as(port, "watcher", broker_pw["watcher"], f"{prefix}/set/Setp", json.dumps({"value": 4321}))
        deadline = time.time() + 5
        while time.time() < deadline and get("/api/tags/Setp")["value"] != 4321:
            time.sleep(0.05)
        rows = get("/api/audit?action=write&target=Setp")
        rows = rows.get("rows", rows) if isinstance(rows, dict) else rows
        check(any(r.get("user") == "line1" and r.get("new") == 4321 for r in rows),
              f"a write through MQTT is audited as the project user line1 ({rows[:1]})")
        w.loop_stop()
        w.disconnect()
        alba.kill()
        alba.wait()
        # A viewer: connected, its writes refused.
        with open(secret, "w") as f:
            f.write(broker_pw["watcher"] + "\n")
        alba, http = run_as("watcher")
        w, got = watcher()
        deadline = time.time() + 10
        while time.time() < deadline and (f"{prefix}/status", "online") not in got:
            time.sleep(0.1)
        publish_as(port, "watcher", broker_pw["watcher"], f"{prefix}/set/Setp", json.dumps({"value": 7}))
        deadline = time.time() + 5
        while time.time() < deadline and not any(t == f"{prefix}/error" for t, _ in got):
            time.sleep(0.05)
        errs = [p for t, p in got if t == f"{prefix}/error"]
        check(errs and "viewer" in errs[0], f"user watcher (a viewer): its writes are refused ({errs[:1]})")
        w.loop_stop()
        w.disconnect()
        alba.kill()
        alba.wait()
        alba = None
        with open(os.path.join(proj, "alba.toml"), "w") as f:
            f.write(toml + 'user = "nobody"\npassword_file = "mqtt.secret"\n')
        r = subprocess.run([binary, "run", proj, "--http", "127.0.0.1:0", "--mqtt", f"127.0.0.1:{port}", "--no-native"],
                           capture_output=True, text=True, timeout=60)
        check(r.returncode != 0 and "nobody" in r.stderr and "users.toml" in r.stderr,
              f"an unknown user stops alba run ({r.stderr.strip()})")
    finally:
        if alba and alba.poll() is None:
            alba.kill()
        broker.kill()


def v5_checks(binary, project):
    from paho.mqtt.packettypes import PacketTypes
    from paho.mqtt.properties import Properties
    print("MQTT 5:", flush=True)
    tmp = tempfile.mkdtemp(prefix="alba-mqtt5-")
    proj = os.path.join(tmp, "project")
    shutil.copytree(project, proj)
    with open(os.path.join(proj, "alba.toml"), "a") as f:
        f.write("version = 5\n")
    name = re.search(r'^name\s*=\s*"([^"]+)"', open(os.path.join(proj, "alba.toml")).read(), re.M).group(1)
    prefix = f"alba/{name}"
    port = free_port()
    broker = start_broker(port, tmp)
    alba, http = start_alba(binary, proj, f"127.0.0.1:{port}")
    got, lock = [], threading.Lock()

    def on_message(_c, _u, m):
        with lock:
            got.append((m.topic, m.payload.decode(errors="replace"), m.retain, m.properties))

    def wait(pred, timeout=10):
        deadline = time.time() + timeout
        while time.time() < deadline:
            with lock:
                for g in got:
                    if pred(*g):
                        return g
            time.sleep(0.02)
        return None

    c = mqtt.Client(client_id=f"v5-{time.time_ns()}", protocol=mqtt.MQTTv5)
    c.on_message = on_message
    try:
        time.sleep(1.0)
        # A late subscriber: what it gets is retained.
        c.connect("127.0.0.1", port)
        c.subscribe(f"{prefix}/#", qos=1)
        c.subscribe("reply/#", qos=1)
        c.loop_start()
        check(wait(lambda t, p, r, pr: t == f"{prefix}/status" and p == "online" and r) is not None,
              "MQTT 5: status online, retained")
        m = wait(lambda t, p, r, pr: t == f"{prefix}/tags/Setp" and r)
        check(m is not None, "MQTT 5: tags retained")
        if m:
            props = m[3]
            check(getattr(props, "PayloadFormatIndicator", None) == 1
                  and getattr(props, "ContentType", None) == "application/json",
                  f"MQTT 5: UTF-8 JSON said in the message's properties ({props})")
        c.publish(f"{prefix}/set/Setp", json.dumps({"value": 555}), qos=1).wait_for_publish(5)
        check(wait(lambda t, p, r, pr: t == f"{prefix}/tags/Setp" and json.loads(p)["value"] == 555) is not None
              and api(http, "/api/tags/Setp")["value"] == 555, "MQTT 5: a write through set/ is published back")
        c.publish(f"{prefix}/set/Start", json.dumps({"value": True}), qos=1).wait_for_publish(5)
        e = wait(lambda t, p, r, pr: t == f"{prefix}/error" and json.loads(p)["tag"] == "Start")
        check(e is not None and "input" in e[1], "MQTT 5: a write to an input is refused on error")
        for value, want in [(777, "value"), ("x", "error")]:
            props = Properties(PacketTypes.PUBLISH)
            props.ResponseTopic = f"reply/{want}"
            props.CorrelationData = f"req-{want}".encode()
            c.publish(f"{prefix}/set/Setp", json.dumps({"value": value}), qos=1, properties=props).wait_for_publish(5)
            r = wait(lambda t, p, r, pr: t == f"reply/{want}")
            ok = r is not None and want in json.loads(r[1]) and getattr(r[3], "CorrelationData", None) == f"req-{want}".encode()
            check(ok, f"MQTT 5: a write with a response topic is answered there with its correlation data ({r and r[1]})")
        with lock:
            got.clear()
        alba.send_signal(signal.SIGKILL)
        alba.wait()
        check(wait(lambda t, p, r, pr: t == f"{prefix}/status" and p == "offline", timeout=60) is not None,
              "MQTT 5: last will offline after kill -9")
    finally:
        c.loop_stop()
        if alba.poll() is None:
            alba.kill()
        broker.kill()


def publish_as(port, user, pw, topic, payload):
    c = client(f"pub-{time.time_ns()}")
    c.username_pw_set(user, pw)
    c.connect("127.0.0.1", port)
    c.loop_start()
    c.publish(topic, payload, qos=1).wait_for_publish(5)
    c.loop_stop()
    c.disconnect()


if __name__ == "__main__":
    main()
