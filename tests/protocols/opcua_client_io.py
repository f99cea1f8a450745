#!/usr/bin/env python3
"""Alba as an OPC UA client ([[opcua_server]] of alba.toml) against a server
written elsewhere: python asyncua's.

Usage: opcua_client_io.py ALBA_BINARY PROJECT_DIR

The server runs in this process with the nodes ns=2;s=Tank.Level (Double)
and ns=2;s=Tank.Pump (Boolean), endpoints None and Basic256Sha256
SignAndEncrypt, and one user (op / the right password). Checks:
- a wrong password is refused: S:IOOK false and `alba run` says why
  (wrong user name or password), as do the connection's health in
  /api/status and a browse (502), neither echoing the password;
- the right one: Level reaches the tag LevelIn through the subscription,
  PumpOut written from Alba reaches the node; /api/status shows the
  connection ok; GET /api/opcua/tank/browse lists Tank under Objects and
  its variables with their data types and nsu= node ids;
- the server stops: S:IOOK false, the connection down in /api/status,
  LevelIn holds its last value; a new server on the same port: S:IOOK
  true again, the new subscription delivers its values, PumpOut is
  written again without being changed;
- with Basic256Sha256 SignAndEncrypt, the server's certificate is not
  trusted: refused (S:IOOK false, the reason on stderr) and kept in
  pki-client/rejected/; moved to trusted/, the client connects.
"""

import asyncio
import json
import os
import re
import shutil
import sys
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path

from asyncua import Server, ua
from asyncua.crypto.cert_gen import setup_self_signed_certificate
from asyncua.crypto.permission_rules import User, UserRole
from cryptography.x509.oid import ExtendedKeyUsageOID
from alba_run import Alba, free_port

failures = []
GOOD = "correct horse battery staple"


def check(cond, what):
    if not cond:
        failures.append(what)
        print(f"  FAIL: {what}", flush=True)


def until(what, f, timeout=60.0):
    deadline = time.time() + timeout
    while time.time() < deadline:
        try:
            if f():
                return True
        except Exception:
            pass
        time.sleep(0.05)
    check(False, f"timed out waiting for {what}")
    return False


def get(alba, path):
    """GET `path` of `alba run`'s API: (status, JSON body), errors included."""
    try:
        with urllib.request.urlopen(alba.http + path, timeout=30) as r:
            return r.status, json.loads(r.read())
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read() or b"null")


def connection(alba):
    return alba.api("GET", "/api/status")["connections"][0]


class Users:
    def get_user(self, iserver, username=None, password=None, certificate=None):
        if username == "op" and password == GOOD:
            return User(role=UserRole.User)
        return None


class TankServer:
    """An asyncua server on its own event loop thread."""

    def __init__(self, port, pki):
        self.port = port
        self.pki = pki
        self.loop = asyncio.new_event_loop()
        threading.Thread(target=self.loop.run_forever, daemon=True).start()
        self._run(self._start())

    def _run(self, coro, timeout=30):
        return asyncio.run_coroutine_threadsafe(coro, self.loop).result(timeout)

    async def _start(self):
        cert, key = self.pki / "server.der", self.pki / "server.pem"
        uri = "urn:alba-test:asyncua-tank"
        await setup_self_signed_certificate(key, cert, uri, "localhost",
                                            [ExtendedKeyUsageOID.SERVER_AUTH, ExtendedKeyUsageOID.CLIENT_AUTH],
                                            {"commonName": "asyncua tank"})
        self.server = Server(user_manager=Users())
        await self.server.init()
        self.server.set_endpoint(f"opc.tcp://127.0.0.1:{self.port}/")
        await self.server.set_application_uri(uri)
        self.server.set_security_policy([ua.SecurityPolicyType.NoSecurity,
                                         ua.SecurityPolicyType.Basic256Sha256_SignAndEncrypt])
        self.server.set_identity_tokens([ua.UserNameIdentityToken])
        await self.server.load_certificate(str(cert))
        await self.server.load_private_key(str(key))
        ns = await self.server.register_namespace("urn:tank")
        assert ns == 2, ns
        tank = await self.server.nodes.objects.add_object(ua.NodeId("Tank", ns), "Tank")
        self.level = await tank.add_variable(ua.NodeId("Tank.Level", ns), "Level", 3.25)
        self.pump = await tank.add_variable(ua.NodeId("Tank.Pump", ns), "Pump", False)
        await self.pump.set_writable()
        await self.server.start()

    def set_level(self, v):
        self._run(self.level.write_value(v))

    def pump_value(self):
        return self._run(self.pump.read_value())

    def stop(self):
        self._run(self.server.stop())



def configure(project, port, password, secure):
    toml = Path(project) / "alba.toml"
    text = toml.read_text()
    text = re.sub(r'endpoint = "[^"]*"', f'endpoint = "opc.tcp://localhost:{port}/"', text)
    text = re.sub(r'\nsecurity_policy = "[^"]*"\nsecurity_mode = "[^"]*"', "", text)
    if secure:
        text = text.replace('user = "op"', 'security_policy = "Basic256Sha256"\nsecurity_mode = "SignAndEncrypt"\nuser = "op"')
    toml.write_text(text)
    (Path(project) / "password.txt").write_text(password + "\n")


def main():
    binary, project = sys.argv[1], sys.argv[2]
    port = free_port()
    pki = Path(project) / "server-pki"
    pki.mkdir(exist_ok=True)
    server = TankServer(port, pki)
    try:
        print("opcua client io: a wrong password is refused", flush=True)
        configure(project, port, "wrong", secure=False)
        alba = Alba(binary, project, "sim")
        try:
            until("a refusal on stderr", lambda: alba.said("wrong user name or password"))
            check(alba.tag("S:IOOK") is False, "S:IOOK false with a wrong password")
            until("the refusal in /api/status", lambda: "wrong user name or password" in (connection(alba)["last_error"] or ""))
            c = connection(alba)
            check(c["ok"] is False and c["connected"] is False and c["name"] == "tank", f"health while refused: {c}")
            code, body = get(alba, "/api/opcua/tank/browse")
            check(code == 502 and "wrong user name or password" in body["error"], f"browse refused with the reason: {code} {body}")
        finally:
            alba.stop()
        check(not any(GOOD in l or "wrong\n" == l for l in alba.log), "the password is never echoed")

        print("opcua client io: subscription and writes (None, right password)", flush=True)
        configure(project, port, GOOD, secure=False)
        alba = Alba(binary, project, "sim")
        try:
            until("S:IOOK", lambda: alba.tag("S:IOOK") is True)
            until("LevelIn 3.25", lambda: alba.tag("LevelIn") == 3.25)
            server.set_level(7.5)
            until("LevelIn 7.5", lambda: alba.tag("LevelIn") == 7.5)
            alba.api("PUT", "/api/tags/PumpOut", {"value": True})
            until("Pump true on the server", lambda: server.pump_value() is True)
            alba.api("PUT", "/api/tags/PumpOut", {"value": False})
            until("Pump false on the server", lambda: server.pump_value() is False)
            c = connection(alba)
            check(c["ok"] is True and c["protocol"] == "opcua" and c["last_error"] is None, f"health: {c}")
            code, objects = get(alba, "/api/opcua/tank/browse")
            check(code == 200, f"browse Objects: {code} {objects}")
            tank = [x for x in objects.get("children", []) if x["browse_name"] == "Tank"]
            check(tank and tank[0]["node"] == "ns=2;s=Tank" and tank[0]["node_uri"] == "nsu=urn:tank;s=Tank"
                  and tank[0]["class"] == "Object", f"Tank under Objects: {objects}")
            code, r = get(alba, "/api/opcua/tank/browse?node=nsu%3Durn%3Atank%3Bs%3DTank")
            kids = {x["browse_name"]: x for x in r.get("children", [])}
            check(code == 200 and kids.get("Level", {}).get("data_type") == "Double"
                  and kids.get("Level", {}).get("node_uri") == "nsu=urn:tank;s=Tank.Level"
                  and kids.get("Pump", {}).get("data_type") == "Boolean", f"Tank's variables: {code} {r}")
            check(GOOD not in json.dumps([objects, r, c]), "no password in the API's answers")

            print("opcua client io: the server restarts (inputs held, S:IOOK false, then recovery)", flush=True)
            alba.api("PUT", "/api/tags/PumpOut", {"value": True})
            until("Pump true on the server", lambda: server.pump_value() is True)
            server.set_level(6.0)
            until("LevelIn 6.0", lambda: alba.tag("LevelIn") == 6.0)
            server.stop()
            until("S:IOOK false while the server is down", lambda: alba.tag("S:IOOK") is False)
            until("the loss in /api/status", lambda: connection(alba)["connected"] is False)
            c = connection(alba)
            check(c["ok"] is False and c["last_error"] and c["errors"] >= 1, f"health while down: {c}")
            time.sleep(1.0)
            check(alba.tag("LevelIn") == 6.0, f"LevelIn holds its last value: {alba.tag('LevelIn')}")
            check(alba.tag("S:IOOK") is False, "S:IOOK stays false while the server is down")
            # A new server on the same port, with its initial values (Level 3.25, Pump false).
            server = TankServer(port, pki)
            until("S:IOOK true again", lambda: alba.tag("S:IOOK") is True)
            until("the output written again (Pump true on the new server)", lambda: server.pump_value() is True)
            until("LevelIn 3.25 from the new server's subscription", lambda: alba.tag("LevelIn") == 3.25)
            server.set_level(8.5)
            until("LevelIn 8.5 after the restart", lambda: alba.tag("LevelIn") == 8.5)
            c = connection(alba)
            check(c["ok"] is True and c["connects"] >= 2 and c["last_error"] is None, f"health after the restart: {c}")
            alba.api("PUT", "/api/tags/PumpOut", {"value": False})
            until("Pump false on the new server", lambda: server.pump_value() is False)
        finally:
            alba.stop()

        print("opcua client io: an untrusted server certificate is refused (Basic256Sha256)", flush=True)
        configure(project, port, GOOD, secure=True)
        alba = Alba(binary, project, "sim")
        rejected = Path(project) / ".alba" / "pki-client" / "rejected"
        try:
            until("the certificate in rejected/", lambda: any(rejected.glob("*.der")))
            until("a refusal on stderr", lambda: alba.said("OPC UA client tank") and not alba.tag("S:IOOK"))
            check(alba.tag("S:IOOK") is False, "S:IOOK false with an untrusted server")
            check(not alba.said("connected to"), "no connection to an untrusted server")
            print("opcua client io: trusted, it connects", flush=True)
            trusted = Path(project) / ".alba" / "pki-client" / "trusted"
            trusted.mkdir(parents=True, exist_ok=True)
            for f in rejected.glob("*.der"):
                shutil.move(str(f), str(trusted / f.name))
            until("S:IOOK (secure)", lambda: alba.tag("S:IOOK") is True, timeout=40)
            server.set_level(1.5)
            until("LevelIn 1.5 (secure)", lambda: alba.tag("LevelIn") == 1.5)
        finally:
            alba.stop()
    finally:
        server.stop()
    if failures:
        print("".join(alba.log[-40:]))
        raise SystemExit(f"{len(failures)} failure(s)")
    print("opcua client io: ok", flush=True)


if __name__ == "__main__":
    main()
